//! What an optimiser is given (variables, bounds, the black box and its
//! surrogate, a budget) and what it returns.

use serde::Serialize;

use crate::error::OptimError;

/// How a variable behaves at its bounds (finishing.md 12.9).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum Boundary {
    /// Clipped to `[lower, upper]` (`omega`, `zeta`).
    Clip,
    /// Periodic with period `upper - lower`: wrapped, never clipped (a feed
    /// direction `Theta` in `[0, pi]`).
    Periodic,
    /// Periodic jointly with the tilt variable of index `tilt` (an azimuth `Psi`
    /// in `[0, pi]` with its tilt `Phi` in `[-pi/2, pi/2]`): leaving the range
    /// by one period maps `(Phi, Psi) -> (-Phi, Psi -+ pi)`, the same tool axis.
    /// The tilt must have symmetric bounds and [`Boundary::Clip`].
    Azimuth {
        /// Index of the tilt variable.
        tilt: usize,
    },
}

/// One optimisation variable.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Variable {
    /// Name shown in reports and errors (e.g. `theta_2`).
    pub name: String,
    /// Lower bound.
    pub lower: f64,
    /// Upper bound (`> lower`).
    pub upper: f64,
    /// Behaviour at the bounds.
    pub boundary: Boundary,
}

impl Variable {
    /// A clipped variable.
    #[must_use]
    pub fn clip(name: impl Into<String>, lower: f64, upper: f64) -> Variable {
        Variable { name: name.into(), lower, upper, boundary: Boundary::Clip }
    }

    /// A periodic variable of period `upper - lower`.
    #[must_use]
    pub fn periodic(name: impl Into<String>, lower: f64, upper: f64) -> Variable {
        Variable { name: name.into(), lower, upper, boundary: Boundary::Periodic }
    }
}

/// A box-bounded problem and its start point.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Problem {
    /// The variables.
    pub variables: Vec<Variable>,
    /// The start point (one value per variable, inside the bounds; periodic
    /// values are wrapped).
    pub start: Vec<f64>,
}

impl Problem {
    /// Checks bounds, the start point and the azimuth pairs.
    ///
    /// # Errors
    /// [`OptimError::BadVariable`] or [`OptimError::BadStart`] naming the variable.
    pub fn validate(&self) -> Result<(), OptimError> {
        if self.variables.is_empty() {
            return Err(OptimError::NoVariables);
        }
        if self.start.len() != self.variables.len() {
            return Err(OptimError::BadStart {
                name: format!("{} values for {} variables", self.start.len(), self.variables.len()),
                value: f64::NAN,
            });
        }
        for (i, v) in self.variables.iter().enumerate() {
            let bad = |why: &'static str| OptimError::BadVariable { name: v.name.clone(), why };
            if !(v.lower.is_finite() && v.upper.is_finite() && v.upper > v.lower) {
                return Err(bad("bounds must be finite with upper > lower"));
            }
            if let Boundary::Azimuth { tilt } = v.boundary {
                let t = self.variables.get(tilt).ok_or_else(|| bad("its tilt index is out of range"))?;
                if tilt == i || t.boundary != Boundary::Clip || (t.lower + t.upper).abs() > 1e-12 * t.upper.abs() {
                    return Err(bad("its tilt must be another clipped variable with symmetric bounds"));
                }
            }
            let x = self.start[i];
            let inside = x >= v.lower && x <= v.upper;
            if !x.is_finite() || (v.boundary == Boundary::Clip && !inside) {
                return Err(OptimError::BadStart { name: v.name.clone(), value: x });
            }
        }
        Ok(())
    }
}

/// One evaluation of the black box or of its surrogate.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Evaluation {
    /// Objective value (a non-finite value is a failed evaluation, rejected).
    pub value: f64,
    /// Constraint violation `h >= 0` (0: feasible; finishing.md 12.9).
    pub violation: f64,
}

impl Evaluation {
    /// A feasible value.
    #[must_use]
    pub fn feasible(value: f64) -> Evaluation {
        Evaluation { value, violation: 0.0 }
    }

    /// Whether it is usable: finite value and finite, non-negative violation.
    #[must_use]
    pub fn is_valid(&self) -> bool {
        self.value.is_finite() && self.violation.is_finite() && self.violation >= 0.0
    }
}

/// The function to minimise. Called with unscaled values, one per variable.
pub trait Objective {
    /// The black box (cost: 1 evaluation of the budget).
    fn evaluate(&mut self, x: &[f64]) -> Evaluation;

