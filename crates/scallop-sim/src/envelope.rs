//! The lower envelope of a cutter swept along one straight 3-axis move.
//!
//! # Derivation
//!
//! The tool axis is +Z. The tip moves from `A` to `B`; its XY travel has
//! length `L` along the unit direction `e`, its z changes by `dz`, and
//! `m = dz / L` is the slope. For a stock point `p` (XY), let
//!
//! ```text
//! u = (p - A) . e          along-move coordinate of p
//! d = |(p - A) x e|        distance of p from the line of the move
//! ```
//!
//! When the tip's along-move coordinate is `u + w`, the horizontal distance
//! from the axis to `p` is `rho(w) = sqrt(w^2 + d^2)`, and the cutter's lower
//! surface above `p` is at
//!
//! ```text
//! z(w) = z_A + m (u + w) + h(rho(w)),   w in [-u, L - u]  (tip on the segment)
//!                                       |w| <= c = sqrt(R^2 - d^2)  (p under the cutter)
//! ```
//!
//! where `h` is the profile height (`CutterShape::height_at`). The swept floor
//! at `p` is `min z(w)` over that interval (none when it is empty).
//!
//! `rho(w)` is convex in `w` and every profile `h` is convex and non-decreasing
//! on `[0, R]`, so `g(w) = h(rho(w))` is convex and `f(w) = m w + g(w)` is
//! convex: its minimum over an interval is its unconstrained minimiser clamped
//! to the interval. The unconstrained minimiser solves `f'(w) = 0`:
//!
//! - **flat** (`h = 0`): `f = m w` is monotone; the minimum is at the lower end
//!   of the interval when `m > 0`, else at the upper end.
//! - **ball** (`h = R - sqrt(R^2 - rho^2)`, so `g = R - sqrt(c^2 - w^2)`):
//!   `m + w / sqrt(c^2 - w^2) = 0` gives `w* = -m c / sqrt(1 + m^2)`.
//! - **cone** (`h = rho / tan(a)`): `m + cot(a) w / rho = 0`, i.e.
//!   `w / rho = k` with `k = -m tan(a)`. For `|k| < 1`: `w* = k d / sqrt(1 - k^2)`;
//!   for `|k| >= 1` the move descends at least as steeply as the flank and `f` is
//!   monotone (the minimum is at an end, as for the flat cutter).
//! - **bull-nose** (flat bottom of radius `R - r`, torus corner of radius `r`):
//!   `f'(w) = m + h'(rho) w / rho` with `h'(rho) = s / sqrt(r^2 - s^2)`,
//!   `s = rho - (R - r)` (0 on the flat bottom). `f'` is continuous and
//!   non-decreasing (f is convex, C1), so its root is bracketed by the
//!   interval's ends and found by Newton steps kept inside a shrinking bracket
//!   (bisection as the fallback) to `tol::PARAMETER_CONVERGENCE` of the cutter
//!   radius; the value error is the derivative there times that width (far
//!   below 1e-9 mm). No sampling along the move anywhere.
//!
//! A vertical move (`L = 0`, or a slope above [`crate::tol::VERTICAL_SLOPE`]) leaves
//! `min(z_A, z_B) + h(|p - A|)`.
//!
//! The envelope only covers the cutting profile (rho <= R); the flutes above
//! it and the shank are handled by the caller (a z-map removes the whole column
//! above the floor).

use scallop_cutter::CutterShape;
use scallop_geom::tol::PARAMETER_CONVERGENCE;

use crate::tol::{FLOOR_BOUND_MARGIN, VERTICAL_SLOPE};
use scallop_geom::{Point2, Point3};

/// Profile constants (no trigonometry per cell).
#[derive(Debug, Clone, Copy)]
enum Profile {
    Flat,
    Ball,
    Bull { flat_radius: f64, corner: f64 },
    Cone { tan: f64, cot: f64 },
}

