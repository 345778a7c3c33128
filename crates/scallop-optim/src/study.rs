//! The optimisation studies of finishing.md chapter 4: for each `K` in
//! `k_min..=k_max`, minimise the machining time over the partition weights and
//! the per-cluster feed directions (3-axis, 12.3), plus the orientations (3+2,
//! 12.4), or over the directions and the heuristic rotations (PCA heuristic,
//! 12.5), with [`OrthoMads`].
//!
//! The black box (clustering + connected components + planning + time) is
//! behind the [`MachiningModel`] trait, so the study is tested with cheap
//! models; the real one lives next to the clustering and the planner.
//!
//! Runs for different `K` are independent and run in parallel (rayon, indexed
//! collection): with [`CostModel::Fixed`] the study is identical to a
//! sequential one for a fixed seed.

use std::f64::consts::{FRAC_PI_2, PI};

use rayon::prelude::*;
use serde::Serialize;

use crate::error::OptimError;
use crate::mads::OrthoMads;
use crate::problem::{
    Barrier, BlackBoxOptimizer, Boundary, CostModel, Evaluation, HistoryPoint, MadsSettings, Objective, Problem,
    StopReason, Variable,
};

/// The three formulations of chapter 4.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
pub enum Formulation {
    /// 3-axis (Eq. 4.5): `omega` (4) and `Theta_k` (K); no constraint.
    #[serde(rename = "3axis")]
    ThreeAxis,
    /// 3+2 (Eq. 4.2): adds the tool axis `(Phi_k, Psi_k)` per cluster, with the
    /// accessibility constraint `n . a_k >= 0` on every sample of the zone.
    #[serde(rename = "3+2")]
    ThreePlusTwo,
    /// PCA heuristic (Eq. 4.6): K-means with the Euclidean metric (`omega = 1`),
    /// zones oriented by their PCA planes, variables `Theta_k` and `zeta_k`.
    #[serde(rename = "heuristic")]
    Heuristic,
}

impl Formulation {
    /// Whether the thesis runs the quadratic-model search step with it (3-axis
    /// only; 12.8, G19).
    #[must_use]
    pub fn model_search(self) -> bool {
        self == Formulation::ThreeAxis
    }
}

/// Which function the model evaluates (12.6).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Fidelity {
    /// The black box: clustering mesh 80 x 80, machining mesh 0.5 mm.
    BlackBox,
    /// S3: zones as PCA rectangles timed by Annex E (clustering mesh 40 x 40).
    S3,
    /// S4: the black box with a 5 mm machining mesh and `sh = 0.1 mm`
    /// (clustering mesh 40 x 40).
    S4,
}

/// The static surrogate ordering the poll points.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Surrogate {
    /// No surrogate: poll in direction order.
    None,
    /// S3 (Annex E, analytic).
    #[default]
    S3,
    /// S4 (coarse planner).
    S4,
}

impl Surrogate {
    fn fidelity(self) -> Option<Fidelity> {
        match self {
            Surrogate::None => None,
            Surrogate::S3 => Some(Fidelity::S3),
            Surrogate::S4 => Some(Fidelity::S4),
        }
    }
}

/// One point of a study: the variables of 12.1 for one `K` (angles in rad).
/// Vectors have one entry per cluster; the ones a formulation does not use are
/// zeros (`phi`, `psi` in 3-axis; `zeta` outside the heuristic).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Design {
    /// Clustering weights `omega` in `[0, 1]^4` (all 1 in the heuristic).
    pub omega: [f64; 4],
    /// Feed direction `Theta_k` in `[0, pi)` per cluster.
    pub theta: Vec<f64>,
    /// Tool-axis tilt `Phi_k` in `[-pi/2, pi/2]` per cluster (3+2).
    pub phi: Vec<f64>,
    /// Tool-axis azimuth `Psi_k` in `[0, pi)` per cluster (3+2).
    pub psi: Vec<f64>,
    /// Heuristic rotation `zeta_k` in `[-pi/2, pi/2]` per cluster.
    pub zeta: Vec<f64>,
}

