//! The crate's error type: every variant names the patch, the place and the fix.

use std::fmt;

use scallop_mesh::MeshError;

/// A parameter direction of a patch: `U` goes with the first control-net index `i`,
/// `V` with the second index `j`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Direction {
    /// The first parameter (rows of the control net, index `i`).
    U,
    /// The second parameter (columns of the control net, index `j`).
    V,
}

impl Direction {
    /// Both directions, `U` first.
    pub const BOTH: [Direction; 2] = [Direction::U, Direction::V];

    /// 0 for `U`, 1 for `V` (the index into `[u, v]` pairs such as `Patch::degree`).
    #[must_use]
    pub fn index(self) -> usize {
        match self {
            Direction::U => 0,
            Direction::V => 1,
        }
    }
}

impl fmt::Display for Direction {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Direction::U => "u",
            Direction::V => "v",
        })
    }
}

/// Which patch an error is about: its name and, when known, its position in a
/// [`SurfaceSet`](crate::SurfaceSet) or a file (counting from 0).
///
/// A patch built on its own does not know its position; builders of sets fill it
/// in with [`SurfaceError::with_patch_index`].
#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub struct PatchLabel {
    /// Position in the set or file, from 0.
    pub index: Option<usize>,
    /// The patch name (empty when the input did not give one).
    pub name: String,
}

impl PatchLabel {
    /// A label with a name and no position.
    #[must_use]
    pub fn named(name: &str) -> Self {
        PatchLabel { index: None, name: name.to_owned() }
    }
}

impl fmt::Display for PatchLabel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("patch")?;
        if let Some(i) = self.index {
            write!(f, " #{i}")?;
        }
        if !self.name.is_empty() {
            write!(f, " {:?}", self.name)?;
        }
        Ok(())
    }
}

