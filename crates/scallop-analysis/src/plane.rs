//! Analytic models of rectangular planes (finishing.md 8, 12.7 / Annex E, 14.4):
//! times and lengths of zigzag parallel-plane strategies, critical slope `s_c(mu)`
//! and critical shape factor `mu_c(s)`.
//!
//! Lengths mm, areas mm^2, angles rad, times s.

use std::f64::consts::FRAC_PI_2;

use serde::{Deserialize, Serialize};

use crate::cutter::{Cutter, fold_direction_angle, step_over};
use crate::error::AnalysisError;
use crate::kinematics::MachineLimits;
use crate::pca::{Pca, direction_angle_xy};
use crate::tol;

/// The two cutters the advisor compares (finishing.md 10). [`Default`]: the spec's
/// tools (finishing.md 13): ball `R = 5 mm`, toroidal `R = 5 mm`, `r = 2 mm`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ToolOptions {
    /// Ball-end cutter radius `R` (mm).
    pub ball_radius: f64,
    /// Toroidal cutter outer radius `R` (mm).
    pub toroidal_radius: f64,
    /// Toroidal cutter corner radius `r` (mm), `0 <= r <= R`.
    pub corner_radius: f64,
}

impl Default for ToolOptions {
    fn default() -> Self {
        ToolOptions { ball_radius: 5.0, toroidal_radius: 5.0, corner_radius: 2.0 }
    }
}

impl ToolOptions {
    /// The ball cutter.
    #[must_use]
    pub fn ball(&self) -> Cutter {
        Cutter::Ball { radius: self.ball_radius }
    }

    /// The toroidal cutter.
    #[must_use]
    pub fn toroidal(&self) -> Cutter {
        Cutter::Toroidal { radius: self.toroidal_radius, corner: self.corner_radius }
    }

    /// Checks the radii and that `0 < scallop_height < min(ball R, toroidal R)`.
    ///
    /// ```
    /// let tools = scallop_analysis::ToolOptions::default();
    /// assert!(tools.validate(0.01).is_ok() && tools.validate(0.0).is_err());
    /// ```
    ///
    /// # Errors
    /// [`AnalysisError::BadTool`] or [`AnalysisError::BadScallopHeight`].
    pub fn validate(&self, scallop_height: f64) -> Result<(), AnalysisError> {
        for (what, value) in [("ball radius", self.ball_radius), ("toroidal radius", self.toroidal_radius)] {
            if !(value.is_finite() && value > 0.0) {
                return Err(AnalysisError::BadTool { what, value });
            }
        }
        let corner = self.corner_radius;
        if !(corner.is_finite() && corner >= 0.0 && corner <= self.toroidal_radius) {
            return Err(AnalysisError::BadTool { what: "corner radius", value: corner });
        }
        let smallest = self.ball_radius.min(self.toroidal_radius);
        if !(scallop_height.is_finite() && scallop_height > 0.0 && scallop_height < smallest) {
            return Err(AnalysisError::BadScallopHeight { value: scallop_height });
        }
        Ok(())
    }
}

/// A plane rectangle of width `w` (along the principal direction) and height
/// `h <= w` (along the steepest slope, perpendicular to it), tilted by `slope`
/// (finishing.md 8.1).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Rectangle {
    /// `w` (mm).
    pub width: f64,
    /// `h` (mm).
    pub height: f64,
    /// Tilt `s` (rad).
    pub slope: f64,
}

impl Rectangle {
    /// The rectangle of shape factor `mu = w/h` and size `chi = w h` (Eq. 2.1):
    /// `w = sqrt(mu chi)`, `h = sqrt(chi / mu)`.
    ///
    /// ```
    /// let r = scallop_analysis::Rectangle::from_shape(2.0, 1568.0, 1.0);
    /// assert!((r.width - 56.0).abs() < 1e-12 && (r.height - 28.0).abs() < 1e-12);
    /// ```
    #[must_use]
    pub fn from_shape(shape_factor: f64, size: f64, slope: f64) -> Rectangle {
        Rectangle { width: (shape_factor * size).sqrt(), height: (size / shape_factor).sqrt(), slope }
    }

    /// `mu = w / h`.
    #[must_use]
    pub fn shape_factor(&self) -> f64 {
        self.width / self.height
    }

