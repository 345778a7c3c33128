//! Every numeric threshold of the field engine, with its reason.

/// Samples per axis of one storage block of a [`crate::Field`]. A block whose
/// centre is farther from the surface than the band cutoff plus its half-diagonal
/// holds no sample in the band and is not stored (cell binning of the band).
pub const BLOCK: usize = 8;

/// Default bound on the number of grid samples (2^25, at most 256 MiB of f64
/// per field). A grid over it is refused with [`crate::FieldError::GridTooLarge`],
/// which names the smallest voxel size that fits.
pub const DEFAULT_MAX_SAMPLES: usize = 1 << 25;

/// The band cutoff exceeds the largest iso-value by this many voxel sizes. The
/// longest edge of the Kuhn tetrahedra is `sqrt(3) h`, and the distance is
/// 1-Lipschitz, so every edge that crosses an iso-value has both ends computed
/// exactly when the cutoff is at least `iso + sqrt(3) h`; 2 leaves a margin. The
/// grid margin around the surface uses the same count (a sheet is never clipped
/// by the grid box).
pub const BAND_MARGIN_VOXELS: f64 = 2.0;

/// Relative clamp of the interpolation parameter on a crossed edge: the output
/// vertex stays at least this fraction of the edge length away from both grid
/// samples, so two vertices on different edges of one sample never coincide and
/// welding by edge never makes a zero-area triangle. The position error it adds
/// (`1e-4 h`) is far below the method's `h / 2` bound.
pub const INTERP_CLAMP: f64 = 1e-4;

/// Relative slack on the bound that a neighbouring sample's distance gives
/// (`d(q) + |p - q|`, the distance being 1-Lipschitz): rounding of the square
/// root and the sum can put the exact bound an ulp below the distance, which
/// would miss the closest triangle; 1e-9 covers it many times over and costs
/// no pruning worth measuring.
pub const LIPSCHITZ_SLACK: f64 = 1e-9;
