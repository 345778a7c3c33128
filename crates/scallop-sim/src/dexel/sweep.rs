//! A line against a convex body swept along a straight move with a fixed
//! tool axis.
//!
//! # Method
//!
//! The body `C` (convex) is placed with its tip at `p(t) = p0 + t V`,
//! `t in [0, 1]`. The swept solid `S = C + [0, V]` is convex, so a line
//! `x(s) = o + s d` meets it in an interval. In the `(s, t)` plane the set
//! `K = {(s, t) : x(s) - p(t) in C, 0 <= t <= 1}` is convex (the preimage of
//! `C` under an affine map, cut by a slab), and the line's interval in `S` is
//! the projection of `K` on `s`:
//!
//! ```text
//! entry = min over t of a(t),   exit = max over t of b(t)
//! ```
//!
//! where `[a(t), b(t)]` is the line inside the body at one position (exact,
//! [`Body::hit`]). `a` is convex and `b` concave on the interval `T` of
//! positions where the line meets the body, and their slopes are known from
//! the outward normal `n` at the entry or exit point: moving the body by
//! `dt V` moves its surface point along `V`, so `a'(t) = (n . V) / (n . d)`
//! (the same for `b`). The extremes are found by bisection on `t` using the
//! sign of that slope (a monotone quantity for a convex function), which
//! gives a certified bracket: the best value found so far is an upper bound
//! (a real position of the body, so nothing outside the swept solid is ever
//! removed) and the two tangent lines at the bracket ends give a lower bound;
//! the bisection stops when they are within [`SWEEP_TOL`].
//!
//! A first position on `T` is needed: an end of the move (`t = 0` or `1`),
//! or, when the line misses both, a point of the middle. The line and `V`
//! span a plane with normal `m = d x V`; the line meets `S` only if that plane
//! meets `C` (`-h(-m) <= m . (o - p0) <= h(m)` with `h` the support function of
//! `C`, exact per piece: this is also the cheap rejection test). Then the
//! segment between the support points of `C` in directions `-m` and `m` lies in
//! `C` and crosses the plane at a point `Q` of `C`; `Q = o - p0 + s d - t V`
//! gives `(s, t)` in `K` if `t in [0, 1]`. If `t` falls outside while both ends
//! miss, the convexity of `K` (without the slab) shows the line misses `S`.

use scallop_geom::{Point3, Vec3};

use super::body::{Body, Line, Span};

/// The bisection stops when the certified bracket of an entry or exit is this
/// narrow (mm).
pub(crate) const SWEEP_TOL: f64 = 1e-9;

/// Most steps per extreme (at least every other step halves the bracket in
/// `t`, so it is then below `2^-30`).
const MAX_BISECT: usize = 60;

/// A body swept along a straight move with a fixed unit axis `a`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Sweep {
    pub(crate) p0: Point3,
    pub(crate) v: Vec3,
    pub(crate) a: Vec3,
}

/// What the search keeps about one position: `t`, the value (entry, or minus
/// the exit) and its slope in `t`.
#[derive(Debug, Clone, Copy)]
struct Probe {
    t: f64,
    value: f64,
    slope: f64,
}

impl Sweep {
    /// The line `o + s d` inside the body at position `t`.
    fn at(&self, body: &Body, o: &Point3, d: &Vec3, t: f64) -> Option<Span> {
        let tip = self.p0 + t * self.v;
        body.hit(&Line::new(self.a, o - tip, *d))
    }

    /// The interval of the line `o + s d` (unit `d`) inside the swept body.
    pub(crate) fn interval(&self, body: &Body, o: &Point3, d: &Vec3) -> Option<(f64, f64)> {
        self.interval_within(body, o, d, f64::NEG_INFINITY, f64::INFINITY)
    }