    /// `chi = w h` (mm^2).
    #[must_use]
    pub fn size(&self) -> f64 {
        self.width * self.height
    }
}

/// Feed direction of a strategy on a plane.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FeedDirection {
    /// Passes along the principal direction `S_I` (long passes, few of them).
    Principal,
    /// Passes along the steepest slope (largest toroidal step-over).
    SteepestSlope,
}

/// Time and length of a zigzag parallel-plane strategy on a plane region.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PlaneTime {
    /// Step-over between passes (mm).
    pub step_over: f64,
    /// Number of passes (real, not rounded: finishing.md 8.4).
    pub passes: f64,
    /// Total path length: passes plus connections (mm).
    pub length: f64,
    /// Machining time (s).
    pub time: f64,
}

/// `passes = extent / step_over` passes of length `pass_length`, each followed by a
/// connection of length `step_over`; every pass and connection is one stop-to-stop
/// move timed by [`MachineLimits::segment_time`]:
///
/// ```text
/// n = extent / sod,  L = n (pass_length + sod),  T = n (t(pass_length) + t(sod))
/// ```
///
/// With passes longer than `2 sqrt(V^3/J)` (7.607 mm by default) and step-overs
/// shorter, `t(pass) = pass/V + 2 sqrt(V/J)` and `t(sod) = 4 cbrt(sod / (2J))`: the
/// closed forms of finishing.md 8.2, 8.3 and 14.4 exactly; outside that regime this
/// is their kinematically correct generalisation (continuous across the cases).
///
/// ```
/// use scallop_analysis::{MachineLimits, strip_time};
/// let t = strip_time(10.0, 40.0, 0.5, &MachineLimits::default());
/// assert_eq!(t.passes, 20.0);
/// assert!((t.length - 20.0 * 40.5).abs() < 1e-9);
/// ```
#[must_use]
pub fn strip_time(extent: f64, pass_length: f64, step_over: f64, machine: &MachineLimits) -> PlaneTime {
    if !(extent > 0.0 && step_over > 0.0) || step_over.is_infinite() {
        return PlaneTime { step_over, passes: 0.0, length: 0.0, time: 0.0 };
    }
    let passes = extent / step_over;
    PlaneTime {
        step_over,
        passes,
        length: passes * (pass_length + step_over),
        time: passes * (machine.segment_time(pass_length) + machine.segment_time(step_over)),
    }
}

/// Analytic time and length of machining `rect` with `cutter` along `feed`
/// (finishing.md 8.2, 8.3, with the corrected L1 and L2):
///
/// - [`FeedDirection::SteepestSlope`]: passes of length `h` stacked across `w`,
///   step-over at `alpha = 0` (Eq. 2.2 for a toroidal cutter: `T1`, `L1`);
/// - [`FeedDirection::Principal`]: passes of length `w` stacked across `h`,
///   step-over at `alpha = pi/2` (ball: `T2`, `L2`; toroidal: `R_eff = r`).
///
/// Step-overs are capped by [`Cutter::max_step_over`] (finishing.md 5.3), so a
/// horizontal rectangle has a finite time. See [`strip_time`] for the timing.
///
/// ```
/// use scallop_analysis::{plane_time, FeedDirection, MachineLimits, Rectangle, ToolOptions};
/// let rect = Rectangle { width: 56.0, height: 28.0, slope: 60f64.to_radians() };
/// let (tools, m) = (ToolOptions::default(), MachineLimits::default());
/// let t1 = plane_time(&rect, &tools.toroidal(), FeedDirection::SteepestSlope, 0.01, &m);
/// let t2 = plane_time(&rect, &tools.ball(), FeedDirection::Principal, 0.01, &m);
/// assert!((t1.time - 43.06).abs() < 0.01 && (t2.time - 37.34).abs() < 0.01);   // A3
/// ```
#[must_use]
pub fn plane_time(
    rect: &Rectangle,
    cutter: &Cutter,
    feed: FeedDirection,
    scallop_height: f64,
    machine: &MachineLimits,
) -> PlaneTime {
    match feed {
        FeedDirection::SteepestSlope => {
            let sod = cutter.step_over(scallop_height, rect.slope, 0.0);
            strip_time(rect.width, rect.height, sod, machine)
        }
        FeedDirection::Principal => {
            let sod = cutter.step_over(scallop_height, rect.slope, FRAC_PI_2);
            strip_time(rect.height, rect.width, sod, machine)
        }
    }
}

