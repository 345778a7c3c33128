//! Convex solids of revolution in the tool frame and their exact
//! intersections with straight lines.
//!
//! A [`Body`] is the union of at most two convex [`Piece`]s whose union is
//! convex (the cutting part of every cutter shape, the shank, a holder
//! segment). Coordinates along the tool axis `h` (from the tip) and the
//! radial distance `rho` from the axis.
//!
//! - [`Piece::Frustum`]: `h0 <= h <= h1`, `rho <= r0 + k (h - h0)` (a cylinder
//!   when `k = 0`, a cone flank when `r0 = 0`). Along a line `rho^2` and the
//!   linear radius are quadratic and linear in the line parameter, so the
//!   intersection is a closed form (a quadratic and two slab planes).
//! - [`Piece::Cap`]: the points within `r` of the disc of radius `core` at
//!   height `r` on the axis, below `h = r`: the ball end (`core = 0`, a sphere:
//!   closed form) and the bull-nose corner (`core = R - r`). The corner's
//!   boundary is a torus, a quartic along a line; its entry and exit are found
//!   by Newton's method on `u - r`, `u` the distance to the core disc, which is
//!   convex and 1-Lipschitz along the line: started outside the solid (on the
//!   bounding cylinder), Newton on a convex function never overshoots the
//!   first root, and `u - r` is the exact distance to the solid, so the
//!   iterate it stops at lies within [`NEWTON_TOL`] of the surface.

use scallop_cutter::{Cutter, CutterShape};
use scallop_geom::Vec3;

/// Newton on the bull-nose corner stops when the point lies within this
/// distance (mm) of the corner's surface.
pub(crate) const NEWTON_TOL: f64 = 1e-10;

/// Newton iterations before giving up on a (grazing) corner hit.
const NEWTON_STEPS: usize = 100;

/// A line's squared distance coefficients below this count as zero (the line
/// is parallel to the axis, or lies in a plane normal to it).
const PARALLEL: f64 = 1e-24;

/// One convex solid of revolution (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Piece {
    /// `h0 <= h <= h1`, `rho <= r0 + k (h - h0)`.
    Frustum { h0: f64, h1: f64, r0: f64, k: f64 },
    /// `h <= r` and the distance to the disc `rho <= core`, `h = r` at most `r`.
    Cap { core: f64, r: f64 },
}

/// A convex union of pieces, with its reach from the tip.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Body {
    pieces: Vec<Piece>,
    /// Largest distance from the tip to a point of the body (mm).
    reach: f64,
}

/// A line `w(s) = w0 + s d` relative to the tool tip, with the tool axis `a`
/// (both unit vectors) and its coefficients in the tool frame.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Line {
    pub(crate) a: Vec3,
    pub(crate) w0: Vec3,
    pub(crate) d: Vec3,
    /// `h(s) = h0 + s dh`.
    h0: f64,
    dh: f64,
    /// Radial part: `w_perp(s) = p0 + s p1`, `rho^2 = qa s^2 + 2 qb s + qc`.
    p0: Vec3,
    p1: Vec3,
    qa: f64,
    qb: f64,
    qc: f64,
}

impl Line {
    pub(crate) fn new(a: Vec3, w0: Vec3, d: Vec3) -> Line {
        let h0 = w0.dot(&a);
        let dh = d.dot(&a);
        let p0 = w0 - h0 * a;
        let p1 = d - dh * a;
        Line { a, w0, d, h0, dh, p0, p1, qa: p1.norm_squared(), qb: p0.dot(&p1), qc: p0.norm_squared() }
    }

    fn h(&self, s: f64) -> f64 {
        self.h0 + s * self.dh
    }

    fn radial(&self, s: f64) -> Vec3 {
        self.p0 + s * self.p1
    }
}

/// The part of a line inside a convex solid: `[s0, s1]` with the outward
/// normals (not normalised) at the entry and the exit; zero normals at
/// infinite ends.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Span {
    pub(crate) s0: f64,
    pub(crate) n0: Vec3,
    pub(crate) s1: f64,
    pub(crate) n1: Vec3,
}

impl Span {
    const ALL: Span =
        Span { s0: f64::NEG_INFINITY, n0: Vec3::new(0.0, 0.0, 0.0), s1: f64::INFINITY, n1: Vec3::new(0.0, 0.0, 0.0) };

    /// Intersection of two spans (the entry is the later one, with its normal).
    fn meet(self, o: Span) -> Option<Span> {
        let (s0, n0) = if o.s0 > self.s0 { (o.s0, o.n0) } else { (self.s0, self.n0) };
        let (s1, n1) = if o.s1 < self.s1 { (o.s1, o.n1) } else { (self.s1, self.n1) };
        (s0 <= s1).then_some(Span { s0, n0, s1, n1 })
    }

