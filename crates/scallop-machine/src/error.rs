//! The crate's one error type: every variant names the place and the fix.

/// Everything that can go wrong when loading a machine or solving its kinematics.
///
/// ```
/// let err = scallop_machine::Machine::from_toml_str("schema = 3").unwrap_err();
/// assert!(err.to_string().contains("line 1"));
/// ```
#[non_exhaustive]
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MachineError {
    /// The text is not valid TOML, or a field has the wrong type or name.
    /// Fix: correct the file at the given line and column (see `docs/machine.md`).
    #[error(
        "machine description, line {line} column {column}: {message}; fix: correct this field as documented in docs/machine.md"
    )]
    Parse {
        /// 1-based line of the offending text.
        line: usize,
        /// 1-based column of the offending text.
        column: usize,
        /// What the TOML reader said.
        message: String,
    },
    /// A field parses but its value is not acceptable (stroke min >= max, non-unit
    /// direction, missing dynamics, ...).
    #[error("machine description, `{place}`: {problem}; fix: {fix}")]
    Invalid {
        /// The dotted path of the field, e.g. `axes.A.limits`.
        place: String,
        /// What is wrong.
        problem: String,
        /// How to repair it.
        fix: String,
    },
    /// The description is valid but describes something this version does not handle.
    #[error("machine description, `{place}`: {what} is not supported; fix: {fix}")]
    Unsupported {
        /// The dotted path of the field.
        place: String,
        /// What is not supported.
        what: String,
        /// How to proceed.
        fix: String,
    },
    /// A tool axis the machine's rotary axes cannot produce (outside the reachable
    /// orientation set of the kinematic chain, whatever the strokes).
    #[error("block {}: tool axis ({:.6}, {:.6}, {:.6}) is unreachable for this kinematic chain; fix: tilt the tool axis back into the machine's orientation range or use another setup", fmt_block(*.block), .axis[0], .axis[1], .axis[2])]
    Unreachable {
        /// Index of the pose in the path (`None` for a single inverse).
        block: Option<usize>,
        /// The requested tool axis in the part frame.
        axis: [f64; 3],
    },
    /// Every inverse solution of a pose leaves the stroke of an axis.
    #[error("block {}: axis {axis} = {value:.4} {unit} is outside its stroke [{min}, {max}] {unit}; fix: change the setup (part placement or orientation) or the tool axis so that {axis} stays inside its stroke", fmt_block(*.block))]
    LimitViolation {
        /// Index of the pose in the path (`None` for a single check).
        block: Option<usize>,
        /// The axis name as declared (e.g. `A`).
        axis: String,
        /// The NC word that would be needed (mm or degrees).
        value: f64,
        /// Lower end of the stroke (mm or degrees).
        min: f64,
        /// Upper end of the stroke (mm or degrees).
        max: f64,
        /// `mm` or `deg`.
        unit: &'static str,
    },
    /// A program leaves the travel of a linear axis (3-axis work, [`crate::Described::check_travel`]).
    #[error("the program moves axis {axis} to {value:.3} mm, outside its travel [{min}, {max}] mm; fix: {fix}")]
    OutOfTravel {
        /// The axis name as declared (e.g. `Z`).
        axis: String,
        /// The NC word outside the travel (mm).
        value: f64,
        /// Lower end of the travel (mm).
        min: f64,
        /// Upper end of the travel (mm).
        max: f64,
        /// How to repair it (the program's extent on the axis and what to move).
        fix: String,
    },
    /// The numeric inverse (for chains without a closed form) did not converge.
    #[error("block {}: the numeric inverse did not reproduce the pose (residual {residual:.3e}); fix: check that the pose is reachable, or give a closer previous joint vector", fmt_block(*.block))]
    NoConvergence {
        /// Index of the pose in the path (`None` for a single inverse).
        block: Option<usize>,
        /// Final residual (mm plus unit-vector norm).
        residual: f64,
    },
    /// Every way through this cutting block needs a rotary jump away from the pole (a
    /// branch flip or an unwind) while the tool is in the material.
    #[error(
        "block {block}: every solution needs axis {axis} to jump by {delta_deg:.1} deg while cutting; fix: split the cut with a link move (retract, reorient, approach) before this block, widen the stroke, or change the setup"
    )]
    FlipWhileCutting {
        /// Index of the pose in the path.
        block: usize,
        /// The rotary that would jump.
        axis: String,
        /// The smallest such jump found (deg).
        delta_deg: f64,
    },
    /// Joint-space subdivision did not bring the tip within the tolerance after the
    /// maximum bisection depth (spec 3.10).
    #[error(
        "block {block}: joint-space interpolation still deviates {deviation:.6} mm from the path after {depth} bisections; fix: check the block for a pole crossing or a branch change, or raise the path tolerance"
    )]
    SubdivisionFailed {
        /// Index of the block (its end pose) in the path.
        block: usize,
        /// Remaining tip deviation (mm).
        deviation: f64,
        /// Bisection depth reached.
        depth: usize,
    },
    /// The request does not fit the machine (wrong number of poses, axis unknown, ...).
    #[error("{place}: {problem}; fix: {fix}")]
    BadInput {
        /// Where.
        place: String,
        /// What is wrong.
        problem: String,
        /// How to repair it.
        fix: String,
    },
}

fn fmt_block(block: Option<usize>) -> String {
    block.map_or_else(|| "-".to_string(), |b| b.to_string())
}

impl MachineError {
    /// The same error, attributed to path block `block`.
    ///
    /// ```
    /// use scallop_machine::MachineError;
    /// let e = MachineError::NoConvergence { block: None, residual: 1.0 }.at_block(7);
    /// assert!(e.to_string().starts_with("block 7"));
    /// ```
    #[must_use]
    pub fn at_block(self, index: usize) -> Self {
        match self {
            MachineError::Unreachable { axis, .. } => MachineError::Unreachable { block: Some(index), axis },
            MachineError::LimitViolation { axis, value, min, max, unit, .. } => {
                MachineError::LimitViolation { block: Some(index), axis, value, min, max, unit }
            }
            MachineError::NoConvergence { residual, .. } => {
                MachineError::NoConvergence { block: Some(index), residual }
            }
            other => other,
        }
    }

    pub(crate) fn invalid(place: impl Into<String>, problem: impl Into<String>, fix: impl Into<String>) -> Self {
        MachineError::Invalid { place: place.into(), problem: problem.into(), fix: fix.into() }
    }
}
