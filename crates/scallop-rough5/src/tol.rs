//! Thresholds of 5-axis roughing, each documented.

/// A tool axis whose x component is below this (in absolute value) builds its
/// frame from +X, else from +Y ([`crate::place`]): the frame is then never
/// built from a vector nearly parallel to the axis.
pub const FRAME_SWITCH: f64 = 0.9;

/// A contact closer to the tool axis than this (mm) is on the axis: its
/// normal is taken from the tool's centre point, not from the radial
/// direction (which is then undefined).
pub const ON_AXIS: f64 = 1e-12;

/// A tool axis shorter than this (mm, the distance between a path point and
/// its tilt point) is refused: the axis would be noise.
pub const MIN_AXIS_LENGTH: f64 = 1e-6;

/// Tool-axis steps below this (rad) are not subdivided (the axis is the
/// same to rounding).
pub const ANGLE_EPS: f64 = 1e-12;

/// Body samples of the flank collision check are this far apart along the
/// axis (mm); the check keeps a clearance of half of it, so it is
/// conservative (see `collide.rs`).
pub const BODY_STEP: f64 = 0.25;

/// Most passes (curves) of one level that the assembly accepts: a guard
/// against absurd settings.
pub const MAX_PASSES: usize = 10_000;

/// Most CL points of one pass (length over the step): a guard against
/// absurd settings.
pub const MAX_PASS_POINTS: usize = 1_000_000;

/// Relative finite-difference step of the SQP gradients (times 1 + |x_i|,
/// the polynomial coefficients being of order 1).
pub const SQP_FD_STEP: f64 = 1e-6;

/// A start whose constraint violation exceeds this is refused by the SQP.
pub const SQP_FEASIBLE: f64 = 1e-9;

/// The SQP stops when its step is below this in every coefficient.
pub const SQP_STEP: f64 = 1e-9;

/// The SQP stops when an iteration lowers the objective by less than this
/// times (1 + |objective|).
pub const SQP_REL_DECREASE: f64 = 1e-10;

/// Most iterations of one active-set QP.
pub const QP_MAX_ITER: usize = 500;

/// A working-set multiplier above -this counts as non-negative in the QP.
pub const QP_MULTIPLIER: f64 = 1e-10;

/// The smallest joint progress g_T' + g_D' of the two guide points (Eq.
/// 3.17 as corrected: never both stalled), per unit of s.
pub const MIN_PROGRESS: f64 = 1e-3;
