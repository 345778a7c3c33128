//! Every numeric threshold and algorithm constant of this crate.
//!
//! Path-tolerance budget (style guide 2.6): the tessellation of parametric
//! surfaces takes [`scallop_geom::Tolerances::TESSELLATION_SHARE`] (0.25), the
//! forward sampling along a pass [`SAMPLING_SHARE`] (0.5) and the merging of
//! collinear points [`SIMPLIFY_SHARE`] (0.25): the total is `Tolerances::path`.
//!
//! Below the cutter-location surface (a gouge between cutter locations) only
//! the sampling share counts: a feed or link move never lies deeper than
//! `SAMPLING_SHARE * path` under the exact drop-cutter surface. The merging is
//! one-sided (`scallop_toolpath::simplify_above`: a kept chord passes on or
//! above every point it replaces), so its share is spent above the surface only.

/// Share of the path tolerance for the chordal deviation of the sampled CL
/// polyline (a step is bisected while the CL midpoint is farther than this
/// share of `path` above or below the chord).
pub const SAMPLING_SHARE: f64 = 0.5;

/// Share of the path tolerance for merging nearly collinear CL points
/// (`scallop_toolpath::simplify_above`: above the sampled polyline only).
pub const SIMPLIFY_SHARE: f64 = 0.25;

/// Share of the path tolerance for merging the CL points of parallel-planes
/// passes and links, one-sided (`simplify_above`): half of [`SIMPLIFY_SHARE`].
/// A kept chord passes above the valleys it smooths, and that material lies
/// between the feed samples where the planner measures the scallop: with the
/// full share the z-map simulation of the demo job (Choi, bull-nose R 5, r 2,
/// sh 0.01 mm) found 0.01035 mm, over sh plus its resolution bound (0.01031).
pub const PASS_SIMPLIFY_SHARE: f64 = 0.125;

/// The one-sided merging's tolerance is also at most this share of the
/// scallop height. A merged chord rides above the points it replaces, and the
/// material under it adds to the scallop between the feed samples where the
/// planner measures a pair of planes: the measure adds the larger lift of the
/// two planes (a small Choi zone study simulated 0.01157 mm for sh 0.01 mm
/// with the merging budgeted in the path tolerance only, docs/validation.md).
pub const MERGE_SCALLOP_SHARE: f64 = 0.02;

/// A forward step is split while the CL point at its middle, or at one of its
/// quarter points (an inflection inside the step can put the middle on the
/// chord), lies more than this fraction of the sampling share above the chord.
/// Where the CL surface is concave over the step (a crest, the top of a
/// descent), the chord's deepest point under it is at most twice the
/// midpoint's depth, so the chord stays within the sampling share. Jumps of the CL surface (walls) are
/// bisected down to `(GOUGE_MIDPOINT_SHARE * SAMPLING_SHARE * path)^2 / (2 R)`
/// (over which a circular arc of radius up to the cutter radius `R` rises by
/// at most that depth) and then stepped over vertically.
pub const GOUGE_MIDPOINT_SHARE: f64 = 0.5;

/// Pass ends are located by bisection of the region boundary until the bracket
/// is shorter than this share of the path tolerance (mm along the pass).
pub const BOUNDARY_SHARE: f64 = 0.5;

/// Forward steps are never bisected below this fraction of `max_step`.
pub const MIN_STEP_FRACTION: f64 = 1.0 / 4096.0;

/// The smallest horizontal plane spacing (mm) the planner accepts (finishing.md
/// 6.4 uses `Delta_min = 1e-6 m`); below it the scallop height cannot be met
/// with this cutter and direction and planning fails.
pub const MIN_SPACING: f64 = 1e-3;

/// When the measured scallop between a plane and its tentative successor
/// exceeds `sh`, the gap is multiplied by `sqrt(sh / h) * SPACING_SAFETY` (the
/// scallop grows about as the square of the gap) and measured again.
pub const SPACING_SAFETY: f64 = 1.0 - 1e-6;

/// Retries of the tentative next plane before giving up.
pub const MAX_SPACING_RETRIES: usize = 24;

/// Iterations of the first-plane fixed point (its offset is half its own spacing).
pub const FIRST_PLANE_ITERATIONS: usize = 4;