/// One straight move with everything the per-cell solve needs.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SweptMove {
    profile: Profile,
    radius: f64,
    radius2: f64,
    /// Added to the floor (for shank and holder discs above the tip).
    lift: f64,
    ax: f64,
    ay: f64,
    az: f64,
    ex: f64,
    ey: f64,
    len: f64,
    dz: f64,
    slope: f64,
    vertical: bool,
    /// Ball: `1 / sqrt(1 + m^2)`. Cone: `k / sqrt(1 - k^2)` when `|k| < 1`.
    factor: f64,
    /// Cone: whether `f` is monotone (|k| >= 1).
    monotone: bool,
    /// `1 / L` (0 for vertical moves).
    inv_len: f64,
    /// Ball: `sqrt(1 + m^2)`.
    secant: f64,
    /// `k` of the quadratic lower bound `h(rho) >= k rho^2` (ball `1 / 2R`,
    /// cone `cot / R`, else 0), see [`SweptMove::floor_below`].
    quadratic: f64,
    /// Lowest tip z plus lift: a lower bound of the floor everywhere.
    pub(crate) z_low: f64,
    /// A planar circular arc instead of a straight move (see [`SweptMove::arc`]).
    arc: Option<PlanarArc>,
}

/// A planar arc of the tip: centre, radius, start angle, signed sweep, and
/// its two end points.
#[derive(Debug, Clone, Copy)]
struct PlanarArc {
    cx: f64,
    cy: f64,
    r: f64,
    start: f64,
    sweep: f64,
    ends: [(f64, f64); 2],
}

impl SweptMove {
    /// The cutting profile `shape` moving from `from` to `to`.
    pub(crate) fn new(shape: &CutterShape, from: &Point3, to: &Point3) -> SweptMove {
        let (profile, radius) = match *shape {
            CutterShape::Flat { radius } => (Profile::Flat, radius),
            CutterShape::Ball { radius } => (Profile::Ball, radius),
            CutterShape::Bull { radius, corner } => (Profile::Bull { flat_radius: radius - corner, corner }, radius),
            CutterShape::Cone { radius, half_angle } => {
                let tan = half_angle.tan();
                (Profile::Cone { tan, cot: 1.0 / tan }, radius)
            }
        };
        Self::with_profile(profile, radius, 0.0, from, to)
    }

    /// A flat disc of `radius` at `lift` above the tip (shank, holder).
    pub(crate) fn disc(radius: f64, lift: f64, from: &Point3, to: &Point3) -> SweptMove {
        Self::with_profile(Profile::Flat, radius, lift, from, to)
    }

    fn with_profile(profile: Profile, radius: f64, lift: f64, from: &Point3, to: &Point3) -> SweptMove {
        let (dx, dy, dz) = (to.x - from.x, to.y - from.y, to.z - from.z);
        let len = dx.hypot(dy);
        let slope = if len > 0.0 { dz / len } else { 0.0 };
        // NaN or infinite slopes (len tiny) are vertical too.
        let vertical = len <= 0.0 || slope.abs().partial_cmp(&VERTICAL_SLOPE) != Some(std::cmp::Ordering::Less);
        let (ex, ey) = if vertical { (0.0, 0.0) } else { (dx / len, dy / len) };
        let quadratic = match profile {
            Profile::Ball => 0.5 / radius,
            Profile::Cone { cot, .. } => cot / radius,
            Profile::Flat | Profile::Bull { .. } => 0.0,
        };
        let (factor, monotone) = match profile {
            Profile::Ball => (1.0 / (1.0 + slope * slope).sqrt(), false),
            Profile::Cone { tan, .. } => {
                let k = -slope * tan;
                if k.abs() < 1.0 { (k / (1.0 - k * k).sqrt(), false) } else { (0.0, true) }
            }
            Profile::Flat | Profile::Bull { .. } => (0.0, false),
        };
        SweptMove {
            profile,
            radius,
            radius2: radius * radius,
            lift,
            ax: from.x,
            ay: from.y,
            az: from.z,
            ex,
            ey,
            len,
            dz,
            slope,
            vertical,
            factor,
            monotone,
            inv_len: if vertical { 0.0 } else { 1.0 / len },
            secant: (1.0 + slope * slope).sqrt(),
            quadratic,
            z_low: from.z.min(to.z) + lift,
            arc: None,
        }
    }

