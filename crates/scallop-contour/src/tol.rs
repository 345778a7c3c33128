//! Named tolerances of the contour layer (mm, mm^2).

/// Two positions closer than this are one point (mm); also the equality
/// threshold handed to `cavalier_contours`.
pub const POS_EQUAL: f64 = 1e-5;

/// Offset slices closer than this to the source contour are dropped as
/// invalid, and slice ends closer than this are joined (mm).
pub const OFFSET_DIST: f64 = 1e-4;

/// A ring that turns back along the line it came on, within this distance
/// of it, over ground it runs again after the turn, is a fold of the offset
/// kernel: the stretch is removed (mm; `Contour::without_folds`). Far below
/// any chord tolerance of a pass, far above the kernel's rounding.
pub const FOLD_WIDTH: f64 = 1e-3;

/// Rings with less area than this are dropped (mm^2): slivers that offsets
/// and booleans leave at tangencies.
pub const MIN_AREA: f64 = 1e-6;

/// A bulge below this is a straight segment (sweep below 4e-9 rad).
pub const BULGE_ZERO: f64 = 1e-9;

/// The finest chord tolerance accepted when arcs become chords (mm): finer
/// requests are raised to it (it bounds the number of chords).
pub const MIN_CHORD_TOLERANCE: f64 = 1e-6;

/// Pieces of a link shorter than this found outside a region are the
/// booleans' rounding on the boundary, not a crossing (mm).
pub const LINK_SLACK: f64 = 1e-6;

/// Most points one fitted arc may replace (bounds the quadratic check).
pub const MAX_ARC_POINTS: usize = 256;