/// `2 sqrt(V/J) + 4 cbrt(sod / (2J))`: the kinematic overhead of one pass (case 2)
/// plus one connection of length `sod` (case 3), the constant of Eqs. 2.4, 2.5.
fn pass_overhead(sod: f64, machine: &MachineLimits) -> f64 {
    2.0 * machine.time_to_feed() + 4.0 * (sod / (2.0 * machine.jerk)).cbrt()
}

/// Closed-form `T2` (Eq. 2.5): ball along the principal direction of the rectangle
/// `(mu, chi)`, in the regime of finishing.md 8.4.
fn closed_form_ball_time(shape_factor: f64, size: f64, sod2: f64, machine: &MachineLimits) -> f64 {
    let (root_mu, root_chi) = (shape_factor.sqrt(), size.sqrt());
    root_chi / (root_mu * sod2) * (root_chi * root_mu / machine.feed + pass_overhead(sod2, machine))
}

/// Critical slope `s_c(mu)` (rad) for a rectangle of shape factor `mu` and size
/// `chi` (mm^2): the tilt at which the toroidal cutter along the slope (`T1`, Eq. 2.4)
/// and the ball along the principal direction (`T2`, Eq. 2.5) take the same time
/// (finishing.md 8.5). Below it the toroidal cutter is faster.
///
/// With `z = cbrt(sod1)`, `T1 = T2` is `z^3 - p z - q = 0` (Eq. 2.6),
/// `p = 4 sqrt(mu chi) / (T2 cbrt(2J))`, `q = (sqrt(mu chi)/T2)(sqrt(chi)/(sqrt(mu) V) + 2 sqrt(V/J))`,
/// `Delta = 4p^3 - 27q^2`. Its unique positive root is Cardano's (Eq. 2.9 with the
/// sign erratum fixed: `+q` inside the cube roots)
///
/// ```text
/// z = cbrt((q + sqrt(-Delta/27)) / 2) + cbrt((q - sqrt(-Delta/27)) / 2)      (Delta < 0)
/// z = 2 sqrt(p/3) cos( acos( (3q/(2p)) sqrt(3/p) ) / 3 )                     (Delta >= 0)
/// ```
///
/// and Eq. 2.10 (`sod1^2 = z^6`, `R_eff = (z^6 + 4 sh^2)/(8 sh) = (R - r)/sin s + r`):
/// `s_c = arcsin( 8 sh (R - r) / (z^6 + 4 sh^2 - 8 sh r) )`, `pi/2` when the
/// argument is `>= 1` or not positive-definite (e.g. `mu = 1`). `T1`, `T2` are the
/// closed forms (passes in case 2, connections in case 3, uncapped step-over), as
/// in the derivation. The ball and toroidal radii may differ.
///
/// ```
/// use scallop_analysis::{critical_slope, MachineLimits, ToolOptions};
/// let s = critical_slope(2.0, 1568.0, &ToolOptions::default(), 0.01, &MachineLimits::default());
/// assert!((s.to_degrees() - 33.86).abs() < 0.01);                                // A4
/// ```
#[must_use]
pub fn critical_slope(
    shape_factor: f64,
    size: f64,
    tools: &ToolOptions,
    scallop_height: f64,
    machine: &MachineLimits,
) -> f64 {
    let sh = scallop_height;
    let (radius, corner) = (tools.toroidal_radius, tools.corner_radius);
    let sod2 = step_over(sh, tools.ball_radius);
    let t2 = closed_form_ball_time(shape_factor, size, sod2, machine);
    let root_mu_chi = (shape_factor * size).sqrt();
    let p = 4.0 * root_mu_chi / (t2 * (2.0 * machine.jerk).cbrt());
    let q = root_mu_chi / t2 * (size.sqrt() / (shape_factor.sqrt() * machine.feed) + 2.0 * machine.time_to_feed());
    let delta = 4.0 * p.powi(3) - 27.0 * q * q;
    let z = if delta < 0.0 {
        let root = (-delta / 27.0).sqrt();
        ((q + root) / 2.0).cbrt() + ((q - root) / 2.0).cbrt()
    } else {
        let cosine = (3.0 * q / (2.0 * p) * (3.0 / p).sqrt()).clamp(-1.0, 1.0);
        2.0 * (p / 3.0).sqrt() * (cosine.acos() / 3.0).cos()
    };
    let denominator = z.powi(6) + 4.0 * sh * sh - 8.0 * sh * corner;
    let argument = 8.0 * sh * (radius - corner) / denominator;
    if denominator > 0.0 && argument < 1.0 { argument.max(0.0).asin() } else { FRAC_PI_2 }
}