    /// The profile `shape` (or, with `disc`, a flat disc of that radius at
    /// `lift` above the tip) moving at constant z along a circular arc of the XY
    /// plane from `from` around `center` by `sweep` radians (positive
    /// counter-clockwise) to `to`.
    ///
    /// # Derivation
    /// At constant z the cutter's lower surface above a point `p` is at
    /// `z + h(rho)`, `rho` the horizontal distance from the axis to `p`, and `h`
    /// is non-decreasing on [0, R]: the swept floor is `z + h(d)` with `d` the
    /// distance from `p` to the tip's arc (none when `d > R`). With `a = |p - c|`
    /// and `phi` the angle of `p` about `c`: `d = |a - r|` when `phi` lies in the
    /// swept range (the nearest point of the circle is on the arc), else the
    /// distance to the nearer end point (the distance to the circle point at
    /// angle `theta` grows with the angle between `theta` and `phi`). At the
    /// centre (`a = 0`) every point of the arc is at `r`. Exact: no sampling.
    pub(crate) fn arc(
        shape: Option<&CutterShape>,
        disc: (f64, f64),
        from: &Point3,
        to: &Point3,
        center: Point2,
        sweep: f64,
    ) -> SweptMove {
        let mut m = match shape {
            Some(shape) => SweptMove::new(shape, from, from),
            None => SweptMove::disc(disc.0, disc.1, from, from),
        };
        let start = (from.y - center.y).atan2(from.x - center.x);
        let r = (from.x - center.x).hypot(from.y - center.y);
        m.arc = Some(PlanarArc { cx: center.x, cy: center.y, r, start, sweep, ends: [(from.x, from.y), (to.x, to.y)] });
        m
    }

    /// The floor of an arc move (see [`SweptMove::arc`]).
    #[inline(never)]
    fn arc_floor(&self, arc: &PlanarArc, x: f64, y: f64) -> f64 {
        let (qx, qy) = (x - arc.cx, y - arc.cy);
        let a = qx.hypot(qy);
        let along = if arc.sweep.abs() >= std::f64::consts::TAU || a == 0.0 {
            true
        } else {
            let phi = qy.atan2(qx);
            let delta = if arc.sweep > 0.0 { phi - arc.start } else { arc.start - phi };
            delta.rem_euclid(std::f64::consts::TAU) <= arc.sweep.abs()
        };
        let d = if along {
            (a - arc.r).abs()
        } else {
            let [(x0, y0), (x1, y1)] = arc.ends;
            (x - x0).hypot(y - y0).min((x - x1).hypot(y - y1))
        };
        let d2 = d * d;
        if d2 > self.radius2 {
            return f64::INFINITY;
        }
        self.z_low + self.profile_height(0.0, d2, self.radius2 - d2)
    }

    /// The XY box of the tip's path: the two ends and the circle's extreme
    /// points within the sweep (for an arc).
    pub(crate) fn tip_box(&self, from: &Point3, to: &Point3) -> (Point2, Point2) {
        let mut lo = Point2::new(from.x.min(to.x), from.y.min(to.y));
        let mut hi = Point2::new(from.x.max(to.x), from.y.max(to.y));
        if let Some(arc) = &self.arc {
            for k in 0..4 {
                let theta = f64::from(k) * std::f64::consts::FRAC_PI_2;
                let delta = if arc.sweep > 0.0 { theta - arc.start } else { arc.start - theta };
                if arc.sweep.abs() >= std::f64::consts::TAU
                    || delta.rem_euclid(std::f64::consts::TAU) <= arc.sweep.abs()
                {
                    let (px, py) = (arc.cx + arc.r * theta.cos(), arc.cy + arc.r * theta.sin());
                    lo = Point2::new(lo.x.min(px), lo.y.min(py));
                    hi = Point2::new(hi.x.max(px), hi.y.max(py));
                }
            }
        }
        (lo, hi)
    }

    /// Whether this is an arc move.
    pub(crate) fn is_arc(&self) -> bool {
        self.arc.is_some()
    }

    /// Height of the profile above the tip at `w` along the move from the foot
    /// of `p`, with `d2 = d^2`, `c2 = R^2 - d^2 >= w^2`.
    #[inline]
    fn profile_height(&self, w: f64, d2: f64, c2: f64) -> f64 {
        match self.profile {
            Profile::Flat => 0.0,
            Profile::Ball => self.radius - (c2 - w * w).max(0.0).sqrt(),
            Profile::Bull { flat_radius, corner } => {
                let s = (w * w + d2).sqrt() - flat_radius;
                if s <= 0.0 { 0.0 } else { corner - (corner * corner - s * s).max(0.0).sqrt() }
            }
            Profile::Cone { cot, .. } => cot * (w * w + d2).sqrt(),
        }
    }

