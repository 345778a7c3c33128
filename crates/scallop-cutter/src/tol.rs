//! The physical range of cutter sizes, named in one place.

/// Largest cutter radius R (mm): a 1 m face mill is beyond any catalogue; past it a
/// size is a typo (a diameter in microns, a missing decimal point), and the planning and
/// simulation work it implies has no bound.
pub const MAX_RADIUS: f64 = 500.0;

/// Smallest cutter radius R (mm): 1 micron, below the smallest micro end mills (5 microns
/// in diameter); a smaller radius makes scallop-driven spacings vanish.
pub const MIN_RADIUS: f64 = 1e-3;

/// Largest flute, shank or holder length and holder radius (mm): 2 m.
pub const MAX_LENGTH: f64 = 2000.0;