impl Design {
    /// The thesis's start shape for `k` clusters: `omega = 1`, all angles 0.
    #[must_use]
    pub fn zeros(k: usize) -> Design {
        Design { omega: [1.0; 4], theta: vec![0.0; k], phi: vec![0.0; k], psi: vec![0.0; k], zeta: vec![0.0; k] }
    }

    /// The tool axis `a_k = (sin Phi cos Psi, sin Phi sin Psi, cos Phi)` of
    /// cluster `k` (finishing.md 4.5).
    #[must_use]
    pub fn axis(&self, k: usize) -> [f64; 3] {
        let (sp, cp) = self.phi[k].sin_cos();
        let (ss, cs) = self.psi[k].sin_cos();
        [sp * cs, sp * ss, cp]
    }
}

/// What the model says of a design.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Assessment {
    /// Predicted machining time (s): zones, connections and transitions.
    pub time_s: f64,
    /// Accessibility violation `h = sum_k sum_i max(0, -n_i . a_k)^2` (0 in
    /// 3-axis; 12.9).
    pub violation: f64,
}

/// One zone of a described plan.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ZoneReport {
    /// Zone label (connected-component order).
    pub zone: usize,
    /// Parent cluster.
    pub cluster: usize,
    /// Clustering cells in the zone.
    pub cells: usize,
    /// Feed direction (degrees from X, in the zone's frame).
    pub theta_deg: f64,
    /// Tool-axis tilt (degrees; 3+2 and heuristic orientations, else 0).
    pub phi_deg: f64,
    /// Tool-axis azimuth (degrees; 3+2 and heuristic orientations, else 0).
    pub psi_deg: f64,
    /// Heuristic rotation `zeta` (degrees; heuristic only, else 0).
    pub zeta_deg: f64,
    /// Machining time of the zone (s).
    pub time_s: f64,
    /// Cut + link length (mm).
    pub length_mm: f64,
    /// Passes.
    pub passes: usize,
}

/// The plan of a design, for reports and pictures.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PlanReport {
    /// Total time (s).
    pub time_s: f64,
    /// Time of the inter-zone transitions (s), included in `time_s`.
    pub transition_time_s: f64,
    /// Accessibility violation (0: every zone reachable).
    pub violation: f64,
    /// Clustering grid `[N_u, N_v]`.
    pub grid: [usize; 2],
    /// Zone label of each clustering cell, index `a * N_v + b` (`u` index `a`)
    /// (not serialised: large).
    #[serde(skip)]
    pub labels: Vec<u32>,
    /// XY position (mm) of each clustering cell's sample, same order (not
    /// serialised).
    #[serde(skip)]
    pub cell_xy: Vec<[f64; 2]>,
    /// The zones.
    pub zones: Vec<ZoneReport>,
}

/// The clustering + planning black box and its surrogates (finishing.md 12.2,
/// 12.6). `Partition` is the result of the clustering stage for one `(K,
/// omega)` and fidelity, kept by the study while only angles change.
pub trait MachiningModel: Sync {
    /// A partition (clusters, zones, per-zone data).
    type Partition: Send;

    /// Clusters the surface into `k` clusters with weights `omega` at the
    /// clustering mesh of `fidelity`.
    ///
    /// # Errors
    /// A clustering failure.
    fn partition(&self, k: usize, omega: &[f64; 4], fidelity: Fidelity) -> Result<Self::Partition, OptimError>;

    /// Time and accessibility violation of `design` on `partition`.
    ///
    /// # Errors
    /// A planning failure (the study charges it as a rejected point).
    fn assess(
        &self,
        partition: &Self::Partition,
        formulation: Formulation,
        design: &Design,
        fidelity: Fidelity,
    ) -> Result<Assessment, OptimError>;

    /// The start point of 12.8 on the black-box partition of `omega = 1`:
    /// `Theta_k` = the mean steepest-slope direction of cluster `k`, `Phi = Psi
    /// = 0`, `zeta = 0` (heuristic: `Theta_k` after orientation).
    ///
    /// # Errors
    /// A zone that no orientation can reach, or a clustering failure.
    fn initial_design(
        &self,
        k: usize,
        formulation: Formulation,
        partition: &Self::Partition,
    ) -> Result<Design, OptimError>;

