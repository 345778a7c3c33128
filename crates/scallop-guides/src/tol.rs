//! Thresholds of the guide-curve algorithms, each documented.

/// Root finding on a Marching Facets edge stops when the exact field is within
/// this of the iso-value, or the bracket is this short (mm). Far below the
/// 1e-6 mm asked of edge points (issue 17; docs/guides-curves.md).
pub const ROOT_TOLERANCE: f64 = 1e-10;

/// Iteration cap of the edge root finding (Illinois false position with
/// bisection steps); 2^-100 of an edge is far below [`ROOT_TOLERANCE`].
pub const MAX_ROOT_ITERATIONS: usize = 100;

/// A facet is flagged as crossed by the medial axis of the curve when the feet
/// of its corners on the curve are farther apart than this many times the
/// facet's longest edge (docs/guides-curves.md, "Medial-axis facets").
pub const MEDIAL_FOOT_FACTOR: f64 = 3.0;

/// Offsets stop after this many curves beyond `diagonal / a_e + 2` (a guard:
/// every step shrinks the region, so it is never reached on a valid mesh).
pub const EXTRA_STEPS: usize = 2;

/// A vertex of a curve is a corner to round in the vectorial offset (Alg. 3,
/// Jousselin 2020, Annex A) when the curve turns there by more than this
/// (radians): gaps on straight stretches are not filled, since the radial push
/// would bring the points closer than the offset distance to the curve.
pub const CORNER_TURN: f64 = 0.1;

/// Most axial levels of one guide set (bounds the work on absurd settings).
pub const MAX_LEVELS: usize = 1000;

/// Consecutive curve points closer than this (mm) are merged in a distance
/// field ([`crate::CurveField`]): the mesh intersection and Marching Facets
/// can leave points a rounding error apart, whose segment has no reliable
/// direction (coordinates of 1e2 mm carry 1e-14 mm of rounding, a direction
/// error of 1e-7 rad at this length), so its left vector could flip the side
/// of the points whose nearest point is its end.
pub const MERGE_DISTANCE: f64 = 1e-7;

/// An offset loop whose mean width (`2 area / length`) is under this many
/// facet sizes has vanished ([`crate::offset_curves`]): its shape is below
/// the mesh's resolution (docs/guides-curves.md, "Slivers").
pub const SLIVER_WIDTH_FACETS: f64 = 0.5;
