//! Loops where an offset ring would cut a slot (docs/roughing.md, "Offset
//! clearing", "Slots").
//!
//! Inside-out, a ring of `levels[k]` has uncut material on its outer side
//! only, about ae wide, where `levels[k + 1]` lies ae inside it: the deeper
//! rings swept every point within R of `levels[k + 1]`. Where it does not
//! (the first ring of a branch, the thin tip of a level that the next one
//! does not reach), the tool would have material on both sides: a slot.
//! There the ring is cut with loops: every `p` along it the tool runs a full
//! circle of radius `r` on the ring's inner side (counter-clockwise when
//! climbing: the loop's front meets the material with it on the tool's
//! right), as trochoidal milling does (Otkur and Lazoglu 2007, "Trochoidal
//! milling", Int. J. Mach. Tools Manuf. 47(9)). `p` is the largest advance
//! whose steady-state loops keep the engagement at the target
//! ([`advance`]), and the loops start far enough before the material that the
//! first one meets only `p` of it.

use std::collections::HashMap;

use scallop_contour::{Contour, P2, Region, Vertex};

use super::Banded;
use crate::tol;

/// Samples skipped between probes away from a run of loops.
const IDLE_STRIDE: usize = 8;

/// Loop radii tried, as shares of R: the largest whose circle fits.
/// Down to R / 32: a channel narrower than the tool by less than that is
/// slotted (a loop there would advance a few microns).
const RADIUS_SHARES: [f64; 16] =
    [1.0, 0.8, 0.64, 0.5, 0.4, 0.32, 0.25, 0.2, 0.16, 0.125, 0.1, 0.08, 0.0625, 0.05, 0.04, 0.03125];

/// The loops of one level's rings: what the deeper rings and the loops
/// already cut swept.
pub(crate) struct Looper<'a> {
    /// Where a tool centre may go (the loops' circles stay in it).
    region: &'a Region,
    /// Runs of loops shorter than this along the ring are left out.
    min_run: f64,
    /// `levels[k + 1]` grown by R less the chip: swept by the deeper rings.
    deeper: Option<Banded>,
    /// The region grown by R less two chips: where the tool can meet stock.
    reach: Banded,
    radius: f64,
    /// +1 when the ring's inner side is on its left (climb), -1 on its right.
    side: f64,
    chord: f64,
    target: f64,
    /// Loop discs swept so far at this level: centre and reach (r + R).
    discs: Vec<(P2, f64)>,
    buckets: HashMap<(i64, i64), Vec<usize>>,
    cell: f64,
    /// Loops made (bounded by [`tol::MAX_LOOPS`]).
    pub(crate) count: usize,
}