    /// The full plan of `design` (black-box fidelity), for reports.
    ///
    /// # Errors
    /// A planning failure.
    fn describe(
        &self,
        partition: &Self::Partition,
        formulation: Formulation,
        design: &Design,
    ) -> Result<PlanReport, OptimError>;
}

/// A clock supplied by the caller (the library reads none): for measured
/// surrogate costs and per-K wall times.
pub trait Stopwatch: Sync {
    /// Seconds since any fixed origin.
    fn seconds(&self) -> f64;
}

/// Progress reports from a running study (called from worker threads).
pub trait StudyObserver: Sync {
    /// Budget spent so far by the run of `k` (black-box equivalents).
    fn progress(&self, _k: usize, _spent: f64) {}
    /// The run of `k` finished.
    fn finished(&self, _k: usize) {}
}

/// An observer that ignores everything.
#[derive(Clone, Copy, Debug, Default)]
pub struct Silent;

impl StudyObserver for Silent {}

/// Settings of a study (job table `[optimize]`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct StudySettings {
    /// Formulation.
    pub formulation: Formulation,
    /// Smallest `K` (`>= 1`).
    pub k_min: usize,
    /// Largest `K` (`>= 2`, `>= k_min`).
    pub k_max: usize,
    /// Budget per `K` in black-box-equivalent evaluations.
    pub budget: f64,
    /// Static surrogate ordering the poll.
    pub surrogate: Surrogate,
    /// Seed of the poll directions.
    pub seed: u64,
    /// Cost of surrogate evaluations.
    pub cost: CostModel,
    /// Quadratic-model search (`None`: 3-axis only, as in the thesis).
    pub model_search: Option<bool>,
    /// Constraint handling (3+2 and heuristic).
    pub barrier: Barrier,
    /// Start weights `omega` (12.8: all 1; ignored by the heuristic).
    pub start_omega: [f64; 4],
}

impl StudySettings {
    /// The thesis's settings for `formulation` (12.8): `K = 2..10`, 1000
    /// evaluations, surrogate S3, seed 0, surrogate cost 0.05.
    #[must_use]
    pub fn thesis(formulation: Formulation) -> StudySettings {
        StudySettings {
            formulation,
            k_min: 2,
            k_max: 10,
            budget: 1000.0,
            surrogate: Surrogate::S3,
            seed: 0,
            cost: CostModel::Fixed(0.05),
            model_search: None,
            barrier: Barrier::Progressive,
            start_omega: [1.0; 4],
        }
    }

    /// Checks the settings; errors name the job key.
    ///
    /// # Errors
    /// [`OptimError::BadSetting`].
    pub fn validate(&self) -> Result<(), OptimError> {
        if self.k_max < 2 {
            return Err(OptimError::BadSetting {
                key: "optimize.k_max",
                value: self.k_max.to_string(),
                fix: "give K_max >= 2 (the spec studies K = 2..10)",
            });
        }
        if self.k_min < 1 || self.k_min > self.k_max {
            return Err(OptimError::BadSetting {
                key: "optimize.k_min",
                value: self.k_min.to_string(),
                fix: "give 1 <= k_min <= k_max",
            });
        }
        if !(self.budget.is_finite() && self.budget >= 1.0) {
            return Err(OptimError::BadSetting {
                key: "optimize.budget",
                value: self.budget.to_string(),
                fix: "give at least 1 black-box evaluation per K (the spec uses 1000)",
            });
        }
        if let Some(w) = self.start_omega.iter().find(|w| !(0.0..=1.0).contains(*w)) {
            return Err(OptimError::BadSetting {
                key: "optimize.omega",
                value: w.to_string(),
                fix: "clustering weights must lie in [0, 1]",
            });
        }
        if let CostModel::Fixed(r) = self.cost
            && !(r.is_finite() && r >= 0.0)
        {
            return Err(OptimError::BadSetting {
                key: "optimize.surrogate_cost",
                value: r.to_string(),
                fix: "give a ratio >= 0 (surrogate time / black-box time) or \"measured\"",
            });
        }
        Ok(())
    }
}

