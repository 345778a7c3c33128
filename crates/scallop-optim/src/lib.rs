//! Black-box optimisation of finishing plans (finishing.md 12, issue 8).
//!
//! - [`BlackBoxOptimizer`] and its native implementation [`OrthoMads`], the
//!   compact OrthoMADS of finishing.md 12.9: variables scaled to `[0, 1]`,
//!   periodic and jointly periodic variables, ORTHO 2N poll directions from a
//!   seeded Halton sequence, poll ordering by a static surrogate whose cost is
//!   charged to the budget, opportunistic poll, quadratic-model search,
//!   progressive barrier, a cache on mesh points, budgets in
//!   black-box-equivalent evaluations.
//! - [`study`]: the three formulations of chapter 4 (3-axis, 3+2, PCA
//!   heuristic) over `K = k_min..=k_max`, run in parallel per `K`, behind the
//!   [`study::MachiningModel`] trait (the clustering + planning black box and
//!   its surrogates S3 and S4).
//!
//! # Invariants
//! - Never performs I/O, never prints, never reads the clock: measured
//!   surrogate costs and wall times come from the caller
//!   ([`Objective::measured_surrogate_cost`], [`study::Stopwatch`]).
//! - Deterministic: with [`CostModel::Fixed`] the same inputs and seed give the
//!   same result bit for bit, on any number of threads (per-K runs are
//!   independent and collected by index).
//! - The budget is never exceeded with [`CostModel::Fixed`]; the result is never
//!   worse than the (feasible) start point; cache hits cost nothing.

mod error;
mod mads;
mod plot;
mod problem;
pub mod study;
pub mod surface;
pub use scallop_geom::tol::optim as tol;

pub use error::OptimError;
pub use mads::OrthoMads;
pub use plot::{convergence_svg, zones_svg};
pub use problem::{
    Barrier, BlackBoxOptimizer, Boundary, CostModel, Evaluation, HistoryPoint, MadsSettings, Objective, Outcome,
    Problem, StopReason, Variable,
};