impl<'a> Looper<'a> {
    /// `deeper`: `levels[k + 1]`, `None` at the deepest level; `target` the
    /// engagement angle (rad) the loops hold.
    pub(crate) fn new(
        region: &'a Region,
        deeper: Option<&Region>,
        radius: f64,
        climb: bool,
        target: f64,
        chord: f64,
    ) -> Looper<'a> {
        let deeper = Looper::grown(deeper, radius, chord);
        let reach = Banded::new(&region.offset(-(radius - 2.0 * tol::AIR_RING_CHIP)), chord);
        Looper {
            region,
            min_run: 0.0,
            deeper,
            reach,
            radius,
            side: if climb { 1.0 } else { -1.0 },
            chord,
            target,
            discs: Vec::new(),
            buckets: HashMap::new(),
            cell: 4.0 * radius,
            count: 0,
        }
    }

    /// Loops on the rings of a region an earlier clearing left
    /// ([`Looper::looped_after`]; docs/roughing.md, "Adaptive clearing", the
    /// region's rings).
    pub(crate) fn after(region: &'a Region, radius: f64, climb: bool, target: f64, chord: f64) -> Looper<'a> {
        Looper { min_run: tol::LOOP_MIN_RUN_SHARE * radius, ..Looper::new(region, None, radius, climb, target, chord) }
    }

    fn grown(deeper: Option<&Region>, radius: f64, chord: f64) -> Option<Banded> {
        deeper.map(|d| Banded::new(&d.offset(-(radius - tol::AIR_RING_CHIP)), chord))
    }

    /// The next level out: its rings are cut once `deeper`'s are (the loops
    /// cut so far stay swept).
    pub(super) fn set_deeper(&mut self, deeper: Option<&Region>) {
        self.deeper = Looper::grown(deeper, self.radius, self.chord);
    }

    fn advance_of(&self, i: usize) -> f64 {
        self.radius * unit_advance(i, self.target)
    }

    fn key(&self, p: P2) -> (i64, i64) {
        #[allow(clippy::cast_possible_truncation, reason = "bucket indices of a bounded region")]
        ((p[0] / self.cell).floor() as i64, (p[1] / self.cell).floor() as i64)
    }

    fn add_disc(&mut self, c: P2, reach: f64) {
        let i = self.discs.len();
        self.discs.push((c, reach));
        let (lo, hi) = (self.key([c[0] - reach, c[1] - reach]), self.key([c[0] + reach, c[1] + reach]));
        for x in lo.0..=hi.0 {
            for y in lo.1..=hi.1 {
                self.buckets.entry((x, y)).or_default().push(i);
            }
        }
    }

    /// The tool's periphery at `y` is swept: within R of `levels[k + 1]`
    /// or in a loop's disc (less the chip).
    fn swept(&self, y: P2, cleared: Option<&dyn Fn(P2) -> bool>) -> bool {
        self.deeper.as_ref().is_some_and(|d| d.contains(y))
            || cleared.is_some_and(|f| f(y))
            || self.buckets.get(&self.key(y)).is_some_and(|v| {
                v.iter().any(|&i| {
                    let (c, reach) = self.discs[i];
                    (y[0] - c[0]).hypot(y[1] - c[1]) <= reach - tol::AIR_RING_CHIP
                })
            })
    }

    /// The largest radius share (index) not above `most` whose loop at `p`
    /// with inner normal `n` fits in the region.
    fn fit(&self, p: P2, n: P2, most: f64) -> Option<usize> {
        RADIUS_SHARES.iter().position(|&s| {
            let r = s * self.radius;
            r <= most + 1e-12 && self.region.holds_disc([p[0] + r * n[0], p[1] + r * n[1]], r * (1.0 - 1e-3))
        })
    }

    /// `cut` with loops where its inner side meets material the deeper
    /// rings did not sweep; `cut` itself where there is none.
    pub(crate) fn looped(&mut self, cut: &Contour) -> Contour {
        self.looped_by(cut, None)
    }

    /// As [`Looper::looped`], what an earlier clearing swept told by
    /// `cleared` (whether a point of the periphery is cut: the adaptive
    /// walk's field) besides the deeper rings and the loops.
    pub(crate) fn looped_after(&mut self, cut: &Contour, cleared: &dyn Fn(P2) -> bool) -> Contour {
        self.looped_by(cut, Some(cleared))
    }

    fn looped_by(&mut self, cut: &Contour, cleared: Option<&dyn Fn(P2) -> bool>) -> Contour {
        let closed = cut.is_closed();
        let samples = sample(cut, self.chord, self.side, tol::LOOP_SAMPLE_SHARE * self.radius);
        let n = samples.len();
        if n < 2 {
            return cut.clone();
        }
        let total = samples[n - 1].cum;
        // The probe lies a chip inside the tool's periphery, and is swept
        // when within a loop's reach less a chip: on a level's tip of no
        // width (both sides of its ring on one line) the loops of one side
        // sweep the other side's probes with a chip to spare.
        let reach = self.radius - 2.0 * tol::AIR_RING_CHIP;
        // The arc length of sample `i`'s position `d` further on.
        let ahead = |i: usize, d: f64| -> usize {
            let want = samples[i].cum + d;
            let want = if closed && want > total { want - total } else { want.min(total) };
            samples.partition_point(|s| s.cum < want).min(n - 1)
        };
        let inward = |s: &Sample| [s.p[0] + reach * s.n[0], s.p[1] + reach * s.n[1]];
        let mut loops: Vec<(usize, f64)> = Vec::new();
        let mut last: Option<(f64, P2, f64, f64)> = None; // (cum, centre, r, p)
        // After an entry (a bore of 1.5 R about the start) or a link, the
        // first loop is small: it sweeps within the bore.
        let mut most = 0.25 * self.radius;
        let last_index = if closed { n - 1 } else { n };
        // Away from a run of loops the samples are probed every
        // `IDLE_STRIDE`; where one finds material, the ones skipped before it
        // are probed again one by one.
        let mut i = 0;
        let mut fine_until = 0;
        while i < last_index {
            if self.count >= tol::MAX_LOOPS {
                break;
            }
            let idle = last.is_none() && i >= fine_until;
            let s = &samples[i];
            let guess = RADIUS_SHARES.iter().position(|&x| x * self.radius <= most + 1e-12).unwrap_or(0);
            let (r, p) = (RADIUS_SHARES[guess] * self.radius, self.advance_of(guess));
            if let Some((cum, c0, r0, p0)) = last {
                // How far the loop's centre moved, at the last loop's radius.
                let c = [s.p[0] + r0 * s.n[0], s.p[1] + r0 * s.n[1]];
                let moved = (s.cum - cum).max((c[0] - c0[0]).hypot(c[1] - c0[1]));
                if moved < p.min(p0) {
                    i += 1;
                    continue;
                }
            }
            // The material this loop would meet: the inner side a loop's
            // reach ahead (so the first loop of a run meets only p of it).
            let radius = self.radius;
            let probe_at = |r: f64, p: f64| inward(&samples[ahead(i, (r + radius - p).max(0.0))]);
            // Within a run, also the material straight ahead of the next
            // loop's front: the run goes on to the end of a tip, where the
            // ring turns back along its own loops.
            let front = |r: f64| {
                let c = [s.p[0] + r * s.n[0], s.p[1] + r * s.n[1]];
                let t = [s.n[1] * self.side, -s.n[0] * self.side];
                let d = r + self.radius - 2.0 * tol::AIR_RING_CHIP;
                [c[0] + d * t[0], c[1] + d * t[1]]
            };
            let ahead_material = |r: f64| {
                last.is_some() && {
                    let f = front(r);
                    self.reach.contains(f) && !self.swept(f, cleared)
                }
            };
            if self.swept(probe_at(r, p), cleared) && !ahead_material(r) {
                if last.is_some_and(|l| s.cum - l.0 > 2.0 * (l.2 + self.radius)) {
                    // A run ended: the next one starts small again.
                    last = None;
                    most = 0.25 * self.radius;
                }
                i += if idle { IDLE_STRIDE } else { 1 };
                continue;
            }
            if idle && i > 0 {
                // Back to the first sample after the last one probed.
                fine_until = i + 1;
                i = i.saturating_sub(IDLE_STRIDE - 1);
                continue;
            }
            let Some(k) = self.fit(s.p, s.n, most) else {
                i += 1;
                continue;
            };
            let (r, p) = (RADIUS_SHARES[k] * self.radius, self.advance_of(k));
            if k != guess && self.swept(probe_at(r, p), cleared) && !ahead_material(r) {
                i += 1;
                continue;
            }
            let c = [s.p[0] + r * s.n[0], s.p[1] + r * s.n[1]];
            loops.push((i, r));
            self.add_disc(c, r + self.radius);
            self.count += 1;
            last = Some((s.cum, c, r, p));
            most = (r + p).max(0.25 * self.radius);
            i += 1;
        }
        if self.min_run > 0.0 {
            loops = self.long_runs(&samples, &loops);
        }
        if loops.is_empty() {
            return cut.clone();
        }
        self.build(&samples, &loops, closed).unwrap_or_else(|| cut.clone())
    }

    /// The loops of the runs at least `min_run` long along the ring (a run
    /// ends where the next loop is farther on than the last one's reach, as
    /// in [`Looper::looped`]).
    fn long_runs(&self, samples: &[Sample], loops: &[(usize, f64)]) -> Vec<(usize, f64)> {
        let mut kept = Vec::new();
        let mut run: Vec<(usize, f64)> = Vec::new();
        let mut flush = |run: &mut Vec<(usize, f64)>| {
            if let (Some(a), Some(b)) = (run.first(), run.last()) {
                if samples[b.0].cum - samples[a.0].cum >= self.min_run {
                    kept.extend_from_slice(run);
                }
            }
            run.clear();
        };
        for &l in loops {
            if run.last().is_some_and(|&(i, r)| samples[l.0].cum - samples[i].cum > 2.0 * (r + self.radius)) {
                flush(&mut run);
            }
            run.push(l);
        }
        flush(&mut run);
        kept
    }

    /// The contour through the samples with a full circle at each loop,
    /// the stretches between loops refitted as lines and arcs.
    fn build(&self, samples: &[Sample], loops: &[(usize, f64)], closed: bool) -> Option<Contour> {
        let fit = tol::RING_ARC_FIT_SHARE * self.chord;
        let mut out: Vec<Vertex> = Vec::new();
        let mut stretch: Vec<P2> = Vec::new();
        let flush = |stretch: &[P2], out: &mut Vec<Vertex>| -> Option<()> {
            if stretch.len() == 1 {
                out.push(Vertex { x: stretch[0][0], y: stretch[0][1], bulge: 0.0 });
                return Some(());
            }
            let c = Contour::from_points(stretch, false, fit).ok()?;
            out.extend(c.vertices());
            Some(())
        };
        let mut next = loops.iter().peekable();
        let n = samples.len();
        for (i, s) in samples.iter().enumerate() {
            if closed && i == n - 1 {
                // The closing sample repeats the first point.
                stretch.push(s.p);
                break;
            }
            let here = next.peek().is_some_and(|&&(j, _)| j == i);
            // The chords' own vertices and the loops' places: the points
            // added between vertices are not kept.
            if (s.vertex || here) && stretch.last().is_none_or(|q| (q[0] - s.p[0]).hypot(q[1] - s.p[1]) > 1e-9) {
                stretch.push(s.p);
            }
            if let Some(&&(j, r)) = next.peek()
                && j == i
            {
                next.next();
                flush(&stretch, &mut out)?;
                let v = out.last_mut()?;
                v.bulge = self.side;
                let far = [s.p[0] + 2.0 * r * s.n[0], s.p[1] + 2.0 * r * s.n[1]];
                out.push(Vertex { x: far[0], y: far[1], bulge: self.side });
                stretch.clear();
                stretch.push(s.p);
            }
        }
        if stretch.len() > 1 {
            flush(&stretch, &mut out)?;
        } else if let Some(&p) = stretch.first() {
            out.push(Vertex { x: p[0], y: p[1], bulge: 0.0 });
        }
        if closed {
            // The last vertex repeats the first.
            out.pop();
        }
        Contour::new(&out, closed).ok()
    }
}