/// The variables of a formulation for `k` clusters and their map to a [`Design`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    /// Formulation.
    pub formulation: Formulation,
    /// Clusters.
    pub k: usize,
}

impl Layout {
    /// The problem with `start` as start point (12.1-12.5 bounds; `Theta`
    /// periodic, `(Phi, Psi)` jointly periodic, `omega` and `zeta` clipped).
    #[must_use]
    pub fn problem(&self, start: &Design) -> Problem {
        let k = self.k;
        let mut variables = Vec::new();
        let mut values = Vec::new();
        if self.formulation != Formulation::Heuristic {
            for (i, w) in start.omega.iter().enumerate() {
                variables.push(Variable::clip(format!("omega_{}", i + 1), 0.0, 1.0));
                values.push(w.clamp(0.0, 1.0));
            }
        }
        for c in 0..k {
            variables.push(Variable::periodic(format!("theta_{}", c + 1), 0.0, PI));
            values.push(start.theta[c].rem_euclid(PI));
        }
        match self.formulation {
            Formulation::ThreeAxis => {}
            Formulation::ThreePlusTwo => {
                for c in 0..k {
                    let tilt = variables.len();
                    variables.push(Variable::clip(format!("phi_{}", c + 1), -FRAC_PI_2, FRAC_PI_2));
                    values.push(start.phi[c].clamp(-FRAC_PI_2, FRAC_PI_2));
                    variables.push(Variable {
                        name: format!("psi_{}", c + 1),
                        lower: 0.0,
                        upper: PI,
                        boundary: Boundary::Azimuth { tilt },
                    });
                    values.push(start.psi[c].rem_euclid(PI));
                }
            }
            Formulation::Heuristic => {
                for c in 0..k {
                    variables.push(Variable::clip(format!("zeta_{}", c + 1), -FRAC_PI_2, FRAC_PI_2));
                    values.push(start.zeta[c].clamp(-FRAC_PI_2, FRAC_PI_2));
                }
            }
        }
        Problem { variables, start: values }
    }

    /// The design of a point of [`Layout::problem`].
    #[must_use]
    pub fn design(&self, x: &[f64]) -> Design {
        let k = self.k;
        let mut d = Design::zeros(k);
        let mut at = 0;
        if self.formulation != Formulation::Heuristic {
            d.omega.copy_from_slice(&x[..4]);
            at = 4;
        }
        d.theta.copy_from_slice(&x[at..at + k]);
        at += k;
        match self.formulation {
            Formulation::ThreeAxis => {}
            Formulation::ThreePlusTwo => {
                for c in 0..k {
                    d.phi[c] = x[at + 2 * c];
                    d.psi[c] = x[at + 2 * c + 1];
                }
            }
            Formulation::Heuristic => d.zeta.copy_from_slice(&x[at..at + k]),
        }
        d
    }
}

/// The result for one `K`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct KResult {
    /// Number of clusters.
    pub k: usize,
    /// Objective at the start point (s).
    pub f0: f64,
    /// Best objective (s).
    pub f_best: f64,
    /// Gain `eta = (f0 - f*) / f0` (Eq. 4.4).
    pub eta: f64,
    /// Black-box evaluations.
    pub evaluations: usize,
    /// Surrogate evaluations.
    pub surrogate_evaluations: usize,
    /// Budget spent (black-box equivalents).
    pub spent: f64,
    /// Why the run stopped.
    pub stop: StopReason,
    /// Wall time of the run (s), when a [`Stopwatch`] was given.
    pub wall_time_s: Option<f64>,
    /// Wall time of its black-box evaluations, when a [`Stopwatch`] was given.
    pub black_box_times: Option<EvaluationTimes>,
    /// Start design.
    pub start: Design,
    /// Best design.
    pub best: Design,
    /// The best design's plan.
    pub plan: PlanReport,
    /// Best value after each improvement.
    pub history: Vec<HistoryPoint>,
}