    /// Hull of two spans of a convex union (the earlier entry, the later exit).
    fn join(self, o: Span) -> Span {
        let (s0, n0) = if o.s0 < self.s0 { (o.s0, o.n0) } else { (self.s0, self.n0) };
        let (s1, n1) = if o.s1 > self.s1 { (o.s1, o.n1) } else { (self.s1, self.n1) };
        Span { s0, n0, s1, n1 }
    }
}

/// `{s : A s^2 + 2 B s + C <= 0}` as at most two intervals (possibly infinite).
fn quadratic_le0(a: f64, b: f64, c: f64) -> [Option<(f64, f64)>; 2] {
    let scale = a.abs().max(b.abs()).max(c.abs());
    if scale == 0.0 {
        return [Some((f64::NEG_INFINITY, f64::INFINITY)), None];
    }
    if a.abs() <= PARALLEL * scale.max(1.0) {
        // Linear: 2 B s + C <= 0.
        if b == 0.0 {
            return if c <= 0.0 { [Some((f64::NEG_INFINITY, f64::INFINITY)), None] } else { [None, None] };
        }
        let root = -c / (2.0 * b);
        return if b > 0.0 { [Some((f64::NEG_INFINITY, root)), None] } else { [Some((root, f64::INFINITY)), None] };
    }
    let disc = b * b - a * c;
    if disc < 0.0 {
        return if a > 0.0 { [None, None] } else { [Some((f64::NEG_INFINITY, f64::INFINITY)), None] };
    }
    // Stable roots: q = -(B + sign(B) sqrt(disc)); roots q / A and C / q.
    let sq = disc.sqrt();
    let q = -(b + if b >= 0.0 { sq } else { -sq });
    let (r1, r2) = if q == 0.0 { (0.0, 0.0) } else { (q / a, c / q) };
    let (lo, hi) = if r1 <= r2 { (r1, r2) } else { (r2, r1) };
    if a > 0.0 { [Some((lo, hi)), None] } else { [Some((f64::NEG_INFINITY, lo)), Some((hi, f64::INFINITY))] }
}

impl Piece {
    /// The slab `lo <= h <= hi` along the line.
    fn slab(line: &Line, lo: f64, hi: f64) -> Option<Span> {
        if line.dh.abs() <= 1e-15 {
            let h = line.h0;
            return (h >= lo && h <= hi).then_some(Span::ALL);
        }
        let (sa, sb) = ((lo - line.h0) / line.dh, (hi - line.h0) / line.dh);
        if line.dh > 0.0 {
            Some(Span { s0: sa, n0: -line.a, s1: sb, n1: line.a })
        } else {
            Some(Span { s0: sb, n0: line.a, s1: sa, n1: -line.a })
        }
    }

    /// `rho <= r0 + k (h - h0)` along the line.
    fn flank(line: &Line, h0: f64, r0: f64, k: f64) -> Option<Span> {
        // l(s) = l0 + l1 s.
        let l0 = r0 + k * (line.h0 - h0);
        let l1 = k * line.dh;
        let (qa, qb, qc) = (line.qa - l1 * l1, line.qb - l0 * l1, line.qc - l0 * l0);
        // Half-line where the radius is >= 0.
        let half = if l1 > 0.0 {
            (-l0 / l1, f64::INFINITY)
        } else if l1 < 0.0 {
            (f64::NEG_INFINITY, -l0 / l1)
        } else if l0 >= 0.0 {
            (f64::NEG_INFINITY, f64::INFINITY)
        } else {
            return None;
        };
        let mut out: Option<(f64, f64)> = None;
        for (lo, hi) in quadratic_le0(qa, qb, qc).into_iter().flatten() {
            let (lo, hi) = (lo.max(half.0), hi.min(half.1));
            if lo <= hi {
                out = Some(out.map_or((lo, hi), |(a, b)| (a.min(lo), b.max(hi))));
            }
        }
        let (s0, s1) = out?;
        let normal = |s: f64| {
            if !s.is_finite() {
                return Vec3::zeros();
            }
            let w = line.radial(s);
            let rho = w.norm();
            if rho > 0.0 { w / rho - k * line.a } else { -line.a }
        };
        Some(Span { s0, n0: normal(s0), s1, n1: normal(s1) })
    }