/// A point along a contour with its unit inner normal and arc length.
struct Sample {
    p: P2,
    /// A vertex of the contour's chords (not a point added between them).
    vertex: bool,
    /// Unit normal towards the ring's inner side.
    n: P2,
    cum: f64,
}

/// `c` as points at most `step` apart (arcs as chords within `chord`), each
/// with the normal of the chord after it towards `side` (+1 left); a closed
/// contour's first point repeated at the end. At a vertex where the inner
/// side opens (a reflex turn), the normal turns in steps of at most 0.2 rad
/// about the vertex, so the loops there follow each other.
fn sample(c: &Contour, chord: f64, side: f64, step: f64) -> Vec<Sample> {
    let mut pts = c.to_points(chord);
    if c.is_closed()
        && let Some(&first) = pts.first()
    {
        pts.push(first);
    }
    let mut out: Vec<Sample> = Vec::new();
    let mut cum = 0.0;
    let normal = |a: P2, b: P2| -> Option<P2> {
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let l = dx.hypot(dy);
        (l > 1e-12).then(|| [-dy / l * side, dx / l * side])
    };
    let mut prev_n: Option<P2> = None;
    for w in pts.windows(2) {
        let (a, b) = (w[0], w[1]);
        let Some(n) = normal(a, b) else { continue };
        let vertex = a;
        if let Some(pn) = prev_n {
            // The turn from the last chord's normal to this one, positive
            // towards the inner side's opening (away from the inner side).
            let cross = pn[0] * n[1] - pn[1] * n[0];
            let turn = cross.atan2(pn[0] * n[0] + pn[1] * n[1]) * side;
            if turn < -0.2 {
                #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "at most 16 steps")]
                let m = (turn.abs() / 0.2).ceil().min(16.0) as usize;
                let a0 = pn[1].atan2(pn[0]);
                for j in 1..m {
                    #[allow(clippy::cast_precision_loss, reason = "small counts")]
                    let angle = a0 - side * turn.abs() * j as f64 / m as f64;
                    out.push(Sample { p: vertex, vertex: false, n: [angle.cos(), angle.sin()], cum });
                }
            }
        }
        let d = (b[0] - a[0]).hypot(b[1] - a[1]);
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "a ring's samples")]
        let m = (d / step).ceil().max(1.0) as usize;
        for j in 0..m {
            #[allow(clippy::cast_precision_loss, reason = "small counts")]
            let f = j as f64 / m as f64;
            out.push(Sample {
                p: [a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1])],
                vertex: j == 0,
                n,
                cum: cum + f * d,
            });
        }
        cum += d;
        prev_n = Some(n);
    }
    if let (Some(&last), Some(n)) = (pts.last(), prev_n) {
        out.push(Sample { p: last, vertex: true, n, cum });
    }
    out
}

