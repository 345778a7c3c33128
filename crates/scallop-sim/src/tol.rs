//! The simulator's named numeric thresholds (the workspace-wide ones are in
//! `scallop_geom::tol`).

/// A stock width within this relative distance of a whole number of cells is
/// that number of cells (not one more): `60 / 0.05` is 1200 cells even when the
/// division rounds to 1200.0000000000002.
pub const GRID_SNAP: f64 = 1e-9;

/// Default number of gouge cells listed in a [`crate::SimError::Gouge`].
pub const WORST_REPORTED: usize = 20;

/// Cells of the machined surface over the scallop limit that
/// [`crate::split_rest`] lists for a refinement, at most (the thickest).
pub const OVER_REPORTED: usize = 20_000;

/// Slopes `|dz / L|` of a move above this are treated as vertical: the
/// horizontal travel is then below 1e-100 of the vertical one, far below
/// rounding, and the slope's square stays finite in the closed forms.
pub const VERTICAL_SLOPE: f64 = 1e100;

/// Largest distance (mm) between a circular or helical move of a tri-dexel
/// cut and the chords it is cut as (their vertices lie on the arc).
pub const ARC_SAGITTA: f64 = 1e-4;

/// Margin (mm) subtracted from the lower bounds of a swept floor that skip
/// the exact per-cell solve (`z_low + h(distance)`): far above the rounding of
/// both the bound and the solve (1e-14 mm at 100 mm), so that a skip never
/// happens where the solve would have lowered the cell, and results are the
/// same bits as without the bound.
pub const FLOOR_BOUND_MARGIN: f64 = 1e-9;

/// A probed point of the tool's periphery counts as cut by one of the tool's
/// recent moves only when it lies deeper than this (mm) inside the disc swept
/// by that move: the periphery of the current position is at exactly `R`
/// from the path's last point, and rounding must not count it as cut.
pub const ENGAGEMENT_CONTACT: f64 = 1e-6;

/// Samples per block of an engagement evaluation: a block reads the raster of
/// older cuts as it stood before the block, its samples run in parallel. A
/// fixed count, so the figures do not depend on the thread count.
pub const ENGAGEMENT_BLOCK: usize = 64;
