//! The tool-down links of an adaptive plan between its passes
//! (docs/roughing.md, "Adaptive clearing").
//!
//! A link from the end of a chain to the start of the next stays at the
//! cutting depth through cleared area: a shortest path on a lattice of the
//! grid (every [`LATTICE`]th cell) through the tool centres that cut
//! nothing (no probe of the periphery in material, checked on the grid's
//! swept field as it is when the link runs), shortened by straight
//! segments that cut nothing either, the last [`APPROACH_SHARE`] R to the
//! start allowed to engage up to the target (a pass starts next to
//! material). It is a retract only when no such path exists
//! within [`DETOUR`] times the straight distance plus [`DETOUR_EXTRA`] R.

use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashMap};

use scallop_contour::P2;

use super::squares::{NOTHING, RIM};
use super::{Planner, dist};
use crate::grid::{BIG, Grid};
use crate::offset::Step;
use crate::tol;
use crate::tol::{APPROACH_SHARE, DETOUR, DETOUR_EXTRA, LATTICE, LINK_SLACK, MAX_EXPAND, MAX_GOALS};

/// A lattice node's state in the cache of [`Planner::node_clear`].
const CLEAR: u32 = u32::MAX;

/// The samples of a link's move tested together for no material around
/// them ([`Planner::segment_ok`]): 16 half cells, 1.5 mm for a 6 mm tool.
const CHUNK: usize = 16;