/// [`advance`] for a tool of radius 1 and loops of radius
/// `RADIUS_SHARES[share]`, computed once per process (the advance scales with
/// the tool: every length of [`loop_engagement`] does).
fn unit_advance(share: usize, target: f64) -> f64 {
    static CACHE: std::sync::OnceLock<std::sync::Mutex<HashMap<(usize, u64), f64>>> = std::sync::OnceLock::new();
    let cache = CACHE.get_or_init(|| std::sync::Mutex::new(HashMap::new()));
    let key = (share, target.to_bits());
    if let Some(&p) = cache.lock().ok().as_ref().and_then(|c| c.get(&key)) {
        return p;
    }
    let p = advance(RADIUS_SHARES[share], 1.0, target);
    if let Ok(mut c) = cache.lock() {
        c.insert(key, p);
    }
    p
}

/// The largest advance per loop (mm) of loops of radius `r` for a tool of
/// radius `radius` whose engagement, measured as the simulator measures it
/// (the arc of the front half of the periphery in material), stays within
/// `target` (rad) in the steady state ([`loop_engagement`]); bisection.
pub(super) fn advance(r: f64, radius: f64, target: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, 2.0 * radius);
    for _ in 0..tol::LOOP_BISECTIONS {
        let mid = 0.5 * (lo + hi);
        if loop_engagement_until(r, mid, radius, target) <= target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo.max(1e-3 * radius)
}

