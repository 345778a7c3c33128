//! The tolerance budget of a job, built and validated once (docs/job.md,
//! "Tolerances"): the path tolerance is shared between the planning (the
//! tessellation, the drop-cutter sampling, the point merging and the
//! boundary, see `Tolerances::tessellation` and the strategy's own split) and
//! the arc fitting of the program; the simulation's gouge allowance is the
//! user's gouge tolerance plus the path tolerance (the chords between cutter
//! locations may dip below the CL surface by at most that much) plus the
//! chordal error of a tessellated part.

use scallop_geom::Tolerances;

use crate::EngineError;

/// Share of the path tolerance given to arc fitting when it is on.
pub const ARC_SHARE: f64 = 0.25;

/// The job's tolerances, checked, and their shares.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Budget {
    pub(crate) tolerances: Tolerances,
    pub(crate) arc_fitting: bool,
}

impl Budget {
    /// The budget of a job with these tolerances, with or without arc fitting.
    ///
    /// ```
    /// use scallop_engine::Budget;
    /// use scallop_geom::Tolerances;
    /// let b = Budget::new(Tolerances { path: 0.01, gouge: 0.0 }, true).unwrap();
    /// assert_eq!(b.planning().path, 0.0075);
    /// assert_eq!(b.arc_fitting(), Some(0.0025));
    /// assert_eq!(b.gouge_allowance(0.002), 0.012);
    /// assert!(Budget::new(Tolerances { path: 0.0, gouge: 0.0 }, false).is_err());
    /// assert!(Budget::new(Tolerances { path: 0.01, gouge: f64::NAN }, false).is_err());
    /// ```
    ///
    /// # Errors
    /// [`EngineError::BadTolerance`] for a path tolerance that is not finite
    /// and > 0, or a gouge tolerance that is not finite and >= 0.
    pub fn new(tolerances: Tolerances, arc_fitting: bool) -> Result<Budget, EngineError> {
        if !(tolerances.path.is_finite() && tolerances.path > 0.0) {
            return Err(EngineError::BadTolerance(tolerances.path));
        }
        if !(tolerances.gouge.is_finite() && tolerances.gouge >= 0.0) {
            return Err(EngineError::BadTolerance(tolerances.gouge));
        }
        Ok(Budget { tolerances, arc_fitting })
    }

    /// The tolerances as the job gave them.
    #[must_use]
    pub fn job(&self) -> Tolerances {
        self.tolerances
    }

    /// The tolerances the planning runs with: the path tolerance less the
    /// arc fitting's share when arcs are on.
    #[must_use]
    pub fn planning(&self) -> Tolerances {
        let share = if self.arc_fitting { 1.0 - ARC_SHARE } else { 1.0 };
        Tolerances { path: self.tolerances.path * share, ..self.tolerances }
    }

    /// The arc fitting's tolerance (mm), `None` when arcs are off.
    #[must_use]
    pub fn arc_fitting(&self) -> Option<f64> {
        self.arc_fitting.then_some(ARC_SHARE * self.tolerances.path)
    }

    /// The simulation's gouge allowance (mm) for a part approximated within
    /// `chordal_error`: gouge + path + chordal error.
    #[must_use]
    pub fn gouge_allowance(&self, chordal_error: f64) -> f64 {
        self.tolerances.gouge + chordal_error + self.tolerances.path
    }
}
