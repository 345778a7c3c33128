//! The crate's error type.

/// Why an optimisation or a study cannot run. Each message names the place and
/// the fix.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum OptimError {
    /// A problem without variables. Fix: give at least one variable.
    #[error("the problem has no variables")]
    NoVariables,
    /// Bad bounds or a bad azimuth pair.
    #[error("variable `{name}`: {why}")]
    BadVariable {
        /// Variable name.
        name: String,
        /// What is wrong.
        why: &'static str,
    },
    /// A start value outside its bounds, or not finite.
    #[error("start value of `{name}` = {value} is outside its bounds or not finite; give a value inside the bounds")]
    BadStart {
        /// Variable name.
        name: String,
        /// The value.
        value: f64,
    },
    /// The start point cannot be evaluated (non-finite value), or is infeasible
    /// under the extreme barrier.
    #[error(
        "the start point cannot be used: value {value}, constraint violation {violation}; give a feasible start point"
    )]
    StartFailed {
        /// The black box's value.
        value: f64,
        /// Its constraint violation.
        violation: f64,
    },
    /// A budget below one evaluation.
    #[error("budget = {0}: give at least 1 black-box evaluation (the spec uses 1000 per K)")]
    BadBudget(f64),
    /// A negative or non-finite surrogate cost ratio.
    #[error("surrogate cost = {0}: give a ratio >= 0 (surrogate time / black-box time)")]
    BadCost(f64),
    /// A bad study setting, naming its job key.
    #[error("`{key}` = {value}: {fix}")]
    BadSetting {
        /// The job key, e.g. `optimize.k_max`.
        key: &'static str,
        /// The value given.
        value: String,
        /// What to do.
        fix: &'static str,
    },
    /// The machining model failed (clustering, planning, an unreachable zone).
    #[error("{0}")]
    Model(String),
}