/// Why a patch, a set of patches or a tessellation request is invalid.
///
/// Each variant names the patch ([`PatchLabel`]), the place (direction, knot index,
/// control point `(i, j)` with `i` along u) and, in its message, the fix.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SurfaceError {
    /// A degree below 1. Fix: use degree 1 (bilinear) or more in both directions.
    #[error("{patch}: degree in {direction} is {degree}; it must be at least 1")]
    DegreeTooLow {
        /// The patch.
        patch: PatchLabel,
        /// The direction whose degree is wrong.
        direction: Direction,
        /// The given degree.
        degree: usize,
    },
    /// A degree above [`crate::tol::MAX_DEGREE`], checked before anything is allocated.
    /// Fix: split the patch or lower the degree (CAD exports stay far below the cap).
    #[error(
        "{patch}: degree in {direction} is {degree}; the largest accepted is {max} (evaluation cost and rounding grow with it); lower the degree or split the patch"
    )]
    DegreeTooHigh {
        /// The patch.
        patch: PatchLabel,
        /// The direction whose degree is too high.
        direction: Direction,
        /// The given degree.
        degree: usize,
        /// The cap, [`crate::tol::MAX_DEGREE`].
        max: usize,
    },
    /// The control net has the wrong number of rows (u direction, index `i`).
    /// Fix: a Bezier patch of degree p in u has p + 1 rows; a NURBS patch has at
    /// least p + 1 rows and exactly (number of u knots) - p - 1.
    #[error("{patch}: the control net has {found} rows (index i, along u) but {expected} are needed ({reason})")]
    ControlRows {
        /// The patch.
        patch: PatchLabel,
        /// Rows given.
        found: usize,
        /// Rows required.
        expected: usize,
        /// Where the requirement comes from.
        reason: &'static str,
    },
    /// A row of the control net has the wrong length (v direction, index `j`).
    /// Fix: every row needs the same number of points: q + 1 for a Bezier patch of
    /// degree q in v, (number of v knots) - q - 1 for a NURBS patch.
    #[error(
        "{patch}: control row i = {row} has {found} points (index j, along v) but {expected} are needed ({reason})"
    )]
    ControlColumns {
        /// The patch.
        patch: PatchLabel,
        /// The row `i`.
        row: usize,
        /// Points given in that row.
        found: usize,
        /// Points required.
        expected: usize,
        /// Where the requirement comes from.
        reason: &'static str,
    },
    /// A knot vector whose length does not match the control net and degree.
    /// Fix: give (control points in that direction) + degree + 1 knots.
    #[error(
        "{patch}: knot vector {direction} has {found} knots but {control_points} control points of degree {degree} need {expected}"
    )]
    KnotCount {
        /// The patch.
        patch: PatchLabel,
        /// The knot vector.
        direction: Direction,
        /// Knots given.
        found: usize,
        /// Knots required.
        expected: usize,
        /// Control points in this direction.
        control_points: usize,
        /// Degree in this direction.
        degree: usize,
    },
    /// A knot that is NaN or infinite. Fix: give finite knots.
    #[error("{patch}: knot {direction}[{index}] = {value} is not finite")]
    NonFiniteKnot {
        /// The patch.
        patch: PatchLabel,
        /// The knot vector.
        direction: Direction,
        /// Index of the knot, from 0.
        index: usize,
        /// The value.
        value: f64,
    },
    /// A knot smaller than the one before it. Fix: knots must be non-decreasing; sort them.
    #[error(
        "{patch}: knot {direction}[{index}] = {value} is smaller than knot {direction}[{before}] = {previous}; knots must be non-decreasing",
        before = .index - 1
    )]
    KnotsDecreasing {
        /// The patch.
        patch: PatchLabel,
        /// The knot vector.
        direction: Direction,
        /// Index of the offending knot (the one smaller than its predecessor).
        index: usize,
        /// Its value.
        value: f64,
        /// The value of the knot before it.
        previous: f64,
    },
    /// A knot repeated too often: more than degree + 1 times anywhere (a basis
    /// function would vanish), or more than degree times strictly inside the domain
    /// (the surface would be discontinuous). Fix: remove repeats, or split the patch.
    #[error(
        "{patch}: knot {direction}[{index}] = {value} is repeated {multiplicity} times; at most {max} allowed there (degree {degree})"
    )]
    KnotMultiplicity {
        /// The patch.
        patch: PatchLabel,
        /// The knot vector.
        direction: Direction,
        /// Index of the first knot of the run.
        index: usize,
        /// The repeated value.
        value: f64,
        /// How many times it appears.
        multiplicity: usize,
        /// The maximum allowed at that place.
        max: usize,
        /// Degree in this direction.
        degree: usize,
    },
    /// The parameter domain `[knot[p], knot[n]]` has zero length. Fix: the knots
    /// from index p to index n (number of control points) must not all be equal.
    #[error("{patch}: the {direction} domain [{start}, {end}] is empty (knots {direction}[{p}] and {direction}[{n}])")]
    EmptyDomain {
        /// The patch.
        patch: PatchLabel,
        /// The knot vector.
        direction: Direction,
        /// Domain start, knot `p`.
        start: f64,
        /// Domain end, knot `n`.
        end: f64,
        /// Index of the start knot (the degree).
        p: usize,
        /// Index of the end knot (number of control points).
        n: usize,
    },
    /// A control-point coordinate that is NaN or infinite. Fix: give finite coordinates.
    #[error("{patch}: control point (i = {i}, j = {j}) = {point:?} is not finite")]
    NonFiniteControlPoint {
        /// The patch.
        patch: PatchLabel,
        /// Index along u.
        i: usize,
        /// Index along v.
        j: usize,
        /// The coordinates.
        point: [f64; 3],
    },
    /// The weight net does not have the shape of the control net.
    /// Fix: one weight per control point, in the same rows, or no weights at all.
    #[error("{patch}: weights {place} has {found} entries but the control net needs {expected}")]
    WeightsShape {
        /// The patch.
        patch: PatchLabel,
        /// "rows" or "row i = ...".
        place: String,
        /// Entries given.
        found: usize,
        /// Entries required.
        expected: usize,
    },
    /// A weight that is not finite and strictly positive. Fix: weights must be > 0
    /// (a zero or negative weight puts the surface at infinity or outside its hull).
    #[error("{patch}: weight (i = {i}, j = {j}) = {weight} must be finite and > 0")]
    BadWeight {
        /// The patch.
        patch: PatchLabel,
        /// Index along u.
        i: usize,
        /// Index along v.
        j: usize,
        /// The weight.
        weight: f64,
    },
    /// A set without patches. Fix: give at least one patch.
    #[error("the surface set has no patches")]
    EmptySet,
    /// Two patches with the same name. Fix: rename one; names identify patches.
    #[error("{patch}: the name is already used by patch #{first}")]
    DuplicateName {
        /// The second patch with the name.
        patch: PatchLabel,
        /// Index of the first patch with the name.
        first: usize,
    },
    /// A tessellation tolerance that is not finite and positive. Fix: pass a chordal
    /// tolerance in mm, e.g. `Tolerances::tessellation()`.
    #[error("tessellation tolerance {value} mm is not a finite positive number")]
    BadTolerance {
        /// The tolerance given.
        value: f64,
    },
    /// The tolerance would need more than the cell limit. Fix: a coarser tolerance,
    /// or split the patch.
    #[error("{patch}: meeting the chordal tolerance needs {cells} grid cells, more than the limit {limit}")]
    TooFine {
        /// The patch.
        patch: PatchLabel,
        /// Cells needed.
        cells: usize,
        /// The limit (`tol::MAX_TESSELLATION_CELLS`).
        limit: usize,
    },
    /// The tessellation is not a valid mesh (for instance every triangle is
    /// degenerate because the surface collapses to a curve). Fix: check the control net.
    #[error("tessellation of {patch} is not a valid mesh: {source}")]
    Mesh {
        /// The patch (for a set: the first patch, as the mesh is built from all of them).
        patch: PatchLabel,
        /// The mesh error.
        source: MeshError,
    },
}