/// Relative measurement slack of the scallop check: a measured height up to
/// `sh * (1 + SCALLOP_REL_SLACK)` passes (rounding of the envelope search).
pub const SCALLOP_REL_SLACK: f64 = 1e-6;

/// Golden-section iterations of the envelope minimisation along one segment.
pub const GOLDEN_ITERATIONS: usize = 64;

/// Iterations of the cusp search (Illinois false position, then bisection).
pub const CUSP_ITERATIONS: usize = 80;

/// Relative convergence of the cusp search (times the plane gap).
pub const CUSP_REL_TOL: f64 = 1e-9;

/// Bins of the scallop histogram over `[0, sh]` (one more bin counts heights above `sh`).
pub const HISTOGRAM_BINS: usize = 10;

/// A normal whose XY projection is shorter than this is horizontal (slope 0).
pub const HORIZONTAL_XY: f64 = 1e-12;

/// A contact this far (relative to the cutter radius) outside the flat bottom
/// of a bull-nose lies on its torus, whose normal is then used.
pub const TORUS_CONTACT_REL: f64 = 1e-9;

/// Bisection iterations of the look-ahead velocity solver.
pub const VELOCITY_ITERATIONS: usize = 60;

/// Moves shorter than this (mm) are ignored by the time models (no direction).
pub const ZERO_LENGTH: f64 = 1e-12;

/// An envelope minimum within this fraction of the cutter radius of a pass end
/// comes from the end position (scallop samples there are skipped).
pub const PASS_END_REL: f64 = 1e-9;

/// A contact within this fraction of its triangle's longest edge from a vertex
/// or an edge lies on it (for the region's boundary test).
pub const ON_FEATURE_REL: f64 = 1e-9;

/// Virtual planes (plus one) of the dense-pass reference of a cusp over the limit.
pub const REFERENCE_PLANES: usize = 8;

/// Forward step of the dense-pass reference, as a fraction of the cutter radius.
pub const REFERENCE_STEP_FRACTION: f64 = 1.0 / 32.0;

/// From the second retry on, the gap shrinks at least by this factor.
pub const SPACING_MIN_SHRINK: f64 = 0.9;

/// Lateral samples of the residual between two passes when the envelopes do
/// not cross or the cutter is flat (its saw tooth need not peak at the crossing).
pub const CUSP_SPAN_SAMPLES: usize = 32;

/// The first retries of a plane measure the scallop against the part only;
/// later ones also subtract rest material (dense virtual passes, costly).
pub const RAW_RETRIES: usize = 3;

/// Relative convergence of the golden-section envelope search (times the cutter
/// radius): the envelope's value errs by the square of it (times the curvature).
pub const GOLDEN_REL_TOL: f64 = 1e-6;

/// Passes of the network planner shorter than this (mm) are dropped; their
/// vertices still count for the spacing (finishing.md 6.3: `eps_pass = 1e-6 m`).
pub const MIN_PASS_LENGTH: f64 = 1e-3;

/// Segments of the polylines that estimate isoline lengths for the network
/// resolution (finishing.md 6.3 \[DECISION\]).
pub const NETWORK_ISOLINE_SEGMENTS: usize = 200;

/// Parameters of the isolines whose longest length sets the network resolution
/// (finishing.md 6.3: `v in {0, 1/4, 1/2, 3/4, 1}`, likewise for u).
pub const NETWORK_ISOLINE_PARAMETERS: [f64; 5] = [0.0, 0.25, 0.5, 0.75, 1.0];

/// Largest number of network quads per direction (a 0.5 mm mesh of a 1 m part).
pub const MAX_NETWORK_QUADS: usize = 2048;

/// Relative slack of the spacing comparisons of the network sweep: a plane's
/// spacing within this fraction below the gap accepts the gap (rounding).
pub const LOOKAHEAD_REL: f64 = 1e-9;

/// Moves of a tentative next plane (look-ahead) before the sweep gives up.
pub const MAX_LOOKAHEAD_RETRIES: usize = 32;

/// A network plane closer than this fraction of the zone's extent (at least
/// 1 mm) to the lowest node is moved that far inside, so that a plane at
/// `d_min` yields the boundary (nodes on a plane count as above it).
pub const PLANE_NUDGE_REL: f64 = 1e-9;