    /// The swept floor at (x, y), or `f64::INFINITY` when the move does not reach it.
    #[inline]
    pub(crate) fn floor_at(&self, x: f64, y: f64) -> f64 {
        self.floor_below(x, y, f64::INFINITY)
    }

    /// The swept floor at (x, y) when it may lie below `limit`; otherwise (or
    /// out of reach) some value `>= limit`, possibly infinite. The proof is a
    /// lower bound without square roots: every profile satisfies
    /// `h(rho) >= k rho^2` on [0, R] (ball: `R - sqrt(R^2 - rho^2) =
    /// rho^2 / (R + sqrt(R^2 - rho^2)) >= rho^2 / 2R`; cone: `rho cot >= rho^2 cot / R`;
    /// flat and bull-nose: k = 0), so `z(w) >= z_A + m (u + w) + k (w^2 + d^2)`,
    /// a parabola whose minimum over the move is in closed form.
    #[inline(always)] // hot: called per cell and move; inlining lets the row loop keep state in registers
    pub(crate) fn floor_below(&self, x: f64, y: f64, limit: f64) -> f64 {
        if let Some(arc) = &self.arc {
            return self.arc_floor(arc, x, y);
        }
        let (qx, qy) = (x - self.ax, y - self.ay);
        if self.vertical {
            let rho2 = qx * qx + qy * qy;
            if rho2 > self.radius2 {
                return f64::INFINITY;
            }
            let bound = self.z_low + self.quadratic * rho2;
            if bound >= limit {
                return bound;
            }
            return self.z_low + self.profile_height(0.0, rho2, self.radius2 - rho2);
        }
        let u = qx * self.ex + qy * self.ey;
        let v = qx * self.ey - qy * self.ex;
        let d2 = v * v;
        let c2 = self.radius2 - d2;
        if c2 < 0.0 {
            return f64::INFINITY;
        }
        let (lo_tip, hi_tip) = (-u, self.len - u);
        {
            // Lower bound: min of m w + k w^2 over the tip's interval (k >= 0).
            let w = if self.quadratic > 0.0 {
                (-0.5 * self.slope / self.quadratic).clamp(lo_tip, hi_tip)
            } else if self.slope > 0.0 {
                lo_tip
            } else {
                hi_tip
            };
            let bound = self.az + self.slope * (u + w) + self.quadratic * (w * w + d2) + self.lift;
            if bound >= limit {
                return bound;
            }
        }
        if matches!(self.profile, Profile::Ball) {
            return self.ball_floor(u, c2);
        }
        let c = c2.sqrt();
        let lo = lo_tip.max(-c);
        let hi = hi_tip.min(c);
        if lo > hi {
            return f64::INFINITY;
        }
        if let Profile::Bull { .. } = self.profile {
            // Lower bound without the iterative solve: the tip's lowest z
            // over [lo, hi] plus the profile at the smallest rho there
            // (`rho(w)` is smallest at the w nearest 0, `h` non-decreasing).
            let w_tip = if self.slope > 0.0 { lo } else { hi };
            let w_near = 0.0f64.clamp(lo, hi);
            let near2 = w_near * w_near + d2;
            let bound =
                self.az + self.slope * (u + w_tip) + self.profile_height(0.0, near2, self.radius2 - near2) + self.lift
                    - FLOOR_BOUND_MARGIN;
            if bound >= limit {
                return bound;
            }
        }
        let w = match self.profile {
            Profile::Flat => {
                if self.slope > 0.0 {
                    lo
                } else {
                    hi
                }
            }
            // Returned above by `ball_floor`; the plain clamped minimiser here.
            Profile::Ball => (-self.slope * c * self.factor).clamp(lo, hi),
            Profile::Cone { .. } => {
                if self.monotone {
                    if self.slope > 0.0 { lo } else { hi }
                } else {
                    (self.factor * d2.sqrt()).clamp(lo, hi)
                }
            }
            Profile::Bull { flat_radius, corner } => self.bull_minimiser(lo, hi, d2, flat_radius, corner),
        };
        let t = ((u + w) * self.inv_len).clamp(0.0, 1.0);
        self.az + self.dz * t + self.profile_height(w, d2, c2) + self.lift
    }

