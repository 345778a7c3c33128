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
