//! The crate's error type.

/// Why a partition cannot be computed. Each message names the parameter or the
/// input item at fault and the fix.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ClusterError {
    /// The clustering grid has a zero dimension or no kept cell.
    /// Fix: sample at least one cell in each direction (default 80 x 80).
    #[error("clustering grid {cells_u} x {cells_v} has no cells: sample at least 1 x 1 cells (default 80 x 80)")]
    EmptyGrid {
        /// Cells along u.
        cells_u: usize,
        /// Cells along v.
        cells_v: usize,
    },
    /// The number of clusters `k` is 0 or larger than the number of cells.
    #[error("k = {k} clusters is not valid for {cells} cells: use 1 <= k <= {cells}")]
    BadClusterCount {
        /// The value given.
        k: usize,
        /// Number of cells of the grid (kept cells for a masked grid).
        cells: usize,
    },
    /// A weight `omega_i` is NaN or outside `[0, 1]`.
    #[error("weight omega[{index}] = {value} is not in [0, 1]: give four weights between 0 and 1 (default 1)")]
    BadWeight {
        /// Index of the weight (0 = u, 1 = v, 2 = s, 3 = theta).
        index: usize,
        /// The value given.
        value: f64,
    },
    /// A sample has no `(u, v)` (a mesh sample) or is not on the grid.
    #[error(
        "sample {index} has no (u, v) on a {cells_u} x {cells_v} grid: cluster cell-centre samples of one patch (sample_patch)"
    )]
    NotOnGrid {
        /// Index of the sample.
        index: usize,
        /// Cells along u.
        cells_u: usize,
        /// Cells along v.
        cells_v: usize,
    },
    /// The samples carry no grid (several patches, or a mesh).
    #[error("the samples have no clustering grid: sample one patch with sample_patch or sample_patch_masked")]
    NoGrid,
    /// Two samples fall in the same grid cell, or cells are not in increasing order.
    #[error("sample {index} repeats or precedes grid cell {cell}: give one sample per cell, in cell order a * N_v + b")]
    CellOrder {
        /// Index of the sample.
        index: usize,
        /// Its grid cell index.
        cell: usize,
    },
    /// A feature value is NaN or infinite.
    #[error("feature {index} has a non-finite component: repair or drop that sample")]
    BadFeature {
        /// Index of the feature vector.
        index: usize,
    },
    /// Two input arrays have different lengths.
    #[error("{what} has {got} entries, expected {expected}: give one entry per sample")]
    LengthMismatch {
        /// Which array.
        what: &'static str,
        /// Expected length.
        expected: usize,
        /// Length given.
        got: usize,
    },
    /// The PCA metric needs the 3D points of the samples.
    #[error("the PCA metric needs the samples' 3D points: build Features with from_samples or with_geometry")]
    NeedsGeometry,
    /// A method/metric combination that does not exist.
    #[error("{method} cannot use the {metric} metric: {fix}")]
    Unsupported {
        /// The clustering method.
        method: &'static str,
        /// The metric.
        metric: &'static str,
        /// What to use instead.
        fix: &'static str,
    },
    /// A numeric setting out of its range.
    #[error("{name} = {value} is out of range: {fix}")]
    BadSetting {
        /// The setting (e.g. `max_iterations`, `rpcl.alpha_c0`).
        name: &'static str,
        /// The value given.
        value: f64,
        /// The valid range.
        fix: &'static str,
    },
}