/// The largest engagement (rad) along one loop of radius `r` in a row of
/// loops `p` apart along +x (centres at `(j p, r)`, each a counter-clockwise
/// circle from and back to `(j p, 0)`, joined along the x axis), the
/// material all that no earlier move came within `radius` of.
#[cfg(test)]
fn loop_engagement(r: f64, p: f64, radius: f64) -> f64 {
    loop_engagement_until(r, p, radius, f64::INFINITY)
}

/// [`loop_engagement`], returned as soon as it exceeds `stop` (the places
/// along the loop taken from a third of the way to the apex on, where it
/// is largest).
fn loop_engagement_until(r: f64, p: f64, radius: f64, stop: f64) -> f64 {
    use std::f64::consts::{FRAC_PI_2, PI, TAU};
    let positions = tol::LOOP_POSITIONS;
    let probes = tol::ENGAGE_PROBES / 2;
    let r2 = radius * radius;
    // The probes' directions from the front half's first one.
    #[allow(clippy::cast_precision_loss, reason = "small counts")]
    let turns: Vec<(f64, f64)> = (0..probes).map(|k| (PI * (k as f64 + 0.5) / probes as f64).sin_cos()).collect();
    // The three loops before and their joins.
    let swept_before = |x: P2| -> bool {
        (1..=3).any(|j| {
            #[allow(clippy::cast_precision_loss, reason = "small counts")]
            let cx = -(j as f64) * p;
            let (dx, dy) = (x[0] - cx, x[1] - r);
            let d = (dx * dx + dy * dy).sqrt();
            if (d - r).abs() < radius {
                return true;
            }
            // The join from (cx, 0) to (cx + p, 0).
            let qx = x[0].clamp(cx, cx + p);
            let (ex, ey) = (x[0] - qx, x[1]);
            ex * ex + ey * ey < r2
        })
    };
    let mut worst = 0.0f64;
    let first = positions / 9;
    for n in 0..positions {
        let i = (first + n) % positions;
        #[allow(clippy::cast_precision_loss, reason = "small counts")]
        let psi = -FRAC_PI_2 + TAU * (i as f64 + 0.5) / positions as f64;
        let (sp, cp) = psi.sin_cos();
        let t = [r * cp, r + r * sp];
        // The front half starts at the heading less a quarter turn: psi.
        let along = psi + FRAC_PI_2;
        let mut inside = 0usize;
        for &(sk, ck) in &turns {
            let (dx, dy) = (cp * ck - sp * sk, sp * ck + cp * sk);
            let x = [t[0] + radius * dx, t[1] + radius * dy];
            if swept_before(x) {
                continue;
            }
            // This loop's own path so far (from -pi/2 to psi): no nearer
            // than the circle, so only probes within R of it are looked at.
            let dc = (x[0] * x[0] + (x[1] - r) * (x[1] - r)).sqrt();
            if (dc - r).abs() < radius {
                let rel = ((x[1] - r).atan2(x[0]) + FRAC_PI_2).rem_euclid(TAU);
                // Beyond the arc's angular range the nearest point of it is
                // an end: its start, or the tool's own place, which is R from
                // every probe (the tool does not sweep ahead of itself).
                let swept = if rel < along { true } else { x[0] * x[0] + x[1] * x[1] < r2 };
                if swept {
                    continue;
                }
            }
            inside += 1;
        }
        #[allow(clippy::cast_precision_loss, reason = "small counts")]
        let phi = PI * inside as f64 / probes as f64;
        worst = worst.max(phi);
        if worst > stop {
            return worst;
        }
    }
    worst
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_advance_holds_the_target_and_grows_with_the_radius() {
        let (radius, ae) = (3.0f64, 1.2f64);
        let target = (1.0 - ae / radius).acos();
        let mut last = 0.0;
        for share in [0.125, 0.25, 0.5, 1.0] {
            let p = advance(share * radius, radius, target);
            assert!(loop_engagement(share * radius, p, radius) <= target);
            // A tenth more advance breaks the target: the bisection found the
            // largest, not a small safe one.
            assert!(loop_engagement(share * radius, 1.1 * p, radius) > target, "share {share}: p {p}");
            assert!(p > last);
            last = p;
        }
    }
}