    /// [`Sweep::interval`] where only its overlap with `(m_lo, m_hi)` matters:
    /// `None` as soon as the certified bounds show there is none (the entry
    /// at or after `m_hi`, or the exit at or before `m_lo`).
    pub(crate) fn interval_within(
        &self,
        body: &Body,
        o: &Point3,
        d: &Vec3,
        m_lo: f64,
        m_hi: f64,
    ) -> Option<(f64, f64)> {
        let vv = self.v.norm_squared();
        if vv == 0.0 {
            return self.at(body, o, d, 0.0).map(|s| (s.s0, s.s1));
        }
        let m = d.cross(&self.v);
        let mm = m.norm_squared();
        let parallel = mm <= 1e-24 * vv;
        let w0 = o - self.p0;
        let mut middle = None;
        if !parallel {
            // Separating plane test with the support function.
            let c = m.dot(&w0);
            let (hp, pp) = body.support(&self.a, &m);
            let (hm, pm) = body.support(&self.a, &(-m));
            if c > hp || c < -hm {
                return None;
            }
            middle = Some((c, pp, pm, mm));
        }
        let h0 = self.at(body, o, d, 0.0);
        let h1 = self.at(body, o, d, 1.0);
        let (t_f, span_f) = match (h0, h1) {
            (Some(s), _) => (0.0, s),
            (None, Some(s)) => (1.0, s),
            (None, None) => {
                let (c, pp, pm, mm) = middle?;
                // Q on the segment pm..pp with m . Q = c.
                let (vp, vm) = (m.dot(&pp), m.dot(&pm));
                let q = if vp > vm { pm + (c - vm) / (vp - vm) * (pp - pm) } else { pm };
                let r = q - w0;
                let (dv, dr, vr) = (d.dot(&self.v), d.dot(&r), self.v.dot(&r));
                let t = (dv * dr - vr) / mm;
                if !(0.0..=1.0).contains(&t) {
                    return None;
                }
                (t, self.at(body, o, d, t)?)
            }
        };
        if parallel {
            // Every position meets the line in a translate of one interval.
            let (a, b) = (h0?, h1?);
            return Some((a.s0.min(b.s0), a.s1.max(b.s1)));
        }
        let entry = self.extreme(body, o, d, h0, h1, t_f, span_f, 1.0, m_hi)?;
        if entry >= m_hi {
            return None;
        }
        let exit = -self.extreme(body, o, d, h0, h1, t_f, span_f, -1.0, -m_lo)?;
        (entry <= exit && exit > m_lo).then_some((entry, exit))
    }

    /// Minimum over positions of `sign * edge`, edge the entry (`sign = 1`)
    /// or the exit (`sign = -1`), by bisection on the slope's sign; `None`
    /// once its certified lower bound reaches `cutoff`.
    #[allow(clippy::too_many_arguments)] // private; the pieces of one search.
    fn extreme(
        &self,
        body: &Body,
        o: &Point3,
        d: &Vec3,
        h0: Option<Span>,
        h1: Option<Span>,
        mut t_f: f64,
        span_f: Span,
        sign: f64,
        cutoff: f64,
    ) -> Option<f64> {
        let probe = |t: f64, s: &Span| {
            let (value, n) = if sign > 0.0 { (s.s0, s.n0) } else { (-s.s1, s.n1) };
            let nd = n.dot(d);
            let slope = if nd == 0.0 {
                // Grazing: the slope is infinite (or unknown for a zero normal).
                f64::NAN
            } else {
                sign * n.dot(&self.v) / nd
            };
            Probe { t, value, slope }
        };
        let first = probe(t_f, &span_f);
        let mut best = first.value;
        let mut lo = 0.0;
        let mut hi = 1.0;
        let mut at_lo: Option<Probe> = None;
        let mut at_hi: Option<Probe> = None;
        if let Some(s) = h0 {
            let p = probe(0.0, &s);
            best = best.min(p.value);
            if p.slope >= 0.0 {
                return Some(best); // Non-decreasing from the start: the minimum is there.
            }
            at_lo = p.slope.is_finite().then_some(p);
        }
        if let Some(s) = h1 {
            let p = probe(1.0, &s);
            best = best.min(p.value);
            if p.slope <= 0.0 {
                return Some(best);
            }
            at_hi = p.slope.is_finite().then_some(p);
        }
        // Probe at the tangents' crossing while that shrinks the bracket at
        // least by half, else at the middle (a safeguarded cutting-plane
        // step: superlinear on smooth minima, never slower than bisection
        // every other step).
        let mut cut_step = true;
        for _ in 0..MAX_BISECT {
            let mut crossing = None;
            if let (Some(l), Some(h)) = (at_lo, at_hi) {
                // The convex function lies above both tangents.
                let t = (h.value - l.value + l.slope * l.t - h.slope * h.t) / (l.slope - h.slope);
                let bound = l.value + l.slope * (t - l.t);
                if best - bound <= SWEEP_TOL {
                    break;
                }
                if bound >= cutoff {
                    return None;
                }
                crossing = Some(t);
            }
            let width = hi - lo;
            let mid = match crossing {
                Some(t) if cut_step && t.is_finite() => t.clamp(lo + 0.01 * width, hi - 0.01 * width),
                _ => 0.5 * (lo + hi),
            };
            if mid <= lo || mid >= hi {
                break;
            }
            let probed = self.at(body, o, d, mid).map(|s| probe(mid, &s));
            if let Some(p) = probed {
                best = best.min(p.value);
            }
            match probed {
                Some(p) if !p.slope.is_nan() => {
                    t_f = mid;
                    if p.slope > 0.0 {
                        hi = mid;
                        at_hi = p.slope.is_finite().then_some(p);
                    } else if p.slope < 0.0 {
                        lo = mid;
                        at_lo = p.slope.is_finite().then_some(p);
                    } else {
                        break;
                    }
                }
                _ => {
                    // Off the interval of positions that meet the line
                    // (`None`), or grazing (a NaN slope: the line touches the
                    // body there without entering it): `mid` bounds the
                    // positions that meet the line; they lie on the side of
                    // the known position.
                    if mid < t_f {
                        lo = mid;
                        at_lo = None;
                    } else {
                        hi = mid;
                        at_hi = None;
                    }
                    if probed.is_some() {
                        // A graze keeps the kind of the next step.
                        continue;
                    }
                }
            }
            cut_step = hi - lo <= 0.5 * width;
        }
        Some(best)
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]
mod tests {
    use scallop_cutter::Cutter;