    /// The ball's floor with one square root. Its minimiser `w* = -mu c`,
    /// `mu = m / sqrt(1 + m^2)`, lies strictly inside (-c, c), so the minimum is
    /// at the tip's start (`w* < -u`), at its end (`w* > L - u`) or at `w*`, and
    /// these comparisons of `u` with `mu c` are made on squares, without `c`:
    /// - interior: `m w* - sqrt(c^2 - w*^2) = -c sqrt(1 + m^2)`, so
    ///   `z = z_A + m u + R - c sqrt(1 + m^2)`;
    /// - an end: the static ball there, `z_end + R - sqrt(c^2 - w^2)`.
    #[inline(always)]
    fn ball_floor(&self, u: f64, c2: f64) -> f64 {
        let e = u - self.len;
        // The tip's interval [-u, L - u] misses [-c, c].
        if (u < 0.0 && u * u > c2) || (e > 0.0 && e * e > c2) {
            return f64::INFINITY;
        }
        let mu = self.slope * self.factor;
        let mu2c2 = mu * mu * c2;
        // u < mu c, and e > mu c.
        let before = if mu >= 0.0 { u < 0.0 || u * u < mu2c2 } else { u < 0.0 && u * u > mu2c2 };
        let after = if mu >= 0.0 { e > 0.0 && e * e > mu2c2 } else { e > 0.0 || e * e < mu2c2 };
        let (w, tip_z) = if before {
            (-u, self.az)
        } else if after {
            (-e, self.az + self.dz)
        } else {
            return self.az + self.slope * u + self.radius - c2.sqrt() * self.secant + self.lift;
        };
        tip_z + self.radius - (c2 - w * w).max(0.0).sqrt() + self.lift
    }

    /// Root of the non-decreasing `f'(w) = m + h'(rho) w / rho` in [lo, hi]
    /// (or the end where `f'` keeps its sign): Newton steps on
    /// `f''(w) = h''(rho) (w / rho)^2 + h'(rho) d^2 / rho^3`
    /// (`h' = s / sqrt(r^2 - s^2)`, `h'' = r^2 / (r^2 - s^2)^(3/2)`) kept inside a
    /// bracket that every evaluation shrinks, with bisection whenever a step
    /// leaves it or `f''` vanishes (flat bottom) or is infinite (rim). Stops
    /// when the bracket or the step is below `PARAMETER_CONVERGENCE * R`.
    fn bull_minimiser(&self, mut lo: f64, mut hi: f64, d2: f64, flat_radius: f64, corner: f64) -> f64 {
        let m = self.slope;
        // (f'(w), f''(w)); f'' = NaN where a Newton step is not defined.
        let derivatives = |w: f64| {
            let rho = (w * w + d2).sqrt();
            let s = rho - flat_radius;
            if s <= 0.0 {
                return (m, f64::NAN);
            }
            let q = corner * corner - s * s;
            if q <= 0.0 {
                // At the rim h' is infinite: the sign of w decides.
                let first = if w > 0.0 {
                    f64::INFINITY
                } else if w < 0.0 {
                    f64::NEG_INFINITY
                } else {
                    m
                };
                return (first, f64::NAN);
            }
            let root = q.sqrt();
            let (h1, h2) = (s / root, corner * corner / (q * root));
            let cos = w / rho;
            (m + h1 * cos, h2 * cos * cos + h1 * d2 / (rho * rho * rho))
        };
        if derivatives(lo).0 >= 0.0 {
            return lo;
        }
        if derivatives(hi).0 <= 0.0 {
            return hi;
        }
        let width = PARAMETER_CONVERGENCE * self.radius;
        let mut w = 0.5 * (lo + hi);
        // Each round shrinks the bracket; bisection alone needs ~35 rounds, so
        // the cap is never reached.
        for _ in 0..200 {
            let (first, second) = derivatives(w);
            if first > 0.0 {
                hi = w;
            } else if first < 0.0 {
                lo = w;
            } else {
                return w;
            }
            if hi - lo <= width {
                break;
            }
            let newton = w - first / second;
            if second > 0.0 && newton > lo && newton < hi {
                if (newton - w).abs() <= width {
                    return newton;
                }
                w = newton;
            } else {
                w = 0.5 * (lo + hi);
            }
        }
        0.5 * (lo + hi)
    }