/// The wall times of the black-box evaluations of one run (each runs on one
/// thread: the study parallelises over `K`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct EvaluationTimes {
    /// Number of timed evaluations.
    pub count: usize,
    /// Mean (ms).
    pub mean_ms: f64,
    /// Median (ms).
    pub median_ms: f64,
    /// 95th percentile (ms; nearest rank).
    pub p95_ms: f64,
    /// Largest (ms).
    pub max_ms: f64,
}

impl EvaluationTimes {
    /// The summary of `seconds` (None when empty or not all finite).
    #[must_use]
    pub fn from_seconds(seconds: &[f64]) -> Option<EvaluationTimes> {
        if seconds.is_empty() || !seconds.iter().all(|s| s.is_finite()) {
            return None;
        }
        let mut ms: Vec<f64> = seconds.iter().map(|s| 1e3 * s).collect();
        ms.sort_by(f64::total_cmp);
        let n = ms.len();
        #[allow(clippy::cast_precision_loss, clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        let rank = |q: f64| ms[((q * n as f64).ceil() as usize).clamp(1, n) - 1];
        #[allow(clippy::cast_precision_loss)]
        let mean_ms = ms.iter().sum::<f64>() / n as f64;
        Some(EvaluationTimes { count: n, mean_ms, median_ms: rank(0.5), p95_ms: rank(0.95), max_ms: ms[n - 1] })
    }
}

/// A whole study.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Study {
    /// Settings used.
    pub settings: StudySettings,
    /// One result per `K`, in increasing `K`.
    pub results: Vec<KResult>,
    /// Index in `results` of the fastest plan.
    pub best: usize,
    /// Mean gain over the `K` values.
    pub mean_eta: f64,
}

/// The objective seen by MADS for one `K`: caches the last partition per fidelity.
struct KObjective<'a, M: MachiningModel> {
    model: &'a M,
    layout: Layout,
    settings: &'a StudySettings,
    observer: &'a dyn StudyObserver,
    clock: Option<&'a dyn Stopwatch>,
    partitions: Vec<(Fidelity, [u64; 4], M::Partition)>,
    spent: f64,
    black_box_seconds: f64,
    black_box_count: usize,
    /// Every black-box evaluation's wall time (s), when a clock is given.
    black_box_times: Vec<f64>,
    last_surrogate_seconds: f64,
    /// The first model error met (reported if the start point fails).
    first_error: Option<String>,
}

impl<M: MachiningModel> KObjective<'_, M> {
    fn failed(&mut self, e: &OptimError) -> Evaluation {
        if self.first_error.is_none() {
            self.first_error = Some(e.to_string());
        }
        Evaluation { value: f64::INFINITY, violation: 0.0 }
    }

    fn run(&mut self, x: &[f64], fidelity: Fidelity) -> Evaluation {
        let design = self.layout.design(x);
        let omega = if self.layout.formulation == Formulation::Heuristic { [1.0; 4] } else { design.omega };
        let key = omega.map(f64::to_bits);
        let slot = self.partitions.iter().position(|(f, k, _)| *f == fidelity && *k == key);
        let slot = match slot {
            Some(i) => i,
            None => match self.model.partition(self.layout.k, &omega, fidelity) {
                Ok(p) => {
                    self.partitions.retain(|(f, _, _)| *f != fidelity);
                    self.partitions.push((fidelity, key, p));
                    self.partitions.len() - 1
                }
                Err(e) => return self.failed(&e),
            },
        };
        match self.model.assess(&self.partitions[slot].2, self.layout.formulation, &design, fidelity) {
            Ok(a) => Evaluation { value: a.time_s, violation: a.violation },
            Err(e) => self.failed(&e),
        }
    }

    fn seconds(&self) -> f64 {
        self.clock.map_or(0.0, |c| c.seconds())
    }
}