/// A far strip wider than half a spacing by less than this fraction of the
/// spacing gets no further plane (rounding; ends the network sweep).
pub const END_STRIP_REL: f64 = 1e-6;

/// Look-ahead moves of the network sweep that go exactly to the spacing found;
/// later ones shrink by an extra `LOOKAHEAD_SHRINK * 2^k` (at most 1/2).
pub const LOOKAHEAD_PLAIN_RETRIES: usize = 4;

/// See [`LOOKAHEAD_PLAIN_RETRIES`].
pub const LOOKAHEAD_SHRINK: f64 = 1e-3;

/// Where the spacing shrinks from plane to plane, the network sweep steps by
/// `Delta_k - LOOKAHEAD_TREND (Delta_{k-1} - Delta_k)` instead of `Delta_k`, so
/// that the next plane's own spacing usually accepts the gap at once (a
/// slightly conservative step instead of a second plane).
pub const LOOKAHEAD_TREND: f64 = 1.25;
/// Measurements of the scallop per isoparametric pass pair while fitting the
/// spacing (each scales the step by `sqrt(sh / h)`).
pub const ISO_FIT_ITERATIONS: usize = 8;

/// Points across the gap between two isoparametric passes, plus one, at which the
/// scallop is measured (at every running sample).
pub const ISO_LATERAL_SAMPLES: usize = 6;

/// Most samples of one isoparametric pass.
pub const ISO_MAX_SAMPLES: usize = 20_000;

/// Largest isoparametric step-over, as a multiple of the cutter radius (where the
/// effective radius is infinite: a horizontal flat bottom).
pub const ISO_MAX_STEP_OVER: f64 = 1.8;

/// The isoparametric scallop check walks a pass's segments outwards from the
/// measured point's running parameter and stops after this many in a row that
/// cannot come closer (a segment left out only enlarges the measured scallop).
pub const ISO_WINDOW_MISSES: usize = 8;

/// An isoparametric step whose measured scallop lies between this fraction of
/// `sh` and `sh` is accepted without trying a larger one.
pub const ISO_FIT_ACCEPT: f64 = 0.8;

/// Budget of one plan in drop-cutter queries, checked before planning on a lower bound
/// (forward samples per pass at `max_step` times the passes at the flat-surface spacing):
/// 5e7 queries, a few minutes on 2 cores and about 1 GB of samples; a request over it is
/// refused with the estimate.
pub const MAX_PLAN_SAMPLES: f64 = 5e7;

/// Forward samples of one pass at `max_step` (the samples of a plane are held at once):
/// 1e7, 80 MB of abscissae and 0.6 GB of cutter locations.
pub const MAX_PASS_SAMPLES: f64 = 1e7;

/// The smallest path tolerance (mm) a plan accepts: a tenth of a micron, below the
/// resolution of machine axes and of the G-code's four decimals; a smaller tolerance
/// only multiplies samples, with forward steps bisected down to `MIN_STEP_FRACTION`.
pub const MIN_PATH_TOLERANCE: f64 = 1e-4;

/// Waterline levels of steep-and-shallow finishing stay this share of the path
/// tolerance inside the steep triangles' z range and the part's (mm): the
/// waterline exists strictly inside the part's height range.
pub const LEVEL_EDGE_SHARE: f64 = 1.0;

/// Most waterline levels of one steep-and-shallow plan (bounds the work before
/// it is spent: a wall 1 m tall at the smallest spacing of a 0.1 mm ball).
pub const MAX_LEVELS: usize = 20_000;

/// A pass of a waterline level is linked to the previous pass's end by a
/// straight feed move (when the move stays above the CL surface) only if they
/// are at most this many cutter radii apart; farther, it retracts.
pub const LEVEL_LINK_RADII: f64 = 2.0;

/// Chord tolerance of the waterline loops of steep-and-shallow finishing, as a
/// share of the path tolerance; the loops' points are pushed out by
/// [`LEVEL_PUSH_CHORDS`] of it, so no chord cuts into a convex wall, and the
/// level spacing holds the scallop height less the push.
pub const LEVEL_CHORD_SHARE: f64 = 0.1;

/// A triangle flatter than this slope (rad) is a floor: steep-and-shallow
/// finishing runs a waterline level just above it (at the levels' edge margin).
pub const FLAT_SLOPE: f64 = 1e-3;

