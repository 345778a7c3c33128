//! Every numeric threshold and algorithm constant of this crate, in one place
//! (house rule: no float literal thresholds in algorithms). Values quoted from the
//! specification name the section of `finishing.md` they come from.

/// Iteration cap of K-means and RPCL (finishing.md 11.6, 11.7, section 13): one
/// iteration is one full assignment sweep.
pub const MAX_ITERATIONS: usize = 300;

/// Incremental zone statistics are recomputed in batch every this many assignment
/// iterations (and at termination) so rounding cannot accumulate (finishing.md 11.5).
pub const BATCH_REFRESH_EVERY: usize = 10;

/// Per-cluster Mahalanobis and standard-deviation metrics fall back to the global
/// covariance for clusters with fewer cells than this (finishing.md 11.3, item 3).
pub const MIN_CELLS_PER_CLUSTER_COVARIANCE: usize = 5;

/// A symmetric covariance is singular when an eigenvalue is at most this times the
/// largest one. The global Mahalanobis metric then uses the pseudo-inverse (the
/// directions without spread, e.g. a constant slope on a plane, weigh 0); a
/// per-cluster covariance falls back to the global one (finishing.md 11.3).
pub const SINGULAR_EIGEN_REL: f64 = 1e-12;

/// A standard deviation (rad or parameter units) at or below this is zero: the
/// component is constant over the set and weighs 0 in the standard-deviation metric
/// (globally), or the per-cluster metric falls back to the global one.
pub const MIN_SIGMA: f64 = 1e-12;

/// The PCA metric's extra term is 0 for clusters with fewer cells than this
/// (finishing.md 11.3, item 6 \[DECISION\]).
pub const PCA_MIN_CELLS: usize = 3;

/// A vector whose XY projection is shorter than this (mm, or unit vectors) has no
/// direction angle; the PCA metric's corresponding `sin^2` term is then 0
/// (finishing.md 11.3, item 6 \[DECISION\]).
pub const XY_DEGENERATE: f64 = 1e-12;

/// Closed-form 3x3 eigenvectors: when the best cross product of two rows of
/// `A - lambda_I I` is at most this times the squared Frobenius norm of `A`, the top
/// eigenvalue is (nearly) repeated and the iterative solver is used instead.
pub const EIGEN_CROSS_REL: f64 = 1e-10;

/// RPCL winner learning rate at sweep 0 (finishing.md 11.7, section 13 \[DECISION\]).
pub const RPCL_ALPHA_WINNER: f64 = 0.05;

/// RPCL rival learning rate at sweep 0 (finishing.md 11.7, section 13 \[DECISION\]).
pub const RPCL_ALPHA_RIVAL: f64 = 0.005;

/// RPCL stops when both learning rates are below this (finishing.md 11.7).
pub const RPCL_TOL_ALPHA: f64 = 1e-4;

/// RPCL stops when fewer than this fraction of the cells changed cluster in a sweep
/// (finishing.md 11.7: "1 % move threshold").
pub const RPCL_TOL_MOVE: f64 = 0.01;

/// Assignment sweeps run on the rayon pool when `cells x clusters` is at least this
/// (the PCA metric always does); below, one thread is faster. Either way each cell's
/// label depends only on frozen statistics, so the result is the same.
pub const PARALLEL_MIN_PAIRS: usize = 1 << 17;

/// Relative slack of Hamerly's K-means bounds: a cell skips the scan only when its
/// upper bound times `1 + HAMERLY_SLACK` is below its lower bound, so rounding in
/// the accumulated bounds (about 1e-16 per update) can never keep a cell in the
/// wrong cluster.
pub const HAMERLY_SLACK: f64 = 1e-9;

/// Absolute margin (in the metric's units) added to the K-means scan's pruning
/// radius `2 u (1 + HAMERLY_SLACK)`, so that rounding near `u = 0` never prunes
/// a centre that could tie.
pub const HAMERLY_ABSOLUTE: f64 = 1e-12;

/// Cells per parallel assignment chunk.
pub const PARALLEL_CHUNK: usize = 1024;

/// Hierarchical clustering is O(n^2) in time (O(n) memory, nearest-neighbour
/// chain): grids with more kept cells than this are rejected (about 5 s here); coarsen
/// the clustering grid (the thesis recommends HAC only to suggest a K).
pub const HAC_MAX_CELLS: usize = 40_000;