/// Critical shape factor `mu_c(s)` for a rectangle of size `chi` (mm^2) tilted by
/// `slope` (rad): the `mu` at which `T1 = T2` (finishing.md 8.6, Annex A.1, Eq. 8).
/// Above it the ball along the principal direction is faster. With
/// `k = sod2 / sod1` (uncapped Eq. 2.3 step-overs, as [`critical_slope`], of which it
/// is the inverse: `mu_c(s_c(mu)) = mu`):
///
/// ```text
/// sqrt(mu_c) = ( (sqrt(chi)/V)(1 - k) + sqrt( (chi/V^2)(1 - k)^2 + 16 k K1 K2 ) ) / (4 k K1),
/// K1 = sqrt(V/J) + 2 cbrt(sod1/(2J)),  K2 = sqrt(V/J) + 2 cbrt(sod2/(2J))
/// ```
///
/// `+inf` for a horizontal rectangle (`sin s < tol::SIN_SLOPE_HORIZONTAL`: the
/// toroidal cutter along the slope wins at every shape factor).
///
/// ```
/// use scallop_analysis::{critical_shape_factor, MachineLimits, ToolOptions};
/// let mu = critical_shape_factor(60f64.to_radians(), 1568.0, &ToolOptions::default(), 0.01, &MachineLimits::default());
/// assert!((mu - 1.174).abs() < 1e-3);
/// ```
#[must_use]
pub fn critical_shape_factor(
    slope: f64,
    size: f64,
    tools: &ToolOptions,
    scallop_height: f64,
    machine: &MachineLimits,
) -> f64 {
    let r_eff = tools.toroidal().effective_radius(slope, 0.0);
    if r_eff.is_infinite() {
        return f64::INFINITY;
    }
    let (sod1, sod2) = (step_over(scallop_height, r_eff), step_over(scallop_height, tools.ball_radius));
    let k = sod2 / sod1;
    let (v, j) = (machine.feed, machine.jerk);
    let k1 = machine.time_to_feed() + 2.0 * (sod1 / (2.0 * j)).cbrt();
    let k2 = machine.time_to_feed() + 2.0 * (sod2 / (2.0 * j)).cbrt();
    let linear = size.sqrt() / v * (1.0 - k);
    let root = (linear * linear + 16.0 * k * k1 * k2).sqrt();
    let root_mu = (linear + root) / (4.0 * k * k1);
    root_mu * root_mu
}