    /// The part of the line inside the piece.
    pub(crate) fn hit(&self, line: &Line) -> Option<Span> {
        match *self {
            Piece::Frustum { h0, h1, r0, k } => Self::slab(line, h0, h1)?.meet(Self::flank(line, h0, r0, k)?),
            Piece::Cap { core: 0.0, r } => {
                // Sphere of radius r centred at h = r, below h = r.
                let c = line.w0 - r * line.a;
                let [Some((s0, s1)), None] = quadratic_le0(1.0, c.dot(&line.d), c.norm_squared() - r * r) else {
                    return None;
                };
                let n = |s: f64| c + s * line.d;
                Span { s0, n0: n(s0), s1, n1: n(s1) }.meet(Self::slab(line, f64::NEG_INFINITY, r)?)
            }
            Piece::Cap { core, r } => {
                let bound = Self::slab(line, 0.0, r)?.meet(Self::flank(line, 0.0, core + r, 0.0)?)?;
                let (s0, n0) = Self::newton(line, core, r, bound.s0, bound.n0, bound.s1, 1.0)?;
                let (s1, n1) = Self::newton(line, core, r, bound.s1, bound.n1, bound.s0, -1.0)?;
                (s0 <= s1).then_some(Span { s0, n0, s1, n1 })
            }
        }
    }

    /// The corner's distance function `u - r` and its gradient at `s`.
    fn corner(line: &Line, core: f64, r: f64, s: f64) -> (f64, Vec3) {
        let w = line.radial(s);
        let rho = w.norm();
        let e = (rho - core).max(0.0);
        let dz = line.h(s) - r;
        let u = e.hypot(dz);
        let radial = if rho > 0.0 { w / rho } else { Vec3::zeros() };
        let grad = if u > 0.0 { (e / u) * radial + (dz / u) * line.a } else { -line.a };
        (u - r, grad)
    }

    /// First root of the corner's distance from `start` in direction `dir`
    /// (+1 entry, -1 exit), not beyond `stop`; the start lies on the bounding
    /// cylinder with outward normal `n_start`.
    fn newton(line: &Line, core: f64, r: f64, start: f64, n_start: Vec3, stop: f64, dir: f64) -> Option<(f64, Vec3)> {
        let mut s = start;
        let (f, _) = Self::corner(line, core, r, s);
        if f <= NEWTON_TOL {
            return Some((s, n_start));
        }
        for _ in 0..NEWTON_STEPS {
            let (f, grad) = Self::corner(line, core, r, s);
            if f <= NEWTON_TOL {
                return Some((s, grad));
            }
            let slope = dir * grad.dot(&line.d);
            if slope >= 0.0 {
                return None;
            }
            s += dir * (f / -slope);
            if (s - stop) * dir > 0.0 {
                return None;
            }
        }
        None
    }

    /// Support of the piece in direction `m` (tool frame at the tip): the
    /// largest `m . x` over the piece and a point where it is reached.
    fn support(&self, a: &Vec3, m: &Vec3) -> (f64, Vec3) {
        let ma = m.dot(a);
        let perp = m - ma * a;
        let mu = perp.norm();
        let u = if mu > 0.0 { perp / mu } else { Vec3::zeros() };
        let at = |h: f64, rho: f64| (ma * h + mu * rho, h * a + rho * u);
        match *self {
            Piece::Frustum { h0, h1, r0, k } => {
                let (lo, hi) = (at(h0, r0), at(h1, r0 + k * (h1 - h0)));
                if hi.0 >= lo.0 { hi } else { lo }
            }
            Piece::Cap { core, r } => {
                if ma >= 0.0 {
                    at(r, core + r)
                } else {
                    let p = r * a + core * u + r * m.normalize();
                    (m.dot(&p), p)
                }
            }
        }
    }
}

impl Body {
    fn new(pieces: Vec<Piece>) -> Body {
        let mut reach = 0.0f64;
        for p in &pieces {
            let (lo, hi, r_lo, r_hi) = match *p {
                Piece::Frustum { h0, h1, r0, k } => (h0, h1, r0, r0 + k * (h1 - h0)),
                Piece::Cap { core, r } => (0.0, r, core + r, core + r),
            };
            reach = reach.max(lo.hypot(r_lo)).max(hi.hypot(r_hi)).max(lo.abs()).max(hi.abs());
        }
        Body { pieces, reach }
    }

