//! Every numeric threshold and algorithm constant of this crate, in one place.
//!
//! The house rule is that thresholds live in `scallop-geom/src/tol.rs`; these
//! are specific to parametric surfaces and are kept here, named and documented,
//! until they move there.

/// A normal `Su x Sv` counts as degenerate when `|Su x Sv| <= NORMAL_DEGENERATE_REL * (|Su|^2 + |Sv|^2)`
/// (spec finishing.md 4.2: "< 1e-12 relative").
pub const NORMAL_DEGENERATE_REL: f64 = 1e-12;

/// Last-resort normal fallback: first step towards the domain centre, as a fraction
/// of the way there (doubled on each retry, see [`NORMAL_FALLBACK_STEPS`]).
pub const NORMAL_FALLBACK_FIRST_STEP: f64 = 1e-9;

/// Number of doublings of [`NORMAL_FALLBACK_FIRST_STEP`] tried before giving up and returning +Z.
pub const NORMAL_FALLBACK_STEPS: usize = 30;

/// Newton iterations stop when a step moves less than this fraction of the domain width.
pub const PARAM_STEP_REL: f64 = 1e-14;

/// Sufficient-decrease constant of the Armijo line search.
pub const ARMIJO: f64 = 1e-4;

/// Relative rounding of an objective evaluation (some tens of ulps times the
/// magnitudes that enter it): the line search accepts a step whose value rises by no
/// more than this uncertainty, so that Newton converges on its accurate gradient
/// instead of stalling on noise in the value.
pub const OBJECTIVE_ROUNDING_REL: f64 = 1e-14;

/// Maximum step halvings in one line search.
pub const LINE_SEARCH_HALVINGS: usize = 50;

/// A steepest-descent step (used where the Hessian is not positive definite) starts
/// at this fraction of the domain width.
pub const STEEPEST_FIRST_STEP: f64 = 0.25;

/// Safety factor applied to second-derivative maxima estimated by sampling (rational
/// patches only; polynomial patches use a guaranteed control-net bound).
pub const SAMPLED_BOUND_SAFETY: f64 = 1.5;

/// Sampling intervals per knot span and direction when estimating second-derivative
/// maxima of rational patches.
pub const SAMPLES_PER_SPAN: usize = 16;

/// Largest number of grid cells one patch may be tessellated into (two triangles each).
pub const MAX_TESSELLATION_CELLS: usize = 4_000_000;

/// Composite Gauss-Legendre area integration: sub-intervals per knot span and direction.
pub const AREA_SUBDIVISIONS_PER_SPAN: usize = 8;

/// Largest degree of a patch in either direction. CAD systems export degree 3 to 9
/// (some allow up to 25); past this a degree is a typo, and the control net and the
/// basis tables it implies are allocated only after this check.
pub const MAX_DEGREE: usize = 32;