/// Annex E time (s) of a rectangle of width `w` (along `X_I`) and height `h` (along
/// `X_II`) machined by zigzag passes at angle `alpha` (rad, folded into `[0, pi/2]`)
/// to `X_I`, with in-plane step-over `step_over` (finishing.md 12.7, corrected:
/// bracketed side sums, continuum sums `c N^2/2 + e N` \[DECISION\]).
///
/// Case 1 (`tan a >= h/w`): `l = h/sin a`, `delta = p/sin a`,
/// `n = (sin a/p)(w - h/tan a)`, side passes `N = h cos a / p`, short connection
/// `p/cos a`. Case 2 (`tan a <= h/w`): `l = w/cos a`, `delta = p/cos a`,
/// `n = (cos a/p)(h - w tan a)`, `N = w sin a / p`, short connection `p/sin a`. Then
///
/// ```text
/// t1 = n (l/V + 2 sqrt(V/J) + 4 cbrt(delta/(2J)))
/// t2 = c N^2/2 + e N,  c = p/(cos a sin a V),  e = 2 sqrt(V/J) + 2 cbrt(delta/(2J)) + 2 cbrt(short/(2J))
/// t  = t1 + 2 t2
/// ```
///
/// (`c N^2/2` is evaluated as `h^2 cos a/(2 p V sin a)` or `w^2 sin a/(2 p V cos a)`,
/// finite at the ends). Continuous on `[0, pi/2]`; `a = 0` gives the `T2` form and
/// `a = pi/2` the `T1` form with the same `p`. Passes are charged as reaching `V`
/// and connections as case 3, as the annex assumes.
///
/// ```
/// use scallop_analysis::{rectangle_time_at_angle, MachineLimits};
/// let m = MachineLimits::default();
/// let t0 = rectangle_time_at_angle(56.0, 28.0, 0.0, 0.6321, &m);
/// let t_small = rectangle_time_at_angle(56.0, 28.0, 1e-12, 0.6321, &m);
/// assert!((t0 - t_small).abs() < 1e-6 * t0);
/// ```
#[must_use]
pub fn rectangle_time_at_angle(width: f64, height: f64, alpha: f64, step_over: f64, machine: &MachineLimits) -> f64 {
    let (w, h, p) = (width, height, step_over);
    let alpha = fold_direction_angle(alpha);
    let (sin_a, cos_a) = alpha.sin_cos();
    let (v, j) = (machine.feed, machine.jerk);
    let accelerate = 2.0 * machine.time_to_feed();
    let connection = |length: f64| (length / (2.0 * j)).cbrt();
    // case 1 when tan a >= h/w, i.e. w sin a >= h cos a.
    let (pass_length, delta, central, side_count, side_square, short) = if w * sin_a >= h * cos_a {
        let n = sin_a / p * (w - h * cos_a / sin_a);
        (h / sin_a, p / sin_a, n, h * cos_a / p, h * h * cos_a / (2.0 * p * v * sin_a), p / cos_a)
    } else {
        let n = cos_a / p * (h - w * sin_a / cos_a);
        (w / cos_a, p / cos_a, n, w * sin_a / p, w * w * sin_a / (2.0 * p * v * cos_a), p / sin_a)
    };
    let t1 = central.max(0.0) * (pass_length / v + accelerate + 4.0 * connection(delta));
    let t2 = if side_count < tol::ANNEX_E_MIN_SIDE_PASSES {
        0.0
    } else {
        side_square + (accelerate + 2.0 * connection(delta) + 2.0 * connection(short)) * side_count
    };
    t1 + 2.0 * t2
}

/// Annex E analytic time (s) of the PCA rectangle of `pca` machined with `cutter`
/// by vertical parallel planes of XY feed direction `feed_angle` (rad from X;
/// finishing.md 12.7, the optimiser's fast surrogate S3).
///
/// `F_p = (cos t, sin t, z)` with `F_p . X_III = 0`, normalised;
/// `alpha = arccos(|F_p . X_I|)`; step-over `p` from Eq. 1.5 (capped, 5.3) with the
/// plane tilt `arccos(|X_III . Z|)` and the horizontal angle between the feed and
/// the XY projection of `X_III`; then [`rectangle_time_at_angle`]. `+inf` for a
/// vertical plane (`|X_III . Z| < tol::VERTICAL_PLANE_NZ`: not machinable by this
/// model).
///
/// ```
/// use scallop_analysis::{annex_e_time, sample_patch, MachineLimits, Pca, ToolOptions};
/// let set = scallop_surface::builtin("choi").unwrap();
/// let pca = Pca::from_moments(&sample_patch(&set.patches()[0], &Default::default()).unwrap().moments());
/// let t = annex_e_time(&pca, 0.0, &ToolOptions::default().toroidal(), 0.01, &MachineLimits::default());
/// assert!(t.is_finite() && t > 0.0);
/// ```
#[must_use]
pub fn annex_e_time(pca: &Pca, feed_angle: f64, cutter: &Cutter, scallop_height: f64, machine: &MachineLimits) -> f64 {
    let [x1, _, x3] = pca.axes;
    if x3.z.abs() < tol::VERTICAL_PLANE_NZ {
        return f64::INFINITY;
    }
    let (sin_t, cos_t) = feed_angle.sin_cos();
    let z = -(x3.x * cos_t + x3.y * sin_t) / x3.z;
    let feed = scallop_geom::Vec3::new(cos_t, sin_t, z).normalize();
    let alpha = feed.dot(&x1).abs().min(1.0).acos();
    let tilt = x3.z.abs().min(1.0).acos();
    let horizontal = feed_angle - direction_angle_xy(x3.x, x3.y);
    let p = cutter.step_over(scallop_height, tilt, horizontal);
    rectangle_time_at_angle(pca.width(), pca.height(), alpha, p, machine)
}