    /// The cutting part of `cutter` (flutes): the profile up to the flute length.
    pub(crate) fn flutes(cutter: &Cutter) -> Body {
        let l = cutter.flute_length();
        let cyl = |h0: f64, r: f64| Piece::Frustum { h0, h1: l, r0: r, k: 0.0 };
        let mut pieces = Vec::with_capacity(2);
        match *cutter.shape() {
            CutterShape::Flat { radius } => pieces.push(cyl(0.0, radius)),
            CutterShape::Ball { radius } => {
                pieces.push(Piece::Cap { core: 0.0, r: radius });
                if l > radius {
                    pieces.push(cyl(radius, radius));
                }
            }
            CutterShape::Bull { radius, corner } => {
                pieces.push(Piece::Cap { core: radius - corner, r: corner });
                if l > corner {
                    pieces.push(cyl(corner, radius));
                }
            }
            CutterShape::Cone { radius, half_angle } => {
                let tan = half_angle.tan();
                let hc = radius / tan;
                pieces.push(Piece::Frustum { h0: 0.0, h1: hc.min(l), r0: 0.0, k: tan });
                if l > hc {
                    pieces.push(cyl(hc, radius));
                }
            }
        }
        Body::new(pieces)
    }

    /// The shank: a cylinder above the flutes.
    pub(crate) fn shank(cutter: &Cutter) -> Body {
        let h0 = cutter.flute_length();
        Body::new(vec![Piece::Frustum { h0, h1: h0 + cutter.shank_length(), r0: cutter.shank_radius(), k: 0.0 }])
    }

    /// Holder segment `index` (bottom first), above the shank.
    pub(crate) fn holder(cutter: &Cutter, index: usize) -> Option<Body> {
        let segments = cutter.holder();
        let seg = segments.get(index)?;
        let h0 =
            cutter.flute_length() + cutter.shank_length() + segments[..index].iter().map(|s| s.length).sum::<f64>();
        let k = (seg.top_radius - seg.bottom_radius) / seg.length;
        Some(Body::new(vec![Piece::Frustum { h0, h1: h0 + seg.length, r0: seg.bottom_radius, k }]))
    }

    /// The shank and each holder segment of `cutter` held at stick-out
    /// `stick_out` instead of its own (the holder's bottom that far from the
    /// tip; the shank from the flutes' top up to it, none at the flute length).
    pub(crate) fn guards_at(cutter: &Cutter, stick_out: f64) -> Vec<Body> {
        let h0 = cutter.flute_length();
        let mut out = Vec::with_capacity(1 + cutter.holder().len());
        if stick_out > h0 {
            out.push(Body::new(vec![Piece::Frustum { h0, h1: stick_out, r0: cutter.shank_radius(), k: 0.0 }]));
        }
        let mut from = stick_out.max(h0);
        for seg in cutter.holder() {
            let k = (seg.top_radius - seg.bottom_radius) / seg.length;
            out.push(Body::new(vec![Piece::Frustum { h0: from, h1: from + seg.length, r0: seg.bottom_radius, k }]));
            from += seg.length;
        }
        out
    }

    /// A cylinder round the axis from the flutes' top to `top` (mm from the
    /// tip), as wide as the widest of the shank and the holder: it holds them
    /// at every stick-out up to `top` less the holder's length.
    pub(crate) fn guard_envelope(cutter: &Cutter, top: f64) -> Body {
        let h0 = cutter.flute_length();
        let r = cutter.holder().iter().map(|s| s.bottom_radius.max(s.top_radius)).fold(cutter.shank_radius(), f64::max);
        Body::new(vec![Piece::Frustum { h0, h1: top.max(h0), r0: r, k: 0.0 }])
    }

    /// Largest distance from the tip to the body (mm).
    pub(crate) fn reach(&self) -> f64 {
        self.reach
    }

    /// The part of the line inside the body.
    pub(crate) fn hit(&self, line: &Line) -> Option<Span> {
        let mut out: Option<Span> = None;
        for p in &self.pieces {
            if let Some(s) = p.hit(line) {
                out = Some(out.map_or(s, |o| o.join(s)));
            }
        }
        out
    }

    /// Support value and point of the body (tip at the origin, axis `a`) in direction `m`.
    pub(crate) fn support(&self, a: &Vec3, m: &Vec3) -> (f64, Vec3) {
        let mut best = (f64::NEG_INFINITY, Vec3::zeros());
        for p in &self.pieces {
            let s = p.support(a, m);
            if s.0 > best.0 {
                best = s;
            }
        }
        best
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]
mod tests {
    use super::*;

    /// Inside test by the profile: 0 <= h <= L and rho <= radius_at(h).
    fn inside(shape: &CutterShape, l: f64, a: &Vec3, q: &Vec3) -> bool {
        let h = q.dot(a);
        let rho = (q - h * a).norm();
        if !(0.0..=l).contains(&h) {
            return false;
        }
        let r = match *shape {
            CutterShape::Flat { radius } => radius,
            _ => shape.radius_at(h),
        };
        rho <= r
    }

