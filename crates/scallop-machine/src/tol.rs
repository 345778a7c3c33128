//! Every numeric threshold of this crate, named and documented in one place.
//!
//! The house rule puts thresholds in `scallop-geom/src/tol.rs`; these are specific to
//! machine kinematics and stay here until they move there.

/// A declared axis direction (or tool axis) must have a norm within this of 1
/// before it is normalised (spec 2.3).
pub const DIRECTION_NORM: f64 = 1e-6;

/// Two unit directions count as parallel when `|u x v|` is below this (rotary axes of
/// one machine must not be parallel; a pivot direction is "along e_x" for the
/// closed-form families when it differs from it by less than this).
pub const PARALLEL: f64 = 1e-9;

/// Largest absolute coordinate (mm) of a point in a description (part-frame origin,
/// gauge point, pivot points): 100 m, beyond any machine; past it a value is a typo and
/// the kinematics would overflow.
pub const MAX_COORDINATE: f64 = 1e5;

/// The three linear axes must span space: `|det [d_1 d_2 d_3]|` above this.
pub const LINEAR_INDEPENDENCE: f64 = 1e-6;

/// Default pole threshold: `rho = |sin(tilt)|` below this means the tool axis is on
/// the pole and the free rotary axis is held (spec 2.3, `kinematics.pole_eps`).
pub const POLE_EPS_DEFAULT: f64 = 1e-7;

/// `mu3^2` of the two-rotary subproblem may be this far below zero from rounding and
/// still count as the boundary of the reachable orientation set (then `mu3 = 0`).
pub const SUBPROBLEM_ROUNDING: f64 = 1e-12;

/// Slack on axis limits in internal units (mm, rad): a value this far outside a stroke
/// is rounding, not a violation (the spec's MX330 vector puts A exactly at -125 deg).
pub const LIMIT_SLACK: f64 = 1e-9;

/// Acceptance of a numeric (Levenberg-Marquardt) inverse: the forward kinematics must
/// reproduce the tip to this (mm) and the tool axis to this (unit vector) (spec 3.2).
pub const NUMERIC_ACCEPT: f64 = 1e-9;

/// Maximum Levenberg-Marquardt iterations of the numeric inverse.
pub const NUMERIC_MAX_ITERATIONS: usize = 200;

/// Initial damping of the Levenberg-Marquardt iteration (relative to `diag(J^T J)`).
pub const NUMERIC_INITIAL_DAMPING: f64 = 1e-3;

/// Two branch candidates whose continuity costs (s) differ by less than this are a tie,
/// broken by the user preference (spec 3.5).
pub const COST_TIE: f64 = 1e-12;

/// Two rotary solutions closer than this (rad, after reduction modulo 2 pi) and two
/// linear solutions closer than this (mm) are the same joint vector.
pub const SAME_JOINTS: f64 = 1e-9;

/// The damping grows until this; beyond it no step reduces the residual and the
/// iteration stops.
pub const NUMERIC_MAX_DAMPING: f64 = 1e12;

/// Smallest damping (keeps the normal equations positive definite).
pub const NUMERIC_MIN_DAMPING: f64 = 1e-15;

/// Factor applied to the damping after a successful step.
pub const NUMERIC_DAMPING_DECREASE: f64 = 0.1;

/// Factor applied to the damping after a rejected step.
pub const NUMERIC_DAMPING_INCREASE: f64 = 10.0;

/// Marquardt scaling floor: a diagonal entry of `J^T J` counts as at least this times
/// the largest one (a joint with no effect near a pole still gets damped).
pub const NUMERIC_DIAGONAL_FLOOR: f64 = 1e-9;

/// The orientation iteration stops once `|O(q) - O|` is below `NUMERIC_ACCEPT` times
/// this (room for the rounding of the final linear solve).
pub const NUMERIC_ORIENTATION_MARGIN: f64 = 1e-2;

/// Default rotary jump (rad, 30 deg) above which a block counts as a flip or unwind
/// (spec 3.5 `flip_threshold`).
pub const FLIP_THRESHOLD_DEFAULT: f64 = std::f64::consts::PI / 6.0;

/// Default time charged for a retract, reorientation and approach around a jump on a
/// non-cutting move (s) [PLACEHOLDER until the time model provides it].
pub const REORIENT_PENALTY_DEFAULT: f64 = 5.0;

/// Candidate joint vectors kept per pose by the branch dynamic programme (spec 3.5: K <= 8).
pub const PLAN_BEAM: usize = 8;

/// Uniform samples per block when measuring the deviation of joint-linear motion
/// (spec 3.10), before golden-section refinement of the worst one.
pub const DEVIATION_SAMPLES: usize = 16;