impl<M: MachiningModel> Objective for KObjective<'_, M> {
    fn evaluate(&mut self, x: &[f64]) -> Evaluation {
        let t0 = self.seconds();
        let e = self.run(x, Fidelity::BlackBox);
        let dt = self.seconds() - t0;
        self.black_box_seconds += dt;
        if self.clock.is_some() {
            self.black_box_times.push(dt);
        }
        self.black_box_count += 1;
        self.spent += 1.0;
        self.observer.progress(self.layout.k, self.spent);
        e
    }

    fn surrogate(&mut self, x: &[f64]) -> Option<Evaluation> {
        let fidelity = self.settings.surrogate.fidelity()?;
        let t0 = self.seconds();
        let e = self.run(x, fidelity);
        self.last_surrogate_seconds = self.seconds() - t0;
        if let CostModel::Fixed(r) = self.settings.cost {
            self.spent += r;
        }
        Some(e)
    }

    fn measured_surrogate_cost(&mut self) -> Option<f64> {
        if self.black_box_count == 0 || self.black_box_seconds <= 0.0 {
            return Some(0.0);
        }
        #[allow(clippy::cast_precision_loss)]
        let mean = self.black_box_seconds / self.black_box_count as f64;
        let cost = self.last_surrogate_seconds / mean;
        self.spent += cost;
        Some(cost)
    }
}

/// Runs the study: one OrthoMADS run per `K`, in parallel.
///
/// # Errors
/// Bad settings (naming the job key), a start point the model cannot evaluate
/// (e.g. a zone no orientation can reach), a model failure while describing
/// the best plan.
pub fn run_study<M: MachiningModel>(
    model: &M,
    settings: &StudySettings,
    observer: &dyn StudyObserver,
    clock: Option<&dyn Stopwatch>,
) -> Result<Study, OptimError> {
    settings.validate()?;
    let ks: Vec<usize> = (settings.k_min..=settings.k_max).collect();
    let results: Vec<Result<KResult, OptimError>> =
        ks.par_iter().map(|&k| run_k(model, settings, k, observer, clock)).collect();
    let results: Vec<KResult> = results.into_iter().collect::<Result<_, _>>()?;
    let best = (0..results.len()).min_by(|&a, &b| results[a].f_best.total_cmp(&results[b].f_best)).unwrap_or(0);
    #[allow(clippy::cast_precision_loss)]
    let mean_eta = results.iter().map(|r| r.eta).sum::<f64>() / results.len().max(1) as f64;
    Ok(Study { settings: *settings, results, best, mean_eta })
}

/// One `K` of [`run_study`].
///
/// # Errors
/// See [`run_study`].
pub fn run_k<M: MachiningModel>(
    model: &M,
    settings: &StudySettings,
    k: usize,
    observer: &dyn StudyObserver,
    clock: Option<&dyn Stopwatch>,
) -> Result<KResult, OptimError> {
    let t0 = clock.map(Stopwatch::seconds);
    let layout = Layout { formulation: settings.formulation, k };
    let start_omega = if settings.formulation == Formulation::Heuristic { [1.0; 4] } else { settings.start_omega };
    let start_partition = model.partition(k, &start_omega, Fidelity::BlackBox)?;
    let mut start = model.initial_design(k, settings.formulation, &start_partition)?;
    start.omega = start_omega;
    let problem = layout.problem(&start);
    let mads = OrthoMads {
        settings: MadsSettings {
            budget: settings.budget,
            seed: settings.seed,
            cost: settings.cost,
            model_search: settings.model_search.unwrap_or(settings.formulation.model_search()),
            opportunistic: true,
            barrier: settings.barrier,
        },
    };
    let mut objective = KObjective {
        model,
        layout,
        settings,
        observer,
        clock,
        partitions: vec![(Fidelity::BlackBox, start_omega.map(f64::to_bits), start_partition)],
        spent: 0.0,
        black_box_seconds: 0.0,
        black_box_count: 0,
        black_box_times: Vec::new(),
        last_surrogate_seconds: 0.0,
        first_error: None,
    };
    let outcome = mads.minimize(&problem, &mut objective);
    let outcome = outcome.map_err(|e| match e {
        OptimError::StartFailed { value, violation } => OptimError::Model(format!(
            "K = {k}: the start point of the {:?} study cannot be planned (time {value} s, \
             accessibility violation {violation}){}",
            settings.formulation,
            objective.first_error.as_ref().map_or_else(
                || ": a zone no orientation can reach (use the progressive barrier) or a planning failure".to_string(),
                |e| format!(": {e}")
            )
        )),
        other => other,
    })?;
    let best = layout.design(&outcome.best);
    let omega = if settings.formulation == Formulation::Heuristic { [1.0; 4] } else { best.omega };
    let partition = model.partition(k, &omega, Fidelity::BlackBox)?;
    let plan = model.describe(&partition, settings.formulation, &best)?;
    observer.finished(k);
    let (f0, f_best) = (outcome.start_eval.value, outcome.best_eval.value);
    Ok(KResult {
        k,
        f0,
        f_best,
        eta: if f0 > 0.0 { (f0 - f_best) / f0 } else { 0.0 },
        evaluations: outcome.evaluations,
        surrogate_evaluations: outcome.surrogate_evaluations,
        spent: outcome.spent,
        stop: outcome.stop,
        wall_time_s: t0.and_then(|t| clock.map(|c| c.seconds() - t)),
        black_box_times: EvaluationTimes::from_seconds(&objective.black_box_times),
        start: layout.design(&outcome.start),
        best,
        plan,
        history: outcome.history,
    })
}