impl Planner<'_> {
    /// Whether the tool centred at `p` cuts nothing: inside the region's
    /// grid and no probe of its periphery in material.
    pub(super) fn clear_at(&self, p: P2) -> bool {
        let r = self.options.tool_radius;
        // The swept field first: in cleared area it settles the probe alone.
        let nx = self.grid.nx;
        let open = self.open.as_deref();
        let fields = self.fields();
        for &[c, s] in &self.link_round {
            let q = [p[0] + r * c, p[1] + r * s];
            // Off the grid both fields are far: no material.
            let Some(at) = self.grid.locate(q) else { continue };
            // A square with no material, or all of it in the strip along
            // the walls, holds no material of the test below.
            if matches!(self.squares.get(at.0, &fields), NOTHING | RIM) {
                continue;
            }
            if Grid::interpolate(&self.swept, nx, at) > r + LINK_SLACK
                && Grid::interpolate(&self.reach, nx, at) < r - self.strip
                // As `open_at`, inline.
                && !open.is_some_and(|f| Grid::interpolate(f, nx, at) > 0.0)
            {
                return false;
            }
        }
        true
    }

    /// Whether the straight move `a` to `b` may be part of a link towards
    /// `target`: in the region, and every sample cuts nothing, or, within
    /// [`APPROACH_SHARE`] R of `target`, engages no more than a pass.
    fn link_ok(&self, a: P2, b: P2, target: P2) -> bool {
        let near = APPROACH_SHARE * self.options.tool_radius;
        self.segment_ok(a, b, |p| dist(p, target) <= near && self.engagement(p) <= tol::LINK_APPROACH * self.target)
    }

    /// Whether lattice cell `k` is a centre that cuts nothing, cached: a
    /// clear centre stays clear (material only goes away), a blocked one is
    /// checked again once a chain has been cut since.
    fn node_clear(&mut self, k: usize) -> bool {
        match self.lattice[k] {
            CLEAR => true,
            e if e == self.epoch => false,
            _ => {
                let ok = self.link_cell(k) && self.clear_at(self.grid.centre(k));
                self.lattice[k] = if ok { CLEAR } else { self.epoch };
                ok
            }
        }
    }

    /// The lattice cell nearest `p`, and its (i, j).
    fn lattice_near(&self, p: P2) -> (usize, usize) {
        let g = &self.grid;
        #[allow(
            clippy::cast_possible_truncation,
            clippy::cast_sign_loss,
            clippy::cast_precision_loss,
            reason = "clamped"
        )]
        let snap = |v: f64, n: usize| {
            let c = (v / LATTICE as f64).round().clamp(0.0, ((n - 1) / LATTICE) as f64) as usize;
            c * LATTICE
        };
        (snap((p[0] - g.x0) / g.h - 0.5, g.nx), snap((p[1] - g.y0) / g.h - 0.5, g.ny))
    }

    /// A tool-down link from `from` (where the tool is, its disc cleared) to
    /// `to`: the points between them, or `None` when the link must be a
    /// retract (see the module documentation).
    pub(super) fn link_path(&mut self, from: P2, to: P2) -> Option<Vec<P2>> {
        if dist(from, to) <= 1e-9 {
            return Some(Vec::new());
        }
        if self.link_ok(from, to, to) {
            return Some(Vec::new());
        }
        let (nx, ny) = (self.grid.nx, self.grid.ny);
        let l = LATTICE;
        let step = self.grid.h * l as f64;
        let r = self.options.tool_radius;
        let limit = DETOUR * dist(from, to) + DETOUR_EXTRA * r;
        let near = APPROACH_SHARE * r;
        let mut best: HashMap<usize, (f64, usize)> = HashMap::new();
        let mut heap: BinaryHeap<Reverse<(u64, usize)>> = BinaryHeap::new();
        let push = |heap: &mut BinaryHeap<Reverse<(u64, usize)>>, k: usize, g: f64, p: P2| {
            heap.push(Reverse(((g + dist(p, to)).to_bits(), k)));
        };
        // Seeds: the lattice cells around `from` reached by a clear move.
        let (ci, cj) = self.lattice_near(from);
        for dj in -2i64..=2 {
            for di in -2i64..=2 {
                let (i, j) = (ci as i64 + di * l as i64, cj as i64 + dj * l as i64);
                if i < 1 || j < 1 || i as usize >= nx - 1 || j as usize >= ny - 1 {
                    continue;
                }
                #[allow(clippy::cast_sign_loss, reason = "checked above")]
                let k = j as usize * nx + i as usize;
                let c = self.grid.centre(k);
                if self.node_clear(k) && self.link_ok(from, c, to) {
                    let g = dist(from, c);
                    best.insert(k, (g, usize::MAX));
                    push(&mut heap, k, g, c);
                }
            }
        }
        let mut expanded = 0usize;
        let mut goals = 0usize;
        let mut done: HashMap<usize, ()> = HashMap::new();
        while let Some(Reverse((bits, k))) = heap.pop() {
            if f64::from_bits(bits) > limit || expanded >= MAX_EXPAND || goals >= MAX_GOALS {
                return None;
            }
            if done.insert(k, ()).is_some() {
                continue;
            }
            expanded += 1;
            let c = self.grid.centre(k);
            let g = best.get(&k).map_or(BIG, |b| b.0);
            // An end across a wall does not count as a try.
            if dist(c, to) <= near.max(2.0 * step) && self.in_room(c, to) {
                goals += 1;
                if self.link_ok(c, to, to) {
                    let mut nodes = vec![c];
                    let mut at = k;
                    while let Some(&(_, prev)) = best.get(&at) {
                        if prev == usize::MAX {
                            break;
                        }
                        nodes.push(self.grid.centre(prev));
                        at = prev;
                    }
                    nodes.push(from);
                    nodes.reverse();
                    nodes.push(to);
                    return self.shorten(&nodes, to);
                }
            }
            let (i, j) = (k % nx, k / nx);
            for (di, dj) in [(1i64, 0i64), (-1, 0), (0, 1), (0, -1), (1, 1), (1, -1), (-1, 1), (-1, -1)] {
                let (a, b) = (i as i64 + di * l as i64, j as i64 + dj * l as i64);
                if a < 1 || b < 1 || a as usize >= nx - 1 || b as usize >= ny - 1 {
                    continue;
                }
                #[allow(clippy::cast_sign_loss, reason = "checked above")]
                let n = b as usize * nx + a as usize;
                if done.contains_key(&n) || !self.node_clear(n) {
                    continue;
                }
                // A diagonal move needs both cells beside it clear (no
                // corner of a wall or of material cut across).
                if di != 0 && dj != 0 {
                    #[allow(clippy::cast_sign_loss, reason = "checked above")]
                    let (s1, s2) = (j * nx + a as usize, b as usize * nx + i);
                    if !self.node_clear(s1) || !self.node_clear(s2) {
                        continue;
                    }
                }
                let d = if di != 0 && dj != 0 { step * std::f64::consts::SQRT_2 } else { step };
                let gn = g + d;
                if best.get(&n).is_none_or(|b| gn < b.0) {
                    best.insert(n, (gn, k));
                    push(&mut heap, n, gn, self.grid.centre(n));
                }
            }
        }
        None
    }

    /// The lattice path `nodes` (from the tool's position to `to`) as few
    /// straight moves that each pass [`Planner::link_ok`]: the points
    /// between the ends, or `None` when a lattice move itself fails.
    fn shorten(&self, nodes: &[P2], to: P2) -> Option<Vec<P2>> {
        let last = nodes.len() - 1;
        let mut out = Vec::new();
        let mut i = 0;
        while i < last {
            let mut j = i + 1;
            if !self.link_ok(nodes[i], nodes[j], to) {
                return None;
            }
            // Longest reach first by doubling, then back to the last good.
            let mut span = 1;
            let mut good = j;
            loop {
                let cand = (i + 2 * span).min(last);
                if cand == good || !self.link_ok(nodes[i], nodes[cand], to) {
                    break;
                }
                good = cand;
                span *= 2;
            }
            while good < last && self.link_ok(nodes[i], nodes[good + 1], to) {
                good += 1;
            }
            j = good;
            if j < last {
                out.push(nodes[j]);
            }
            i = j;
        }
        Some(out)
    }

    /// Stamps the polyline `run` on the swept field (no engagement measured).
    pub(super) fn stamp(&mut self, run: &[P2]) {
        if let Some(&p) = run.first() {
            self.stamp_swept(p, p, None);
        }
        for pair in run.windows(2) {
            // A move the last pass stamped already (the same ends, the same
            // width, the field only lowered since) would change nothing.
            if !self.stamped.contains(&(pair[0], pair[1])) {
                self.stamp_swept(pair[0], pair[1], None);
            }
        }
        self.epoch = self.epoch.wrapping_add(1).min(CLEAR - 1);
    }

    /// Appends the runs as cuts (lines), stamped (the link before the first is the
    /// caller's; each run starts where the one before ended).
    /// A move of a run that leaves the region (a chord of the grid across a
    /// wall's bend) is not cut: the tool goes on from the move's end by a
    /// link.
    pub(super) fn emit_runs(&mut self, steps: &mut Vec<Step>, runs: Vec<Vec<P2>>) {
        for mut run in runs {
            run.dedup_by(|a, b| dist(*a, *b) <= super::tol::LINK_GROW * 0.1);
            let mut from = 0;
            for k in 1..=run.len() {
                let split = k < run.len() && !self.in_holder(run[k - 1], run[k]);
                if !split && k < run.len() {
                    continue;
                }
                if k - from >= 2 {
                    self.stamp(&run[from..k]);
                    if let Some(c) = super::lines(&run[from..k]) {
                        steps.push(Step::Cut(c));
                    }
                }
                if split {
                    let link = self.link_step(run[k - 1], run[k]);
                    steps.push(link);
                }
                from = k;
            }
        }
        self.stamped.clear();
    }

    /// The link from the end `from` of a pass whose last move heads `out`
    /// to the start `to` of one that leaves along `into`: arcs turning away
    /// from the material at both ends, tangent to the passes, of the largest
    /// radius of [`tol::LINK_TURN_SHARES`] whose arcs pass
    /// [`Planner::turn_ok`] and whose middle (the common tangent, else a
    /// path of [`Planner::link_path`]) is found; else the same with an arc
    /// at one end only; else [`Planner::link_step`].
    /// `away` and `away0` are the signs of [`Planner::away`] on the last
    /// pass and on the next: each arc turns away from its own pass's
    /// material. Both ways, where the next pass goes back along the
    /// frontier, the two differ: the arcs are then joined by their inner
    /// tangent, else (they overlap) tried both turning the last pass's way.
    pub(super) fn turning_link(
        &mut self,
        from: P2,
        out: Option<f64>,
        (away, away0): (f64, f64),
        to: P2,
        into: f64,
    ) -> Step {
        if let Some(h) = out {
            // Both ends turning first; else the end's arc alone, else the
            // start's (a wall right behind a start or ahead of an end leaves
            // no room for its arc). The end's arc leaves along the pass's
            // last heading, else turned further away from the material by
            // the least of [`tol::LINK_END_TURNS`] that fits: a pass that
            // ends against a wall turns a little there instead of reversing.
            let same = (away0 > 0.0) == (away > 0.0);
            let sides: &[f64] = if same { &[away] } else { &[away0, away] };
            for (need_end, need_start, &side0) in [(true, true), (true, false), (false, true)]
                .into_iter()
                .flat_map(|(e, s)| sides.iter().map(move |side0| (e, s, side0)))
                .filter(|&(e, s, &side0)| (e && s) || (side0 > 0.0) == (away > 0.0))
            {
                let rotations: &[f64] = if need_end { &tol::LINK_END_TURNS } else { &tol::LINK_END_TURNS[..1] };
                for &rot in rotations {
                    for share in tol::LINK_TURN_SHARES {
                        let rho = share * self.options.tool_radius;
                        let Some((first, last)) = turns(away, from, h + away * rot, side0, to, into, rho) else {
                            continue;
                        };
                        let ok = |me: &Self, arc: &[P2]| arc.windows(2).all(|w| me.turn_ok(w[0], w[1]));
                        let ok1 = need_end && ok(self, &first);
                        let ok2 = need_start && ok(self, &last);
                        if ok1 != need_end || ok2 != need_start {
                            continue;
                        }
                        let first = if ok1 { first } else { vec![from] };
                        let last = if ok2 { last } else { vec![to] };
                        let (t1, t2) = (first[first.len() - 1], last[0]);
                        let Some(middle) = self.link_path(t1, t2) else { continue };
                        let mut via: Vec<P2> = first[1..].to_vec();
                        via.extend_from_slice(&middle);
                        via.extend_from_slice(&last[..last.len() - 1]);
                        via.dedup_by(|a, b| dist(*a, *b) <= 1e-6);
                        let mut line = vec![from];
                        line.extend_from_slice(&via);
                        line.push(to);
                        self.stamp(&line);
                        return Step::Link { tool_down: true, via, cleared: true, to: Some(to) };
                    }
                }
            }
        }
        self.link_step(from, to)
    }

    /// Whether the straight move from `a` to `b` stays in the region and each
    /// of its samples (half a grid cell apart, `b` included, `a` not) cuts
    /// nothing or passes `engaged_ok`.
    fn segment_ok(&self, a: P2, b: P2, engaged_ok: impl Fn(P2) -> bool) -> bool {
        // The samples first (the region test is the dearer one); both are
        // pure, so the order does not change the answer.
        let step = 0.5 * self.grid.h;
        let r = self.options.tool_radius;
        // Every probe of every sample lies on a circle of radius R about a
        // point of the move: when the squares about those hold no material (`Grid::quiet`), the
        // samples on that piece are clear; the whole move first, then
        // pieces of `CHUNK` samples, the rest sample by sample.
        let (reach, inner) = (r + self.grid.h, r - self.grid.h);
        let quiet = |p: P2, q: P2| {
            let bounds =
                ([p[0].min(q[0]) - reach, p[1].min(q[1]) - reach], [p[0].max(q[0]) + reach, p[1].max(q[1]) + reach]);
            // On a circle of radius R about a point of the move: no farther
            // than R from the move, no nearer than R to both its ends (the
            // squares' middles, a square's half diagonal either way).
            let near = |m: P2| super::segment_distance(m, p, q) <= reach && dist(m, p).max(dist(m, q)) >= inner;
            self.grid.quiet(&self.swept, &self.reach, bounds, near, r + LINK_SLACK, r - self.strip, Some(&self.blocks))
        };
        let clear = quiet(a, b) || {
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "a small positive count")]
            let n = ((dist(a, b) / step).ceil() as usize).max(1);
            let at = |i: usize| {
                #[allow(clippy::cast_precision_loss, reason = "a small count")]
                let f = i as f64 / n as f64;
                [a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1])]
            };
            (1..=n).step_by(CHUNK).all(|first| {
                let last = (first + CHUNK - 1).min(n);
                (n > CHUNK && quiet(at(first), at(last)))
                    || (first..=last).all(|i| self.clear_at(at(i)) || engaged_ok(at(i)))
            })
        };
        clear && self.in_room(a, b)
    }

    /// Whether the chord `a` to `b` of a link's arc may be cut: in the
    /// region, and every sample cuts nothing or engages no more than a pass
    /// (the arcs lie within a tool radius of a pass's end or start, where
    /// material may be next to the tool; measured all round).
    fn turn_ok(&self, a: P2, b: P2) -> bool {
        self.segment_ok(a, b, |p| self.engagement(p) <= tol::LINK_APPROACH * self.target)
    }

    /// The link from `from` to `to` as a step; a tool-down link's path is
    /// stamped.
    pub(super) fn link_step(&mut self, from: P2, to: P2) -> Step {
        match self.link_path(from, to) {
            Some(via) => {
                let mut line = vec![from];
                line.extend_from_slice(&via);
                line.push(to);
                self.stamp(&line);
                Step::Link { tool_down: true, via, cleared: true, to: Some(to) }
            }
            None => Step::Link { tool_down: false, via: Vec::new(), cleared: self.clear_at(to), to: Some(to) },
        }
    }
}