    /// The static surrogate used to order poll points, when there is one.
    /// Return `None` when there is none (the default): then no cost is charged.
    fn surrogate(&mut self, _x: &[f64]) -> Option<Evaluation> {
        None
    }

    /// With [`CostModel::Measured`]: the cost of the last surrogate evaluation
    /// in black-box equivalents (its wall time over the running mean wall time
    /// of the black box). The library reads no clock: the caller measures.
    /// `None` (the default) charges nothing.
    fn measured_surrogate_cost(&mut self) -> Option<f64> {
        None
    }
}

/// What a surrogate evaluation costs, in black-box-equivalent evaluations.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CostModel {
    /// A fixed ratio (deterministic runs): each surrogate evaluation costs this.
    Fixed(f64),
    /// As reported by [`Objective::measured_surrogate_cost`] (not reproducible:
    /// it depends on the machine's load).
    Measured,
}

/// How constraints are handled.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Barrier {
    /// Progressive barrier (Audet and Dennis 2009): a feasible incumbent and an
    /// infeasible one with `h <= h_max`, `h_max` non-increasing.
    #[default]
    Progressive,
    /// Extreme barrier: any point with `h > 0` is rejected (the start point
    /// must be feasible).
    Extreme,
}

/// Settings of [`crate::OrthoMads`] (finishing.md 12.9).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct MadsSettings {
    /// Budget in black-box-equivalent evaluations (start point included).
    pub budget: f64,
    /// Seed of the Halton sequence of poll directions.
    pub seed: u64,
    /// Cost of surrogate evaluations.
    pub cost: CostModel,
    /// Quadratic-model search step (the thesis's 3-axis runs; off for 3+2 and
    /// the heuristic).
    pub model_search: bool,
    /// Stop the poll at the first improving point.
    pub opportunistic: bool,
    /// Constraint handling.
    pub barrier: Barrier,
}

impl Default for MadsSettings {
    /// 1000 evaluations, seed 0, surrogate cost 0.1, no model search,
    /// opportunistic, progressive barrier.
    fn default() -> Self {
        MadsSettings {
            budget: 1000.0,
            seed: 0,
            cost: CostModel::Fixed(0.1),
            model_search: false,
            opportunistic: true,
            barrier: Barrier::Progressive,
        }
    }
}

impl MadsSettings {
    /// Checks the budget and the cost ratio.
    ///
    /// # Errors
    /// [`OptimError::BadBudget`], [`OptimError::BadCost`].
    pub fn validate(&self) -> Result<(), OptimError> {
        if !(self.budget.is_finite() && self.budget >= 1.0) {
            return Err(OptimError::BadBudget(self.budget));
        }
        if let CostModel::Fixed(r) = self.cost
            && !(r.is_finite() && r >= 0.0)
        {
            return Err(OptimError::BadCost(r));
        }
        Ok(())
    }
}

/// Why the run stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StopReason {
    /// The budget is spent.
    Budget,
    /// The mesh size fell below [`crate::tol::MIN_MESH_SIZE`].
    MeshConverged,
}

/// One point of the convergence history.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct HistoryPoint {
    /// Budget spent so far (black-box equivalents).
    pub spent: f64,
    /// Best feasible value so far.
    pub best: f64,
}

/// The result of a run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Outcome {
    /// Best point (unscaled): the best feasible one, or the least infeasible
    /// when none is feasible.
    pub best: Vec<f64>,
    /// Its evaluation.
    pub best_eval: Evaluation,
    /// The start point as evaluated (after snapping onto the lattice, within
    /// `1 / tol::LATTICE` of the given start in scaled units).
    pub start: Vec<f64>,
    /// The start point's evaluation.
    pub start_eval: Evaluation,
    /// Budget spent (black-box equivalents; `<=` the budget with
    /// [`CostModel::Fixed`]).
    pub spent: f64,
    /// Black-box evaluations.
    pub evaluations: usize,
    /// Surrogate evaluations.
    pub surrogate_evaluations: usize,
    /// Requests answered by the cache (free).
    pub cache_hits: usize,
    /// Iterations (search + poll).
    pub iterations: usize,
    /// Final mesh index `l`.
    pub mesh_index: i32,
    /// Why it stopped.
    pub stop: StopReason,
    /// Best feasible value after each improvement (and at the start).
    pub history: Vec<HistoryPoint>,
}

/// A derivative-free minimiser.
pub trait BlackBoxOptimizer {
    /// Minimises `objective` over `problem`.
    ///
    /// # Errors
    /// Bad problem or settings; a start point that cannot be evaluated.
    fn minimize(&self, problem: &Problem, objective: &mut dyn Objective) -> Result<Outcome, OptimError>;
}