    /// XY reach of the move: its horizontal radius (profile plus nothing else).
    pub(crate) fn radius(&self) -> f64 {
        self.radius
    }

    /// The vertical line at (x, y) inside the swept solid of the whole
    /// cutting body (the profile and a cylinder of radius R up to `top` above
    /// the tip: the flutes), or `None` when the move does not reach it. The
    /// solid is convex, so the line meets it in one interval: from the swept
    /// floor ([`SweptMove::floor_at`]) to the highest top of the cylinder over
    /// the positions where the axis is within R of the line (the tip's z is
    /// linear along the move, so that is an end of the interval of positions,
    /// `w` in `[max(-u, -c), min(L - u, c)]` in the module's notation). Exact:
    /// closed forms, the bull-nose floor to the solver's tolerance.
    pub(crate) fn column(&self, x: f64, y: f64, top: f64) -> Option<(f64, f64)> {
        debug_assert!(self.arc.is_none(), "columns of straight moves only");
        let floor = self.floor_at(x, y);
        if !floor.is_finite() {
            return None;
        }
        let (qx, qy) = (x - self.ax, y - self.ay);
        let ceiling = if self.vertical {
            self.az.max(self.az + self.dz)
        } else {
            let u = qx * self.ex + qy * self.ey;
            let v = qx * self.ey - qy * self.ex;
            let c = (self.radius2 - v * v).max(0.0).sqrt();
            let (lo, hi) = ((-u).max(-c), (self.len - u).min(c));
            let w = if self.slope > 0.0 { hi.max(lo) } else { lo.min(hi) };
            self.az + self.dz * ((u + w) * self.inv_len).clamp(0.0, 1.0)
        };
        Some((floor, ceiling + top + self.lift))
    }

    /// A lower bound of the floor at every point at horizontal distance `>= d`
    /// (`d2 = d^2`) from the tip's path: `z_low + h(min(d, R))`, less
    /// `tol::FLOOR_BOUND_MARGIN` (rounding), and never below the quadratic
    /// bound `z_low + k d^2` (`k` of [`SweptMove::floor_below`]).
    pub(crate) fn floor_bound(&self, d2: f64) -> f64 {
        let rho2 = d2.min(self.radius2);
        let exact = self.z_low + self.profile_height(0.0, rho2, self.radius2 - rho2) - FLOOR_BOUND_MARGIN;
        exact.max(self.z_low + self.quadratic * d2)
    }
}

/// The lowest z of the lower envelope of `shape` (tool axis +Z) swept with its
/// tip along the straight move `from -> to`, above the point `at`, or `None`
/// when the cutter never covers `at` (horizontal distance to the move above
/// the cutter radius). Exact per shape (closed forms for flat, ball and cone,
/// a bracketed root of a monotone derivative for the bull-nose; see the module
/// derivation), never sampled along the move.
///
/// ```
/// use scallop_cutter::CutterShape;
/// use scallop_geom::{Point2, Point3};
/// use scallop_sim::swept_floor;
/// let ball = CutterShape::Ball { radius: 2.0 };
/// let (a, b) = (Point3::new(0.0, 0.0, 0.0), Point3::new(10.0, 0.0, 0.0));
/// // 1 mm beside a horizontal pass the ball's surface is at R - sqrt(R^2 - 1).
/// let z = swept_floor(&ball, &a, &b, &Point2::new(5.0, 1.0)).unwrap();
/// assert!((z - (2.0 - 3f64.sqrt())).abs() < 1e-12);
/// assert_eq!(swept_floor(&ball, &a, &b, &Point2::new(5.0, 2.5)), None);
/// ```
#[must_use]
pub fn swept_floor(shape: &CutterShape, from: &Point3, to: &Point3, at: &Point2) -> Option<f64> {
    let z = SweptMove::new(shape, from, to).floor_at(at.x, at.y);
    z.is_finite().then_some(z)
}