/// The arcs of radius `rho` of [`Planner::turning_link`], as chords
/// within [`tol::LINK_TURN_SAGITTA`]: from `p` (heading `h`) round to the
/// common tangent, and from it round to `s` (heading `h0`); the first turns
/// `side` (1 left, -1 right), the second `side0` (away from the material of
/// the pass each arc joins): the outer tangent of the two circles when
/// they turn the same way, the inner one when not. `None` when the circles
/// coincide, when they turn opposite ways and overlap, or when an arc would
/// turn more than 1.25 half turns.
fn turns(side: f64, p: P2, h: f64, side0: f64, s: P2, h0: f64, rho: f64) -> Option<(Vec<P2>, Vec<P2>)> {
    let centre = |q: P2, a: f64, sd: f64| [q[0] - rho * sd * a.sin(), q[1] + rho * sd * a.cos()];
    let (c1, c2) = (centre(p, h, side), centre(s, h0, side0));
    let d = dist(c1, c2);
    if d <= 1e-9 {
        return None;
    }
    let u = [(c2[0] - c1[0]) / d, (c2[1] - c1[1]) / d];
    // The tangent's direction `v`: `u` when both turn the same way, else
    // (L u + 2 rho side n(u)) / d with L the tangent's length, n the left
    // normal. Its points lie rho from each centre, opposite each turn.
    let v = if (side > 0.0) == (side0 > 0.0) {
        u
    } else {
        if d <= 2.0 * rho {
            return None;
        }
        let l = (d * d - 4.0 * rho * rho).sqrt();
        [(l * u[0] - 2.0 * rho * side * u[1]) / d, (l * u[1] + 2.0 * rho * side * u[0]) / d]
    };
    let off = |sd: f64| [v[1] * sd * rho, -v[0] * sd * rho];
    let (o1, o2) = (off(side), off(side0));
    let (t1, t2) = ([c1[0] + o1[0], c1[1] + o1[1]], [c2[0] + o2[0], c2[1] + o2[1]]);
    let angle = |c: P2, q: P2| (q[1] - c[1]).atan2(q[0] - c[0]);
    let sweep = |sd: f64, a0: f64, a1: f64| (sd * (a1 - a0)).rem_euclid(std::f64::consts::TAU);
    let (a0, a1) = (angle(c1, p), angle(c1, t1));
    let (b0, b1) = (angle(c2, t2), angle(c2, s));
    let (s1, s2) = (sweep(side, a0, a1), sweep(side0, b0, b1));
    let most = 1.25 * std::f64::consts::PI;
    if s1 > most || s2 > most {
        return None;
    }
    let dtheta = 2.0 * (1.0 - (tol::LINK_TURN_SAGITTA / rho).min(1.0)).acos();
    let arc = |c: P2, sd: f64, a: f64, sw: f64, end: P2, begin: P2| {
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "a small positive count")]
        let n = (sw / dtheta.max(1e-3)).ceil() as usize;
        let mut pts = vec![begin];
        for i in 1..n {
            #[allow(clippy::cast_precision_loss, reason = "a small count")]
            let t = a + sd * sw * i as f64 / n as f64;
            pts.push([c[0] + rho * t.cos(), c[1] + rho * t.sin()]);
        }
        pts.push(end);
        pts
    };
    Some((arc(c1, side, a0, s1, t1, p), arc(c2, side0, b0, s2, s, t2)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn link_turns_are_tangent_to_both_passes_and_turn_one_way() {
        let rho = 1.5;
        let dtheta = 2.0 * (1.0 - tol::LINK_TURN_SAGITTA / rho).acos();
        let heading = |a: P2, b: P2| (b[1] - a[1]).atan2(b[0] - a[0]);
        let near =
            |a: f64, b: f64| (a - b + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
        let mut tried = 0;
        for k in 0..200u32 {
            let f = f64::from(k);
            let side = if k % 2 == 0 { 1.0 } else { -1.0 };
            let (p, h) = ([0.0, 0.0], 0.37 * f);
            let (s, h0) = ([10.0 * (0.1 * f).cos(), 7.0 * (0.23 * f).sin()], 1.3 * f);
            let Some((first, last)) = turns(side, p, h, side, s, h0, rho) else { continue };
            tried += 1;
            assert_eq!((first[0], last[last.len() - 1]), (p, s));
            // Leaves the pass's end along it, meets the start along it.
            assert!(near(heading(first[0], first[1]), h).abs() <= dtheta, "case {k}: out");
            assert!(near(heading(last[last.len() - 2], last[last.len() - 1]), h0).abs() <= dtheta, "case {k}: in");
            // The tangent between the arcs continues both.
            let (t1, t2) = (first[first.len() - 1], last[0]);
            let t = heading(t1, t2);
            if first.len() > 1 && dist(first[first.len() - 2], t1) > 1e-9 {
                assert!(near(heading(first[first.len() - 2], t1), t).abs() <= dtheta, "case {k}: tangent out");
            }
            if last.len() > 1 && dist(t2, last[1]) > 1e-9 {
                assert!(near(heading(t2, last[1]), t).abs() <= dtheta, "case {k}: tangent in");
            }
            // Every chord turns to `side` from the one before.
            for arc in [&first, &last] {
                for w in arc.windows(3) {
                    let (a, b) = ([w[1][0] - w[0][0], w[1][1] - w[0][1]], [w[2][0] - w[1][0], w[2][1] - w[1][1]]);
                    assert!(side * (a[0] * b[1] - a[1] * b[0]) >= -1e-12, "case {k}: turns the other way");
                }
            }
        }
        assert!(tried >= 40, "{tried} cases turned");
    }
}