/// Length and time of one strategy.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LengthTime {
    /// Path length (mm).
    pub length: f64,
    /// Machining time (s).
    pub time: f64,
}

impl LengthTime {
    fn sum(parts: &[PlaneTime]) -> LengthTime {
        LengthTime { length: parts.iter().map(|p| p.length).sum(), time: parts.iter().map(|p| p.time).sum() }
    }
}

/// The horizontal cross-shaped plane of finishing.md 14.4: a central bar
/// `[-w/2, w/2] x [-h/2, h/2]` and two arms `[-q/2, q/2] x [h/2, h/2 + p]` and its
/// mirror; the heuristic's counter-example.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CrossPlane {
    /// Bar length `w` along X (mm).
    pub bar_width: f64,
    /// Bar height `h` along Y (mm).
    pub bar_height: f64,
    /// Arm width `q` along X (mm).
    pub arm_width: f64,
    /// Arm length `p` along Y (mm).
    pub arm_length: f64,
}

/// Analytic lengths and times of the three strategies on a [`CrossPlane`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CrossTimes {
    /// One zone fed along X (the principal direction).
    pub along_x: LengthTime,
    /// One zone fed along Y.
    pub along_y: LengthTime,
    /// Three zones: the bar along X, each arm along Y (no inter-zone moves).
    pub three_zones: LengthTime,
}

impl CrossPlane {
    /// The thesis's cross: `w = 80`, `h = 30`, `q = 10`, `p = 40` mm.
    pub const THESIS: CrossPlane = CrossPlane { bar_width: 80.0, bar_height: 30.0, arm_width: 10.0, arm_length: 40.0 };

    /// Whether `(x, y)` lies in the closed cross.
    #[must_use]
    pub fn contains(&self, x: f64, y: f64) -> bool {
        let (w, h, q, p) = (self.bar_width, self.bar_height, self.arm_width, self.arm_length);
        (x.abs() <= w / 2.0 && y.abs() <= h / 2.0) || (x.abs() <= q / 2.0 && y.abs() <= h / 2.0 + p)
    }

    /// Closed-form `[Var(S_x), Var(S_y)]` (mm^2) of the area measure (14.4, diagonal
    /// covariance \[CORR\]): `Var(S_x) = (2 p q^3 + h w^3) / (12 (w h + 2 p q))`,
    /// `Var(S_y) = ((w - q) h^3 + q (2p + h)^3) / (12 (q (2p + h) + (w - q) h))`.
    #[must_use]
    pub fn variances(&self) -> [f64; 2] {
        let (w, h, q, p) = (self.bar_width, self.bar_height, self.arm_width, self.arm_length);
        let var_x = (2.0 * p * q.powi(3) + h * w.powi(3)) / (12.0 * (w * h + 2.0 * p * q));
        let var_y = ((w - q) * h.powi(3) + q * (2.0 * p + h).powi(3)) / (12.0 * (q * (2.0 * p + h) + (w - q) * h));
        [var_x, var_y]
    }

    /// Lengths and times of the three strategies with a ball of radius `radius`
    /// (14.4, corrected `T2` with `w/V`): along X, `2 strip(p, q) + strip(h, w)`;
    /// along Y, `2 strip((w - q)/2, h) + strip(q, h + 2p)`; three zones,
    /// `strip(h, w) + 2 strip(q, p)`, where `strip(extent, pass)` is [`strip_time`]
    /// with `sod = 2 sqrt(2 sh R - sh^2)`.
    #[must_use]
    pub fn times(&self, radius: f64, scallop_height: f64, machine: &MachineLimits) -> CrossTimes {
        let (w, h, q, p) = (self.bar_width, self.bar_height, self.arm_width, self.arm_length);
        let sod = step_over(scallop_height, radius);
        let strip = |extent: f64, pass: f64| strip_time(extent, pass, sod, machine);
        let arm_x = strip(p, q);
        let bar_x = strip(h, w);
        let side_y = strip((w - q) / 2.0, h);
        let middle_y = strip(q, h + 2.0 * p);
        let arm_y = strip(q, p);
        CrossTimes {
            along_x: LengthTime::sum(&[arm_x, arm_x, bar_x]),
            along_y: LengthTime::sum(&[side_y, side_y, middle_y]),
            three_zones: LengthTime::sum(&[bar_x, arm_y, arm_y]),
        }
    }
}
