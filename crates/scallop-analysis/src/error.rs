//! The crate's error type.

/// Why an analysis cannot be made. Each variant says the cause and the fix.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum AnalysisError {
    /// No samples: an empty sampling grid, or a mask that keeps no cell.
    /// Fix: use at least 1 x 1 cells and a mask that selects part of the surface.
    #[error("no samples to analyse (empty grid or mask)")]
    NoSamples,
    /// A sample given to [`crate::Samples::from_samples`] has a non-finite point,
    /// normal or `(u, v)`, or a weight that is negative or not finite.
    /// Fix: drop or repair that sample.
    #[error("sample {index} has a non-finite coordinate or a bad weight")]
    BadSample {
        /// Index of the sample.
        index: usize,
    },
    /// A sampling grid with a zero dimension.
    /// Fix: ask for at least one cell in each direction (default 80 x 80).
    #[error("sampling grid {cells_u} x {cells_v} has no cells")]
    EmptyGrid {
        /// Cells along u.
        cells_u: usize,
        /// Cells along v.
        cells_v: usize,
    },
    /// A sampling grid over the budget ([`crate::tol::MAX_GRID_CELLS`], about 100 bytes a
    /// cell), refused before anything is allocated. Fix: fewer cells per direction.
    #[error(
        "sampling grid {cells_u} x {cells_v} = {cells} cells is over the budget of {max} cells (about 100 bytes each); use fewer cells"
    )]
    TooManyCells {
        /// Cells along u.
        cells_u: usize,
        /// Cells along v.
        cells_v: usize,
        /// Their product (saturating).
        cells: u128,
        /// The budget.
        max: usize,
    },
    /// A cutter size that is not a real tool.
    /// Fix: radii finite and > 0 mm, corner radius in `[0, R]`.
    #[error("cutter {what} = {value} mm is not valid (radii finite and > 0, corner radius in [0, R])")]
    BadTool {
        /// Which size.
        what: &'static str,
        /// The value given.
        value: f64,
    },
    /// A machine limit that is not finite and positive.
    /// Fix: give V (mm/s), A (mm/s^2) and J (mm/s^3) as finite numbers > 0.
    #[error("machine {what} = {value} is not a finite number > 0")]
    BadMachine {
        /// Which limit.
        what: &'static str,
        /// The value given.
        value: f64,
    },
    /// The scallop height is not in `(0, smallest cutter radius)`.
    /// Fix: use a small positive value such as 0.01 mm.
    #[error("scallop height {value} mm must be > 0 and smaller than every cutter radius")]
    BadScallopHeight {
        /// The value given (mm).
        value: f64,
    },
    /// The samples lie on a line or at a point: the PCA rectangle has no area, so
    /// no shape factor or plane time exists. Fix: analyse a real surface patch.
    #[error("the samples are degenerate (on a line or at a point): PCA eigenvalues {eigenvalues:?} mm^2")]
    DegenerateSamples {
        /// `[lambda_I, lambda_II, lambda_III]` (mm^2).
        eigenvalues: [f64; 3],
    },
}
