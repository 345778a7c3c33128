//! Named constants of the optimiser (finishing.md 12.9). Each is a setting of
//! the normative compact OrthoMADS, not a tuning knob.

/// Initial frame and mesh size `Delta_0` in scaled variables (`[0, 1]`).
pub const INITIAL_FRAME: f64 = 0.1;

/// Smallest mesh index `l` (`l >= -2`): the largest frame is `0.1 * 2^2 = 0.4`.
pub const MIN_MESH_INDEX: i32 = -2;

/// Stop when the mesh size `Delta^m` falls below this (scaled units).
pub const MIN_MESH_SIZE: f64 = 1e-9;

/// The mesh index at which `Delta^m = 0.1 * 4^-l < MIN_MESH_SIZE` first holds
/// (`0.1 * 4^-14 = 3.7e-10`); the finest mesh ever polled is `l = 13`.
pub const STOP_MESH_INDEX: i32 = 14;

/// Lattice resolution: every point the optimiser evaluates has scaled
/// coordinates `m / LATTICE` with an integer `m` in `[0, LATTICE]`.
/// `LATTICE = 10 * 4^14`, so `1 / LATTICE` is the mesh size at
/// [`STOP_MESH_INDEX`] and every coarser mesh size is an integer number of
/// lattice steps; cache keys are exact integers and periodic wraps are exact.
pub const LATTICE: i64 = 10 * (1 << 28);

/// `Delta_0` in lattice steps (`0.1 * LATTICE = 2^28`).
pub const INITIAL_FRAME_STEPS: i64 = 1 << 28;

/// The quadratic-model search uses cached points within this multiple of the
/// frame size `Delta^p` (infinity norm, scaled units) of the incumbent.
pub const MODEL_RADIUS_FRAMES: f64 = 2.0;

/// Relative weight of the constant and linear coefficients in the
/// minimum-norm model fit: small, so the norm minimised is (almost only) the
/// Frobenius norm of the Hessian, as in the minimum-Frobenius-norm models.
pub const MODEL_LINEAR_WEIGHT: f64 = 1e-3;

/// Singular values below this fraction of the largest are treated as zero in
/// the model fit's pseudo-inverse.
pub const MODEL_RANK_REL: f64 = 1e-10;

/// Projected-gradient iterations when minimising the model in the frame box.
pub const MODEL_DESCENT_STEPS: usize = 60;

/// Most cached points used by one model fit, as a multiple of the number of
/// coefficients of a full quadratic (beyond that the fit only gets slower).
pub const MODEL_POINTS_PER_COEFFICIENT: usize = 2;
