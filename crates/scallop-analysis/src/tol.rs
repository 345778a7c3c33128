//! Every numeric threshold and algorithm constant of this crate, in one place
//! (house rule: no float literal thresholds in algorithms). Values quoted from the
//! specification name the section of `finishing.md` they come from.

/// A normal whose XY projection is shorter than this is horizontal-plane normal
/// (`n = +-Z`): its steepest-slope direction theta is undefined and set to 0
/// (finishing.md 4.4 \[DECISION\]). The same rule folds the XY projections of the PCA
/// axes `S_I` and `S_III` into angles.
pub const HORIZONTAL_XY: f64 = 1e-12;

/// Below this `sin s`, Eq. 1.5 is treated as singular (horizontal plane) and the
/// toroidal step-over is the flat-bottom cap `sod_max` (finishing.md 5.3).
pub const SIN_SLOPE_HORIZONTAL: f64 = 1e-9;

/// Annex E (finishing.md 12.7): a PCA plane with `|X_III . Z|` below this is
/// vertical and its analytic time is `+inf` (not machinable by that model).
pub const VERTICAL_PLANE_NZ: f64 = 1e-6;

/// Annex E: a side region with fewer than this many (real) passes contributes
/// nothing (finishing.md 12.7 "if N < 1e-12 the side term is 0").
pub const ANNEX_E_MIN_SIDE_PASSES: f64 = 1e-12;

/// PCA canonical signs: when `|S_III . Z|` is at most this, the plane is vertical
/// and the sign of `S_II`, `S_III` is fixed by "largest-magnitude component of
/// `S_III` positive" instead of "`S_III` upward" (finishing.md 9.1).
pub const PCA_VERTICAL_NZ: f64 = 1e-12;

/// The samples are degenerate (on a line or at a point; the PCA rectangle has no
/// area) when `lambda_II <= DEGENERATE_EIGEN_REL * lambda_I`, or when `lambda_I`
/// is at most `DEGENERATE_EIGEN_REL` times the squared coordinate scale.
pub const DEGENERATE_EIGEN_REL: f64 = 1e-12;

/// Shape-factor limit of the decision aid (finishing.md 8.5, thesis footnote):
/// beyond `mu = 9` the model was not validated; the advisor still answers with the
/// `s_c` rule and adds a note.
pub const SHAPE_FACTOR_LIMIT: f64 = 9.0;

/// Samples per chunk in the fixed-order reductions (moments, orientation sums):
/// the chunking depends on this constant only, never on the thread count, so
/// results are bit-identical with any number of threads.
pub const REDUCTION_CHUNK: usize = 4096;

/// Number of points of the critical curve `s_c(mu)` drawn by [`crate::plot_svg`].
pub const PLOT_CURVE_POINTS: usize = 241;

/// Largest sampling grid of a patch (cells): 4 million, about 400 MB of samples and a few
/// seconds; the CLI's `--cells 2000` is the largest square grid under it.
pub const MAX_GRID_CELLS: usize = 4_000_000;
