//! Every numeric threshold of the crate, named.

/// Relative slack under which a value counts as exactly representable when rounding
/// feed words (binary floating point cannot hold 57.368 exactly).
pub const ROUNDING_SLACK: f64 = 1e-9;

/// Largest rotation (deg) of a modulo-360 rotary in one block: blocks turning this much
/// or more are split (spec 3.7: the control takes the shortest path).
pub const MODULO_HALF_TURN: f64 = 179.0;

/// Tilt words within this many degrees of zero satisfy either solution sign.
pub const ZERO_TILT_DEG: f64 = 1e-6;

/// Cost added to a tilted-plane solution whose tilt sign contradicts the direction word.
pub const WRONG_SOLUTION_PENALTY: f64 = 1e6;

/// Largest distance (mm) of the tool tip from a rotary axis assumed when turning the
/// rounding of rotary words into a tip allowance.
pub const REACH: f64 = 1000.0;

/// Number of rounded angles (two rotaries, or three plane angles with margin) in the
/// rounding allowance.
pub const ROUNDED_ANGLES: f64 = 4.0;

/// Relative slack on the path tolerance and the axis-rate ratio in [`crate::check_replay`].
pub const CHECK_SLACK: f64 = 1e-6;

/// Samples of each joint-space block in [`crate::check_replay`].
pub const CHECK_SAMPLES: u32 = 16;

/// Distance from a rounding tie (in units of the last digit) below which `fmt_number`
/// leaves its integer fast path for the exact formatter.
pub const FAST_FORMAT_TIE_MARGIN: f64 = 1e-6;