/// The model's time of the whole surface as one 3-axis zone along each of
/// `directions` (rad), in their order: the single-zone plans a zone plan has to
/// beat (one cluster, `omega = 1`).
///
/// # Errors
/// A clustering or planning failure of the model.
pub fn single_zone_times<M: MachiningModel>(model: &M, directions: &[f64]) -> Result<Vec<f64>, OptimError> {
    let partition = model.partition(1, &[1.0; 4], Fidelity::BlackBox)?;
    directions
        .iter()
        .map(|&theta| {
            let design = Design { theta: vec![theta], ..Design::zeros(1) };
            model.assess(&partition, Formulation::ThreeAxis, &design, Fidelity::BlackBox).map(|a| a.time_s)
        })
        .collect()
}

/// The model's plan of the whole surface as one 3-axis zone along `theta` (rad).
///
/// # Errors
/// A clustering or planning failure of the model.
pub fn single_zone_plan<M: MachiningModel>(model: &M, theta: f64) -> Result<PlanReport, OptimError> {
    let partition = model.partition(1, &[1.0; 4], Fidelity::BlackBox)?;
    let design = Design { theta: vec![theta], ..Design::zeros(1) };
    model.describe(&partition, Formulation::ThreeAxis, &design)
}

#[cfg(test)]
mod evaluation_times_tests {
    use super::EvaluationTimes;

    #[test]
    fn summary_of_one_to_a_hundred_milliseconds() {
        // Shuffled 1..=100 ms: mean 50.5, nearest-rank median 50, p95 95, max 100.
        let seconds: Vec<f64> = (0..100).map(|i| f64::from((i * 37) % 100 + 1) * 1e-3).collect();
        let t = EvaluationTimes::from_seconds(&seconds).expect("finite");
        assert_eq!(t.count, 100);
        assert!((t.mean_ms - 50.5).abs() < 1e-9, "{t:?}");
        assert!((t.median_ms - 50.0).abs() < 1e-9, "{t:?}");
        assert!((t.p95_ms - 95.0).abs() < 1e-9, "{t:?}");
        assert!((t.max_ms - 100.0).abs() < 1e-9, "{t:?}");
    }

    #[test]
    fn no_summary_of_nothing_or_of_a_nan() {
        assert_eq!(EvaluationTimes::from_seconds(&[]), None);
        assert_eq!(EvaluationTimes::from_seconds(&[1e-3, f64::NAN]), None);
        let one = EvaluationTimes::from_seconds(&[2e-3]).expect("one");
        assert!((one.median_ms - 2.0).abs() < 1e-12 && (one.p95_ms - 2.0).abs() < 1e-12);
    }
}