/// Golden-section iterations refining the worst deviation sample (interval shrinks by
/// 0.618 per iteration: 40 iterations reach 1e-8 of the block).
pub const DEVIATION_REFINE_ITERATIONS: usize = 40;

/// Maximum bisection depth of the joint-space subdivision (spec 3.10).
pub const SUBDIVISION_MAX_DEPTH: usize = 16;

/// A G93 word within this relative distance of a multiple of the output step is that
/// multiple (rounding noise of `60/T` must not round an exact feed down a step).
pub const FEED_ROUNDING: f64 = 1e-12;

/// Turning angle (rad, 10 deg) up to which a junction belongs to a smooth curve sampled
/// by a polyline (spec 8.3 `theta_smooth`).
pub const SMOOTH_JUNCTION: f64 = std::f64::consts::PI / 18.0;

/// Bisection iterations of the time model's velocity searches (relative precision 2^-60).
pub const TIME_BISECTION_ITERATIONS: usize = 60;

/// A per-axis direction component below this (mm or rad per mm of path) does not
/// limit a block's acceleration or jerk (the axis does not move in that block).
pub const AXIS_DIRECTION_ZERO: f64 = 1e-12;

/// Default share of the path tolerance for joint-space interpolation (mm; spec 3.10
/// `tol_pos`).
pub const JOINT_INTERPOLATION_DEFAULT: f64 = 0.005;

/// Default angular tolerance of the tool axis under joint-space interpolation (rad,
/// 0.05 deg; spec 3.10 `tol_ang`).
pub const JOINT_ANGLE_DEFAULT: f64 = 0.05 * std::f64::consts::PI / 180.0;

/// Slack on the verification of emitted blocks (relative): rate and deviation checks
/// pass when within this fraction above their limit (rounding only).
pub const VERIFY_SLACK: f64 = 1e-9;

/// A pole-axis move above this (rad, 90 deg) marks a branch flip: the two branches of
/// the standard families differ by 180 deg on the pole axis, a continuous pole crossing
/// keeps it (used by the greedy planner's events and the subdivision's midpoint check).
pub const BRANCH_JUMP: f64 = std::f64::consts::FRAC_PI_2;

/// Factor applied to one axis's velocity, acceleration and jerk limits to measure the
/// time that axis costs (`TimeReport::axis_time_lost`): large enough that the axis never
/// binds, finite so the jerk-limited formulas stay defined.
pub const RELAXED_AXIS_FACTOR: f64 = 1e9;

/// Largest total rotation of one block (rad) for which `feed::deviation_bound` holds
/// (its distance bound needs `3 Omega < 1`); larger blocks are sampled.
pub const BOUND_MAX_ROTATION: f64 = 0.3;

/// Relative and absolute (mm) inflation of the trigonometry-free distance bound of
/// `feed::deviation_bound_relaxed`, so that it also bounds the rounded exact distance.
pub const BOUND_PRETEST_SLACK: f64 = 1e-9;

/// Relative inflation of the atan-free upper bound `r_ref tan(phi) / F` of the rotation
/// term of `feed::inverse_time_feed` (covers the rounding of the exact term, a few ulps).
pub const ROTATION_TERM_SLACK: f64 = 1e-12;

/// Largest rotary turn (rad, 5 deg) of one step of `plan::track`, which follows a CL move
/// continuously: well below the 180 deg between the two inverse branches on the pole
/// axis, so the nearest solution of each step is the continuation.
pub const TRACK_STEP: f64 = std::f64::consts::PI / 36.0;

/// First (and largest) step of `plan::track` as a fraction of the move.
pub const TRACK_FIRST_STEP: f64 = 1.0 / 8.0;

/// Smallest step of `plan::track` (fraction of the move): a turn above `TRACK_STEP` over
/// a step this small is a discontinuity (an exact singularity), not a motion.
pub const TRACK_MIN_STEP: f64 = 1.0 / 1_073_741_824.0;

/// Most inverse evaluations of one `plan::track` (a guard; a move turning several full
/// revolutions near the pole needs a few thousand).
pub const TRACK_MAX_EVALUATIONS: usize = 200_000;

/// An inverse solution is the end of `plan::track`'s continuous motion when its rotaries
/// equal the tracked ones within this (rad) modulo a turn; the tracked values are inverse
/// solutions of the same pose, so only rounding separates them.
pub const TRACK_MATCH: f64 = 1e-6;

/// Default retract distance (mm) along the tool axis of a link that changes branch or
/// unwinds (`program::ProgramOptions::retract`) [PLACEHOLDER: a job's clearance should
/// set it].
pub const LINK_RETRACT_DEFAULT: f64 = 10.0;