    use super::*;

    /// Brute force: the union of the body's intervals at many positions.
    fn brute(body: &Body, sw: &Sweep, o: &Point3, d: &Vec3) -> Option<(f64, f64)> {
        let mut out: Option<(f64, f64)> = None;
        for k in 0..=4000 {
            let t = f64::from(k) / 4000.0;
            if let Some(s) = sw.at(body, o, d, t) {
                out = Some(out.map_or((s.s0, s.s1), |(a, b)| (a.min(s.s0), b.max(s.s1))));
            }
        }
        out
    }

    #[test]
    fn sweeps_match_dense_sampling() {
        let shapes = crate::test_support::shapes(1.5, 0.5, 0.6);
        let mut rng = crate::test_support::Lcg(99);
        let mut rnd = || rng.signed();
        for shape in shapes {
            let body = Body::flutes(&Cutter::new(shape, 4.0).unwrap());
            for case in 0..400 {
                let axis = (rnd().abs() * 3.0) as usize % 3;
                let mut d = Vec3::zeros();
                d[axis] = 1.0;
                let mut a = Vec3::new(rnd(), rnd(), rnd() + 1.5).normalize();
                let mut v = Vec3::new(4.0 * rnd(), 4.0 * rnd(), rnd());
                // Degenerate configurations: the axis along the ray, the move
                // along the ray, along the axis, or no move at all.
                match case % 8 {
                    0 => a = d,
                    1 => v = 3.0 * rnd() * d,
                    2 => v = 3.0 * rnd() * a,
                    3 => v = Vec3::zeros(),
                    4 => {
                        a = d;
                        v = 2.0 * d;
                    }
                    _ => {}
                }
                let sw = Sweep { p0: Point3::new(rnd(), rnd(), rnd()), v, a };
                let mut o = Point3::new(3.0 * rnd(), 3.0 * rnd(), 3.0 * rnd() + 1.0);
                o[axis] = -20.0;
                let got = sw.interval(&body, &o, &d);
                let want = brute(&body, &sw, &o, &d);
                match (got, want) {
                    (Some(g), Some(w)) => {
                        // Sampling under-estimates the extremes by at most
                        // the motion between samples; the solve never exceeds them.
                        let slack = 4.2 * 1.0 / 4000.0 * 50.0;
                        assert!(g.0 <= w.0 + 1e-9 && g.0 >= w.0 - slack, "{shape:?} entry {g:?} vs {w:?}");
                        assert!(g.1 >= w.1 - 1e-9 && g.1 <= w.1 + slack, "{shape:?} exit {g:?} vs {w:?}");
                    }
                    (None, None) => {}
                    (g, w) => {
                        // Only grazing lines may differ.
                        let len = g.or(w).map_or(0.0, |(a, b)| b - a);
                        assert!(len < 1e-3, "{shape:?} {g:?} vs {w:?}");
                    }
                }
            }
        }
    }
}
