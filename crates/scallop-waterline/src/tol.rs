//! Named thresholds of the waterline kernel (mm unless said otherwise).

/// Default distance, along the probe direction, between the last sample with
/// the cutter above the part and the last one with it cutting into the part
/// when a contour point is refined by bisection. The point returned is the
/// outside one, so the cutter placed there at height z never penetrates the part.
pub const CROSSING_TOLERANCE: f64 = 1e-7;

/// Default largest deviation, at a chord's midpoint, between a chord of a loop
/// and the true contour: longer chords are split (adaptive refinement).
pub const CHORD_TOLERANCE: f64 = 1e-4;

/// Default grid step as a fraction of the cutter radius R. Features of the
/// contour smaller than the step may be missed (see `docs/waterline.md`).
pub const STEP_PER_RADIUS: f64 = 0.25;

/// Most samples in the drop-cutter grid of one waterline computation
/// (8 bytes each, plus a bit per level): a larger grid is an input error.
pub const MAX_SAMPLES: usize = 50_000_000;

/// Grid cells of padding around the mesh footprint widened by the cutter
/// radius: every border sample is outside, so loops never reach the border.
pub const PAD_CELLS: f64 = 2.0;

/// Distance (mm) below the lowest contact used as the floor of the sampling grid,
/// so that "nothing under the cutter" is always below every waterline height.
pub const FLOOR_MARGIN: f64 = 1.0;

/// A chord shorter than this many crossing tolerances is never split.
pub const MIN_CHORD_PER_CROSSING: f64 = 16.0;

/// Deepest recursion of the adaptive chord refinement (a chord is halved at
/// most this many times).
pub const MAX_REFINE_DEPTH: u32 = 40;

/// Smallest tolerance accepted, relative to the model's largest |coordinate|:
/// below it the bisection would be deciding rounding noise.
pub const REL_MIN_TOLERANCE: f64 = 1e-13;

/// How many times finer a block of 3 x 3 grid cells is sampled again where a
/// mesh vertex above z lies with every sample of the block outside: a small
/// island of the contour (see `docs/waterline.md`).
pub const ISLAND_REFINE: f64 = 16.0;

// --- Issue 15, waterline linking (branch wline2): new thresholds below. ---

/// Most halvings of an ambiguous grid cell (two or more exits) when its
/// crossings are linked by subdivision: features of the contour down to
/// `step / 2^6` are followed through the cell; below, the inside is joined
/// (see `cell.rs`).
pub const MAX_SUBDIVISION_DEPTH: u32 = 6;