/// The level of a flat area runs this share of the path tolerance above it:
/// the waterline there is the contour where a wall lifts the cutter off the
/// floor, and the floor is left with no more than this.
pub const FLAT_LIFT_SHARE: f64 = 0.01;

/// The contact of a waterline loop point is probed this many chord
/// tolerances inside the loop, where the part lifts the cutter above the level.
pub const LEVEL_PROBE_CHORDS: f64 = 4.0;

/// Waterline levels are spaced this fraction of the profile rule's spacing
/// (the rule assumes a wall of constant slope between two levels; the stock
/// simulation proves the result).
pub const LEVEL_SPACING_SAFETY: f64 = 0.9;

/// Waterline loop points are pushed out this many chord tolerances: the
/// kernel bounds a chord's deviation at its midpoint, and on a near-vertical
/// wall any inward step is a deep vertical gouge.
pub const LEVEL_PUSH_CHORDS: f64 = 2.0;

/// A link between two waterline passes is checked against the drop-cutter
/// every this many chord tolerances along it.
pub const LEVEL_LINK_SAMPLE_CHORDS: f64 = 10.0;

/// When the planner tolerates rest material (steep-and-shallow) and no
/// spacing holds sh (a crease's normal, the foot of a wall that the
/// waterline levels finish), the next plane is this share of the largest
/// step-over away (at most the rule's spacing) and the stock simulation
/// reports what is left.
pub const REST_SPACING_SHARE: f64 = 0.25;

/// Half-width (degrees) of the slope band that both parallel planes and
/// waterline levels finish in steep-and-shallow finishing.
pub const STEEP_OVERLAP_DEG: f64 = 10.0;

/// An edge or vertex contact whose cutter normal leans more than this
/// (degrees) from the contacted facet's normal is a sharp convex feature of
/// the part, not its tessellation: it does not set the pass spacing (see
/// `Planner::rides_sharp_edge`). Tessellations of smooth surfaces within the
/// usual chord tolerances bend by a few degrees between facets.
pub const SHARP_EDGE_DEG: f64 = 30.0;

/// With rest tolerated, a measured residual above this many times sh at the
/// spacing rule's gap is rest material, not a scallop (a scallop grows with
/// the square of the gap: the rule would be 4.5 times too wide), and the
/// next plane goes `REST_SPACING_SHARE` of the largest step-over away
/// instead of shrinking the gap (`Planner::sweep`). So is a residual that
/// keeps more than half its height when the gap is more than halved (a
/// scallop would fall to a quarter).
pub const REST_RESIDUAL_FACTOR: f64 = 20.0;

/// Splits of a level spacing between the two walls of a concave crease at
/// which `steep::crease_residual` evaluates the cusp (the worst is kept).
pub const CREASE_SPLITS: usize = 16;

/// Times a level spacing is shrunk until the residual across the concave
/// creases between the two levels holds the scallop height.
pub const CREASE_RETRIES: usize = 4;

/// A point of a waterline level is paired with the nearest point of the level
/// above within this many times the horizontal offset of two levels on the
/// shallowest steep wall (`dz / tan(threshold - overlap)`) when looking for a
/// concave crease between them (`Levels::crease`).
pub const CREASE_REACH: f64 = 1.5;

// --- Waterline chords checked over their length (issue 15, branch mrush) ---

/// Each chord of a waterline level, pushed out by [`LEVEL_PUSH_CHORDS`]
/// chord tolerances, is probed with the drop-cutter at the `k /
/// LEVEL_CHORD_SAMPLES` points of its length (`0 < k < LEVEL_CHORD_SAMPLES`):
/// the kernel bounds a chord's deviation at its midpoint only, and a contour
/// that crosses the chord there (an S bend) leaves it inside the part on
/// both sides; on a near-vertical wall that is a deep vertical gouge.
pub const LEVEL_CHORD_SAMPLES: usize = 4;

/// Deepest recursion of the split of a waterline chord whose samples cut
/// into the part (a chord is split at most this many times along one path).
pub const LEVEL_CHORD_DEPTH: u32 = 16;

/// Width of the bracket (in chord tolerances) to which the contour point
/// added in a waterline chord is bisected; its outside end is kept.
pub const LEVEL_CHORD_BRACKET: f64 = 0.01;