/// The one list of the variants that carry a patch label, shared by
/// [`SurfaceError::patch`] and `patch_mut` (`&` and `&mut` need two matches).
macro_rules! patch_of {
    ($error:expr) => {
        match $error {
            SurfaceError::DegreeTooLow { patch, .. }
            | SurfaceError::DegreeTooHigh { patch, .. }
            | SurfaceError::ControlRows { patch, .. }
            | SurfaceError::ControlColumns { patch, .. }
            | SurfaceError::KnotCount { patch, .. }
            | SurfaceError::NonFiniteKnot { patch, .. }
            | SurfaceError::KnotsDecreasing { patch, .. }
            | SurfaceError::KnotMultiplicity { patch, .. }
            | SurfaceError::EmptyDomain { patch, .. }
            | SurfaceError::NonFiniteControlPoint { patch, .. }
            | SurfaceError::WeightsShape { patch, .. }
            | SurfaceError::BadWeight { patch, .. }
            | SurfaceError::DuplicateName { patch, .. }
            | SurfaceError::TooFine { patch, .. }
            | SurfaceError::Mesh { patch, .. } => Some(patch),
            SurfaceError::EmptySet | SurfaceError::BadTolerance { .. } => None,
        }
    };
}

impl SurfaceError {
    /// The patch the error is about, if it is about one.
    #[must_use]
    pub fn patch(&self) -> Option<&PatchLabel> {
        patch_of!(self)
    }

    /// The same error with the patch's position set to `index` (for builders of
    /// sets and file readers, which know where the patch came from).
    ///
    /// ```
    /// use scallop_surface::{Patch, SurfaceError};
    /// use scallop_geom::Point3;
    /// let o = Point3::origin();
    /// let err = Patch::bezier("flat", [0, 1], &[vec![o, o]], None).unwrap_err();
    /// assert_eq!(err.with_patch_index(3).patch().unwrap().index, Some(3));
    /// ```
    #[must_use]
    pub fn with_patch_index(mut self, index: usize) -> Self {
        if let Some(label) = self.patch_mut() {
            label.index = Some(index);
        }
        self
    }

    fn patch_mut(&mut self) -> Option<&mut PatchLabel> {
        patch_of!(self)
    }
}
