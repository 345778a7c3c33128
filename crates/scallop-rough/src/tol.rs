//! Named tolerances and thresholds of the roughing planner (mm unless said).

/// Extra width, as a share of the stepover, allowed around the band a
/// tool-down link may cross: a link's radial engagement stays within about
/// one stepover (see `offset.rs`).
pub const LINK_MARGIN_SHARE: f64 = 0.05;

/// A facet whose unit normal has `z` above this is horizontal (a floor that
/// gets a level of its own): within 0.08 degrees of level.
pub const FLAT_NORMAL_Z: f64 = 1.0 - 1e-6;

/// Heights of flat facets closer than this are one floor.
pub const FLAT_MERGE: f64 = 1e-3;

/// Levels closer than this are one level (the higher is kept).
pub const LEVEL_MERGE: f64 = 1e-3;

/// A floor's level is this far above the floor plus the axial allowance, so
/// the waterline height is never exactly a facet's height (where every grid
/// sample would tie).
pub const FLAT_LIFT: f64 = 1e-5;

/// Rapids down into cleared area stop this far above the cleared level; a
/// plunge at the plunge feed does the rest.
pub const APPROACH: f64 = 1.0;

/// Largest sweep of one arc move (rad): longer arcs are split so that no
/// move reads as a full circle and the centre words stay well defined.
pub const MAX_ARC_SWEEP: f64 = std::f64::consts::FRAC_PI_2;

/// Most offset passes of one region (bounds the work on absurd inputs).
pub const MAX_PASSES: usize = 100_000;

/// Most levels of one plan.
pub const MAX_LEVELS: usize = 10_000;

/// A region is grown by this before testing whether a link stays in it, so
/// that passes on its contour count as inside (mm): the tool may go this far
/// into the allowance on a link.
pub const LINK_GROW: f64 = 1e-4;

/// Waterline loops are thinned by Douglas-Peucker at this before the region
/// booleans (mm): their points lie within the waterline's chord tolerance
/// (1e-4 mm) of each other's chords, far denser than a roughing region needs.
/// The region's boundary moves by at most this (into the allowance, and with
/// no allowance into the part: within the job's path tolerance).
pub const SIMPLIFY: f64 = 1e-3;

/// Helical entries: the tool centre's circle has this share of the tool
/// radius (the bore is 1.5 D wide, no core left in its middle).
pub const HELIX_RADIUS_SHARE: f64 = 0.5;

/// Helical entries descend this much per unit of length along the circle
/// (tan of about 3 degrees).
pub const HELIX_SLOPE: f64 = 0.05;

/// A point this far inside a ring (from a chord's midpoint, along its
/// normal) stands for the region in containment tests between levels (mm).
pub const INTERIOR_NUDGE: f64 = 1e-3;

/// Material less than this above a level (mm) is not worth a pass: the
/// in-process stock's cells that hold only this much over the level count
/// as cleared (see `material.rs`).
pub const MIN_CHIP: f64 = 0.05;

/// Most cells of an in-process stock map (bounds the memory of the outline
/// tracing on absurd inputs).
pub const MAX_MATERIAL_CELLS: usize = 64_000_000;

// ---- Adaptive clearing (branch adaptive; issue 16) ----

/// Adaptive clearing: the grid's cell side as a share of the tool radius
/// (R / 16: 0.19 mm for a 6 mm tool).
pub const GRID_SHARE: f64 = 1.0 / 16.0;

/// Adaptive clearing: most cells of one region's grid; larger regions get
/// coarser cells.
pub const MAX_GRID_CELLS: usize = 8_000_000;

/// Adaptive clearing: a pass is kept when its largest engagement, measured
/// on the grid every cell side with the periphery probed every
/// [`ENGAGE_PROBES`]th of a turn, is at most this times the target (the
/// planner's margin under the 1.1 bound of docs/roughing.md).
pub const ENGAGE_ACCEPT: f64 = 1.03;

/// Adaptive clearing: points probed on the tool's periphery.
pub const ENGAGE_PROBES: usize = 180;

/// Adaptive clearing: the next pass tries at most this times the last
/// pass's step (never more than the stepover).
pub const STEP_GROW: f64 = 1.3;

/// Adaptive clearing: the smallest step between passes, as a share of the
/// grid's cell side (a pass that still exceeds the bound there is kept).
pub const STEP_MIN_SHARE: f64 = 0.25;

/// Adaptive clearing: trials of one pass's step before the smallest is kept.
pub const STEP_TRIALS: usize = 12;

/// Adaptive clearing: the passes (grid iso-lines) are replaced by arcs and
/// lines within this (mm): fewer, smoother moves; the tool may go this much
/// deeper into the material or towards a wall.
pub const ARC_FIT: f64 = 0.01;

/// Adaptive clearing: a smaller step that lowers a pass's largest
/// engagement by less than this (rad, 2 degrees) is not worth it: the
/// geometry, not the step, sets the engagement there, and the larger step
/// is kept.
pub const STEP_STALL: f64 = 0.035;
/// Adaptive clearing: the front's speed on a wall of the region, as a share
/// of its speed inside (a front slowed near the walls meets them nearly
/// parallel, with passes closer there: a front meeting a straight wall at an
/// angle theta engages the tool going along the wall by up to theta more
/// than the target, docs/roughing.md).
pub const WALL_SPEED: f64 = 0.3;

/// Adaptive clearing: the band along the walls where the front slows down,
/// as a share of the tool radius.
pub const WALL_BAND: f64 = 1.0;

/// Adaptive clearing: the walls' chords (mm) onto which passes along a wall
/// are moved (see `walls.rs`); a chord of a wall bending into the region
/// lies this much outside it.
pub const WALL_CHORD: f64 = 1e-5;

/// Adaptive clearing: most wall vertices put back between two wall points
/// of a pass (the chords of a wall's arc between two cells).
pub const WALL_CORNERS: usize = 256;

/// Adaptive clearing: a fitted arc of a larger radius (mm) becomes a line
/// (it deviates from its chord by at most chord^2 / 8000 mm: 1 um for a
/// 2.8 mm chord).
pub const MAX_ARC_RADIUS: f64 = 1000.0;
// ---- end of adaptive clearing ----
