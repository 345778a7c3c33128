//! Every numeric threshold of scallop. No other module of the workspace
//! compares floats against a literal; they take a named value from here.

/// User-facing machining tolerances in mm; part of every job.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerances {
    /// Maximum deviation of emitted motion from the ideal CL surface (chordal error).
    pub path: f64,
    /// Maximum allowed penetration into the part; normally 0.
    pub gouge: f64,
}

impl Tolerances {
    /// Share of `path` given to the tessellation of parametric surfaces before a
    /// drop-cutter (the rest goes to path sampling and simplification).
    pub const TESSELLATION_SHARE: f64 = 0.25;

    /// The chordal tolerance budgeted for tessellating surfaces.
    #[must_use]
    pub fn tessellation(&self) -> f64 {
        self.path * Self::TESSELLATION_SHARE
    }
}

/// Relative rounding scale: `Eps` is this times the largest |coordinate|.
pub const REL_ROUNDING: f64 = 1e-12;

/// Relative weld distance for mesh vertices: this times the model's bounding-box diagonal.
pub const REL_WELD: f64 = 1e-9;

/// A mesh vertex farther than this many times the size of the box holding the bulk
/// of the vertices (5 % to 95 % quantiles per axis) from that box is an outlier, an
/// error: one corrupt vertex would otherwise set the weld distance and the bounds.
pub const OUTLIER_FACTOR: f64 = 1e4;

/// Relative tolerance under which a drop-cutter result counts as touching the
/// mesh in tests and verification (times the model scale).
pub const REL_CONTACT: f64 = 1e-9;

/// Relative slack added to upper bounds in branch-and-bound searches (times the
/// model's largest |coordinate|), far above rounding error and far below any
/// geometric feature: pruning stays conservative.
pub const REL_PRUNE_SLACK: f64 = 1e-9;

/// Relative convergence of parameter iterations (times the parameter's range).
/// Used where the result is the maximum of a smooth concave function, whose
/// value errs by O(parameter error^2): 1e-10 of a 10 mm range moves a height by
/// far less than 1e-12 mm.
pub const PARAMETER_CONVERGENCE: f64 = 1e-10;

/// Numeric epsilon derived from the largest |coordinate| of a model: rounding
/// error grows with coordinate magnitude, not with part size. Never user-facing.
#[derive(Clone, Copy, Debug, PartialEq, PartialOrd)]
pub struct Eps(pub f64);

impl Eps {
    /// Epsilon for a model whose largest |coordinate| is `max_abs_coord`.
    ///
    /// ```
    /// let e = scallop_geom::Eps::for_scale(100.0);
    /// assert!(e.0 > 0.0 && e.0 < 1e-6);
    /// ```
    #[must_use]
    pub fn for_scale(max_abs_coord: f64) -> Eps {
        Eps(REL_ROUNDING * max_abs_coord.max(1.0))
    }

    /// Epsilon for a box.
    #[must_use]
    pub fn for_bounds(b: &crate::Aabb3) -> Eps {
        Self::for_scale(b.max_abs_coord())
    }
}