    /// A line through a random point of `[-scale, scale]^2 x [2 - scale, 2 + scale]`
    /// in a random direction: `(origin, unit direction)`.
    fn random_line(rng: &mut crate::test_support::Lcg, scale: f64) -> (Vec3, Vec3) {
        let w0 = Vec3::new(scale * rng.signed(), scale * rng.signed(), scale * rng.signed() + 2.0);
        (w0, Vec3::new(rng.signed(), rng.signed(), rng.signed()).normalize())
    }

    /// Samples the line `w0 + s d` every 0.003 mm for `|s| < 0.003 n`: every
    /// sample `inside` the solid lies in `span`.
    fn assert_samples_in_span(w0: Vec3, d: Vec3, n: i32, span: Option<Span>, inside: impl Fn(&Vec3) -> bool) {
        for k in -n..n {
            let s = f64::from(k) * 0.003;
            if inside(&(w0 + s * d)) {
                let sp = span.unwrap();
                assert!(s >= sp.s0 - 1e-9 && s <= sp.s1 + 1e-9, "s {s} span {sp:?}");
            }
        }
    }

    #[test]
    fn hits_match_the_profile() {
        let shapes = crate::test_support::shapes(2.0, 0.7, 0.5);
        let a = Vec3::new(0.3, -0.4, 0.8).normalize();
        let mut rng = crate::test_support::Lcg(12345);
        for shape in shapes {
            let cutter = Cutter::new(shape, 5.0).unwrap();
            let body = Body::flutes(&cutter);
            for _ in 0..300 {
                let (w0, d) = random_line(&mut rng, 4.0);
                let span = body.hit(&Line::new(a, w0, d));
                // Every inside sample lies in the span and the span's ends are
                // (nearly) inside.
                assert_samples_in_span(w0, d, 4000, span, |q| inside(&shape, 5.0, &a, q));
                if let Some(sp) = span {
                    for s in [sp.s0, sp.s1, 0.5 * (sp.s0 + sp.s1)] {
                        let q = w0 + s * d;
                        let h = q.dot(&a);
                        let rho = (q - h * a).norm();
                        let r = if matches!(shape, CutterShape::Flat { .. }) { 2.0 } else { shape.radius_at(h) };
                        assert!((-1e-9..=5.0 + 1e-9).contains(&h) && rho <= r + 1e-7, "{shape:?} end {s} outside");
                    }
                }
            }
        }
    }

    #[test]
    fn frusta_narrowing_upwards_match_sampling() {
        // A holder taper: radius 2 at h = 1 down to 1 at h = 3.
        let piece = Piece::Frustum { h0: 1.0, h1: 3.0, r0: 2.0, k: -0.5 };
        let a = Vec3::new(0.6, 0.0, 0.8);
        let mut rng = crate::test_support::Lcg(7);
        for _ in 0..500 {
            let (w0, d) = random_line(&mut rng, 3.0);
            let span = piece.hit(&Line::new(a, w0, d));
            assert_samples_in_span(w0, d, 3000, span, |q| {
                let h = q.dot(&a);
                let rho = (q - h * a).norm();
                (1.0..=3.0).contains(&h) && rho <= 2.0 - 0.5 * (h - 1.0)
            });
        }
    }

    #[test]
    fn support_is_the_max() {
        let cutter = Cutter::new(CutterShape::Bull { radius: 2.0, corner: 0.5 }, 4.0).unwrap();
        let body = Body::flutes(&cutter);
        let a = Vec3::new(0.0, 0.6, 0.8);
        for m in [Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.2, -0.3, -0.9), Vec3::new(0.0, 0.0, 1.0)] {
            let (v, p) = body.support(&a, &m);
            scallop_geom::assert_near!(m.dot(&p), v, 1e-12);
            // No point of a dense profile sampling beats it.
            for i in 0..=200 {
                let h = 4.0 * f64::from(i) / 200.0;
                let r = cutter.shape().radius_at(h);
                for j in 0..64 {
                    let th = std::f64::consts::TAU * f64::from(j) / 64.0;
                    let e1 = Vec3::new(1.0, 0.0, 0.0);
                    let e2 = a.cross(&e1);
                    let q = h * a + r * (th.cos() * e1 + th.sin() * e2);
                    assert!(m.dot(&q) <= v + 1e-9);
                }
            }
        }
    }
}
