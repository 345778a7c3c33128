//! The native compact OrthoMADS of finishing.md 12.9.
//!
//! Why our own and not the `basin` crate (the guide's first choice): the
//! normative MADS of 12.9 needs (1) periodic feed directions that wrap instead
//! of being clipped and an azimuth that wraps jointly with its tilt
//! (`(Phi, Psi) -> (-Phi, Psi -+ pi)`), (2) poll points ordered by a static
//! surrogate whose evaluations are charged to the budget in black-box
//! equivalents, (3) a cache keyed on mesh points where hits are free and (4) a
//! budget counted in those equivalents. basin's MADS takes box bounds through
//! the extreme barrier and counts black-box calls only, so (1)-(4) would each
//! need a fork or a wrapper that fights its internals; the whole algorithm is
//! ~400 lines here, deterministic, and keeps the dependency tree small.
//!
//! # Algorithm
//! - Variables are scaled to `[0, 1]` by their bounds and live on an integer
//!   lattice of `tol::LATTICE` steps, so that every mesh of the run is a sub-
//!   lattice, cache keys are exact and periodic wraps are exact.
//! - Mesh index `l` (`l_0 = 0`, `l >= -2`): frame size `Delta^p = 0.1 * 2^-l`,
//!   mesh size `Delta^m = 0.1 * min(1, 4^-l)`.
//! - Poll (ORTHO 2N): `q` = the Halton vector of index `1 + 1_000_003 seed + k`
//!   (iteration `k`) mapped to `[-1, 1]^n`; `H = I - 2 q q^T / |q|^2`;
//!   directions `+-H_j`; poll point `x + Delta^p d / |d|_inf` rounded to the
//!   `Delta^m` grid centred on `x`, then mapped into the bounds (clip, wrap,
//!   joint wrap).
//! - Order: by the static surrogate when there is one (evaluated on every new
//!   poll point, cost charged; feasible first, then by value), else the
//!   direction closest to the last successful one first, then index order.
//!   Opportunistic: the poll stops at the first dominating point.
//! - Search (when enabled): one point per iteration, the minimiser in the frame
//!   box of a quadratic model fitted by minimum-norm least squares (the norm of
//!   the Hessian's coefficients; minimum Frobenius norm when underdetermined)
//!   to the cached feasible points within `2 Delta^p` of the incumbent.
//! - Update: success `l <- max(l - 1, -2)`, failure `l <- l + 1`.
//! - Constraints: progressive barrier (a feasible incumbent and an infeasible
//!   one with `h <= h_max`; `h_max` non-increasing; the poll centre is the
//!   feasible incumbent when there is one). Simplification: the secondary
//!   (infeasible) incumbent is not polled while a feasible one exists.
//! - Stop when the next black-box evaluation would exceed the budget, or when
//!   `Delta^m < 1e-9`.

use std::collections::HashMap;

use scallop_geom::nalgebra::{DMatrix, DVector};

use crate::error::OptimError;
use crate::problem::{
    Barrier, BlackBoxOptimizer, Boundary, CostModel, Evaluation, HistoryPoint, MadsSettings, Objective, Outcome,
    Problem, StopReason,
};
use crate::tol;

/// The native OrthoMADS (finishing.md 12.9).
///
/// ```
/// use scallop_optim::{BlackBoxOptimizer, Evaluation, MadsSettings, Objective, OrthoMads, Problem, Variable};
/// struct Bowl;
/// impl Objective for Bowl {
///     fn evaluate(&mut self, x: &[f64]) -> Evaluation {
///         Evaluation::feasible((x[0] - 1.0).powi(2) + (x[1] + 2.0).powi(2))
///     }
/// }
/// let problem = Problem {
///     variables: vec![Variable::clip("a", -5.0, 5.0), Variable::clip("b", -5.0, 5.0)],
///     start: vec![4.0, 4.0],
/// };
/// let mads = OrthoMads { settings: MadsSettings { budget: 300.0, ..MadsSettings::default() } };
/// let out = mads.minimize(&problem, &mut Bowl).unwrap();
/// assert!(out.best_eval.value < 1e-6 && out.spent <= 300.0);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct OrthoMads {
    /// Settings.
    pub settings: MadsSettings,
}

impl BlackBoxOptimizer for OrthoMads {
    fn minimize(&self, problem: &Problem, objective: &mut dyn Objective) -> Result<Outcome, OptimError> {
        problem.validate()?;
        self.settings.validate()?;
        Run::new(problem, objective, self.settings).run()
    }
}

/// A point of the lattice: scaled coordinate `m / LATTICE` per variable.
type Lattice = Vec<i64>;

/// The outcome of one trial point under the barrier.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Verdict {
    /// Better feasible point, or an infeasible point dominating the infeasible incumbent.
    Dominating,
    /// Infeasible, not dominating, but with a smaller violation.
    Improving,
    /// Nothing gained.
    Nothing,
}

struct Run<'a> {
    problem: &'a Problem,
    objective: &'a mut dyn Objective,
    settings: MadsSettings,
    /// Evaluated points in evaluation order (deterministic iteration).
    archive: Vec<(Lattice, Evaluation)>,
    index: HashMap<Lattice, usize>,
    surrogate_cache: HashMap<Lattice, Evaluation>,
    spent: f64,
    evaluations: usize,
    surrogate_evaluations: usize,
    cache_hits: usize,
    iterations: usize,
    level: i32,
    feasible: Option<usize>,
    infeasible: Option<usize>,
    h_max: f64,
    last_success: Option<Vec<f64>>,
    last_surrogate_cost: f64,
    history: Vec<HistoryPoint>,
}

impl<'a> Run<'a> {
    fn new(problem: &'a Problem, objective: &'a mut dyn Objective, settings: MadsSettings) -> Run<'a> {
        Run {
            problem,
            objective,
            settings,
            archive: Vec::new(),
            index: HashMap::new(),
            surrogate_cache: HashMap::new(),
            spent: 0.0,
            evaluations: 0,
            surrogate_evaluations: 0,
            cache_hits: 0,
            iterations: 0,
            level: 0,
            feasible: None,
            infeasible: None,
            h_max: if settings.barrier == Barrier::Extreme { 0.0 } else { f64::INFINITY },
            last_success: None,
            last_surrogate_cost: 0.0,
            history: Vec::new(),
        }
    }

    fn n(&self) -> usize {
        self.problem.variables.len()
    }

    /// Unscaled values of a lattice point.
    fn unscale(&self, m: &[i64]) -> Vec<f64> {
        #[allow(clippy::cast_precision_loss)] // |m| <= LATTICE < 2^53: exact
        self.problem
            .variables
            .iter()
            .zip(m)
            .map(|(v, &k)| v.lower + (k as f64 / tol::LATTICE as f64) * (v.upper - v.lower))
            .collect()
    }

    /// The lattice point nearest to an unscaled point, mapped into the bounds.
    fn snap(&self, x: &[f64]) -> Lattice {
        #[allow(clippy::cast_possible_truncation, clippy::cast_precision_loss)] // bounded by validate()
        let mut m: Lattice = self
            .problem
            .variables
            .iter()
            .zip(x)
            .map(|(v, &xi)| ((xi - v.lower) / (v.upper - v.lower) * tol::LATTICE as f64).round() as i64)
            .collect();
        self.project(&mut m);
        m
    }

    /// Maps a lattice point into the bounds: clip, wrap, joint wrap (12.9).
    fn project(&self, m: &mut [i64]) {
        let vars = &self.problem.variables;
        for (k, v) in vars.iter().enumerate() {
            if v.boundary == Boundary::Clip {
                m[k] = m[k].clamp(0, tol::LATTICE);
            }
        }
        for (k, v) in vars.iter().enumerate() {
            match v.boundary {
                Boundary::Clip => {}
                Boundary::Periodic => m[k] = m[k].rem_euclid(tol::LATTICE),
                Boundary::Azimuth { tilt } => {
                    let turns = m[k].div_euclid(tol::LATTICE);
                    m[k] = m[k].rem_euclid(tol::LATTICE);
                    if turns.rem_euclid(2) == 1 {
                        m[tilt] = tol::LATTICE - m[tilt];
                    }
                }
            }
        }
    }

    fn frame_steps(&self) -> i64 {
        if self.level >= 0 { tol::INITIAL_FRAME_STEPS >> self.level } else { tol::INITIAL_FRAME_STEPS << (-self.level) }
    }

    fn mesh_steps(&self) -> i64 {
        if self.level >= 0 { tol::INITIAL_FRAME_STEPS >> (2 * self.level).min(62) } else { tol::INITIAL_FRAME_STEPS }
    }

    fn mesh_size(&self) -> f64 {
        #[allow(clippy::cast_precision_loss)] // small integers
        let size = self.mesh_steps() as f64 / tol::LATTICE as f64;
        size
    }

    /// Evaluates the black box at `m` unless cached. `None` when the budget
    /// cannot pay for it.
    fn evaluate(&mut self, m: &Lattice) -> Option<(usize, bool)> {
        if let Some(&i) = self.index.get(m) {
            self.cache_hits += 1;
            return Some((i, true));
        }
        if self.spent + 1.0 > self.settings.budget {
            return None;
        }
        let x = self.unscale(m);
        let mut e = self.objective.evaluate(&x);
        if e.value.is_nan() {
            e.value = f64::INFINITY;
        }
        self.spent += 1.0;
        self.evaluations += 1;
        let i = self.archive.len();
        self.archive.push((m.clone(), e));
        self.index.insert(m.clone(), i);
        Some((i, false))
    }

    /// The surrogate at `m` (cached, cost charged). `None` when there is no
    /// surrogate or the budget cannot pay for it.
    fn surrogate(&mut self, m: &Lattice) -> Option<Evaluation> {
        if let Some(e) = self.surrogate_cache.get(m) {
            self.cache_hits += 1;
            return Some(*e);
        }
        let expected = match self.settings.cost {
            CostModel::Fixed(r) => r,
            CostModel::Measured => self.last_surrogate_cost,
        };
        // Keep one black-box evaluation's worth for the poll itself.
        if self.spent + expected + 1.0 > self.settings.budget {
            return None;
        }
        let x = self.unscale(m);
        let e = self.objective.surrogate(&x)?;
        let cost = match self.settings.cost {
            CostModel::Fixed(r) => r,
            CostModel::Measured => self.objective.measured_surrogate_cost().unwrap_or(0.0).max(0.0),
        };
        self.last_surrogate_cost = cost;
        self.spent += cost;
        self.surrogate_evaluations += 1;
        self.surrogate_cache.insert(m.clone(), e);
        Some(e)
    }

    fn classify(&self, e: &Evaluation) -> Verdict {
        if !e.is_valid() {
            return Verdict::Nothing;
        }
        if e.violation <= 0.0 {
            return match self.feasible {
                Some(i) if e.value >= self.archive[i].1.value => Verdict::Nothing,
                _ => Verdict::Dominating,
            };
        }
        if e.violation > self.h_max {
            return Verdict::Nothing;
        }
        match self.infeasible {
            None => Verdict::Improving,
            Some(i) => {
                let inc = self.archive[i].1;
                let dominates = e.value <= inc.value
                    && e.violation <= inc.violation
                    && (e.value < inc.value || e.violation < inc.violation);
                if dominates {
                    Verdict::Dominating
                } else if e.violation < inc.violation {
                    Verdict::Improving
                } else {
                    Verdict::Nothing
                }
            }
        }
    }

    /// Makes archive entry `i` an incumbent after a dominating verdict.
    fn accept(&mut self, i: usize) {
        let e = self.archive[i].1;
        if e.violation <= 0.0 {
            self.feasible = Some(i);
            self.history.push(HistoryPoint { spent: self.spent, best: e.value });
        } else {
            self.infeasible = Some(i);
        }
    }

    fn centre(&self) -> Option<usize> {
        self.feasible.or(self.infeasible)
    }

    fn run(mut self) -> Result<Outcome, OptimError> {
        let start = self.snap(&self.problem.start);
        let Some((i0, _)) = self.evaluate(&start) else {
            return Err(OptimError::BadBudget(self.settings.budget));
        };
        let e0 = self.archive[i0].1;
        if !e0.is_valid() || (self.settings.barrier == Barrier::Extreme && e0.violation > 0.0) {
            return Err(OptimError::StartFailed { value: e0.value, violation: e0.violation });
        }
        self.accept(i0);
        let stop = loop {
            if self.mesh_size() < tol::MIN_MESH_SIZE || self.level >= tol::STOP_MESH_INDEX {
                break StopReason::MeshConverged;
            }
            if self.spent + 1.0 > self.settings.budget {
                break StopReason::Budget;
            }
            self.iterations += 1;
            match self.iterate() {
                Some(v) => self.update(v),
                None => break StopReason::Budget,
            }
        };
        let best = self.centre().unwrap_or(i0);
        if let Some(i) = self.feasible {
            self.history.push(HistoryPoint { spent: self.spent, best: self.archive[i].1.value });
        }
        Ok(Outcome {
            best: self.unscale(&self.archive[best].0),
            best_eval: self.archive[best].1,
            start: self.unscale(&start),
            start_eval: e0,
            spent: self.spent,
            evaluations: self.evaluations,
            surrogate_evaluations: self.surrogate_evaluations,
            cache_hits: self.cache_hits,
            iterations: self.iterations,
            mesh_index: self.level,
            stop,
            history: self.history,
        })
    }

    /// Mesh and barrier update after an iteration (`improving`: the archive
    /// index of the best improving infeasible point, if any).
    fn update(&mut self, (verdict, improving): (Verdict, Option<usize>)) {
        match verdict {
            Verdict::Dominating => self.level = (self.level - 1).max(tol::MIN_MESH_INDEX),
            Verdict::Improving => {
                if let Some(old) = self.infeasible {
                    self.h_max = self.h_max.min(self.archive[old].1.violation);
                }
                self.infeasible = improving;
            }
            Verdict::Nothing => {
                self.level += 1;
                if let Some(old) = self.infeasible {
                    self.h_max = self.h_max.min(self.archive[old].1.violation);
                }
            }
        }
    }

    /// One search + poll iteration. `None` when the budget ran out before
    /// anything was learnt.
    fn iterate(&mut self) -> Option<(Verdict, Option<usize>)> {
        let centre = self.centre()?;
        let x = self.archive[centre].0.clone();
        let mut improving: Option<usize> = None;
        let note = |run: &Run<'_>, i: usize, improving: &mut Option<usize>| {
            let h = run.archive[i].1.violation;
            if improving.is_none_or(|j| h < run.archive[j].1.violation) {
                *improving = Some(i);
            }
        };
        if self.settings.model_search
            && let Some(candidate) = self.model_candidate(centre)
        {
            match self.evaluate(&candidate) {
                Some((i, false)) => match self.classify(&self.archive[i].1) {
                    Verdict::Dominating => {
                        self.accept(i);
                        return Some((Verdict::Dominating, None));
                    }
                    Verdict::Improving => note(self, i, &mut improving),
                    Verdict::Nothing => {}
                },
                Some((_, true)) => {}
                None => return None,
            }
        }
        let polls = self.poll_points(&x);
        let order = self.order(&polls);
        let mut any = false;
        for k in order {
            let (m, d) = &polls[k];
            let Some((i, cached)) = self.evaluate(m) else {
                break;
            };
            any = true;
            if cached {
                continue;
            }
            match self.classify(&self.archive[i].1) {
                Verdict::Dominating => {
                    self.accept(i);
                    self.last_success = Some(d.clone());
                    if self.settings.opportunistic {
                        return Some((Verdict::Dominating, None));
                    }
                }
                Verdict::Improving => note(self, i, &mut improving),
                Verdict::Nothing => {}
            }
        }
        if self.centre() != Some(centre) && self.feasible.is_some() {
            // A non-opportunistic poll moved the incumbent.
            return Some((Verdict::Dominating, None));
        }
        if !any && self.spent + 1.0 > self.settings.budget {
            return None;
        }
        Some((if improving.is_some() { Verdict::Improving } else { Verdict::Nothing }, improving))
    }

    /// The `2n` ORTHO poll points around `x` (lattice) with their directions,
    /// distinct and different from `x`.
    fn poll_points(&self, x: &Lattice) -> Vec<(Lattice, Vec<f64>)> {
        let n = self.n();
        let t = 1 + self.settings.seed.wrapping_mul(1_000_003).wrapping_add(self.iterations as u64);
        let q: Vec<f64> = (0..n).map(|j| 2.0 * radical_inverse(t, prime(j)) - 1.0).collect();
        let qq: f64 = q.iter().map(|v| v * v).sum();
        let (frame, mesh) = (self.frame_steps(), self.mesh_steps());
        #[allow(clippy::cast_precision_loss)] // powers of two below 2^31
        let ratio = frame as f64 / mesh as f64;
        let mut out: Vec<(Lattice, Vec<f64>)> = Vec::with_capacity(2 * n);
        for sign in [1.0, -1.0] {
            for j in 0..n {
                let d: Vec<f64> = (0..n)
                    .map(|i| {
                        let e = if i == j { 1.0 } else { 0.0 };
                        let h = if qq > 0.0 { e - 2.0 * q[i] * q[j] / qq } else { e };
                        sign * h
                    })
                    .collect();
                let inf = d.iter().fold(0.0f64, |a, v| a.max(v.abs()));
                if inf <= 0.0 {
                    continue;
                }
                #[allow(clippy::cast_possible_truncation)] // |ratio d / inf| <= 2^16
                let mut m: Lattice =
                    x.iter().zip(&d).map(|(&xi, &di)| xi + mesh * (ratio * di / inf).round() as i64).collect();
                self.project(&mut m);
                if m != *x && !out.iter().any(|(p, _)| *p == m) {
                    out.push((m, d));
                }
            }
        }
        out
    }

    /// Evaluation order of the poll points.
    fn order(&mut self, polls: &[(Lattice, Vec<f64>)]) -> Vec<usize> {
        let mut order: Vec<usize> = (0..polls.len()).collect();
        // Static surrogate: evaluate it on every point not yet in the cache.
        let mut keys: Vec<Option<(bool, f64)>> = vec![None; polls.len()];
        let mut have_surrogate = true;
        for (k, (m, _)) in polls.iter().enumerate() {
            if self.index.contains_key(m) {
                continue;
            }
            match self.surrogate(m) {
                Some(e) => {
                    keys[k] = Some((
                        e.violation > 0.0 || !e.is_valid(),
                        if e.value.is_nan() { f64::INFINITY } else { e.value },
                    ))
                }
                None => {
                    have_surrogate = false;
                    break;
                }
            }
        }
        if have_surrogate && keys.iter().any(Option::is_some) {
            order.sort_by(|&a, &b| match (keys[a], keys[b]) {
                (Some(ka), Some(kb)) => ka.0.cmp(&kb.0).then(ka.1.total_cmp(&kb.1)),
                (Some(_), None) => std::cmp::Ordering::Less,
                (None, Some(_)) => std::cmp::Ordering::Greater,
                (None, None) => a.cmp(&b),
            });
        } else if let Some(last) = &self.last_success {
            // The direction closest to the last success first, then index order.
            let cosine = |d: &[f64]| {
                let dot: f64 = d.iter().zip(last).map(|(a, b)| a * b).sum();
                let norm = d.iter().map(|a| a * a).sum::<f64>().sqrt() * last.iter().map(|a| a * a).sum::<f64>().sqrt();
                if norm > 0.0 { dot / norm } else { -1.0 }
            };
            if let Some(best) =
                (0..polls.len()).max_by(|&a, &b| cosine(&polls[a].1).total_cmp(&cosine(&polls[b].1)).then(b.cmp(&a)))
            {
                order.retain(|&k| k != best);
                order.insert(0, best);
            }
        }
        order
    }

    /// The quadratic-model search candidate around archive entry `centre`.
    fn model_candidate(&self, centre: usize) -> Option<Lattice> {
        let n = self.n();
        let x = &self.archive[centre].0;
        let frame = self.frame_steps();
        #[allow(clippy::cast_precision_loss)]
        let frame_f = frame as f64;
        let radius = tol::MODEL_RADIUS_FRAMES * frame_f;
        let diff = |m: &Lattice| -> Vec<f64> {
            m.iter()
                .zip(x)
                .zip(&self.problem.variables)
                .map(|((&a, &b), v)| {
                    let mut d = a - b;
                    if v.boundary != Boundary::Clip {
                        d = (d + tol::LATTICE / 2).rem_euclid(tol::LATTICE) - tol::LATTICE / 2;
                    }
                    #[allow(clippy::cast_precision_loss)]
                    let d = d as f64;
                    d
                })
                .collect()
        };
        let mut near: Vec<(f64, usize, Vec<f64>)> = self
            .archive
            .iter()
            .enumerate()
            .filter(|(_, (_, e))| e.is_valid() && e.violation <= 0.0)
            .filter_map(|(i, (m, _))| {
                let d = diff(m);
                let inf = d.iter().fold(0.0f64, |a, v| a.max(v.abs()));
                (inf <= radius).then(|| (inf, i, d.iter().map(|v| v / frame_f).collect()))
            })
            .collect();
        let coefficients = (n + 1) * (n + 2) / 2;
        if near.len() < n + 2 {
            return None;
        }
        near.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        near.truncate(tol::MODEL_POINTS_PER_COEFFICIENT * coefficients);
        let w = tol::MODEL_LINEAR_WEIGHT;
        let rows = near.len();
        let mut a = DMatrix::<f64>::zeros(rows, coefficients);
        let mut b = DVector::<f64>::zeros(rows);
        let f0 = self.archive[centre].1.value;
        for (r, (_, i, s)) in near.iter().enumerate() {
            b[r] = self.archive[*i].1.value - f0;
            a[(r, 0)] = 1.0 / w;
            for j in 0..n {
                a[(r, 1 + j)] = s[j] / w;
            }
            let mut c = 1 + n;
            for j in 0..n {
                for k in j..n {
                    // H_jj carries s_j^2 / 2; H_jk (j < k) appears twice in |H|_F^2.
                    a[(r, c)] = if j == k { 0.5 * s[j] * s[j] } else { s[j] * s[k] / std::f64::consts::SQRT_2 };
                    c += 1;
                }
            }
        }
        let svd = a.svd(true, true);
        let largest = svd.singular_values.iter().fold(0.0f64, |m, v| m.max(*v));
        let phi = svd.solve(&b, tol::MODEL_RANK_REL * largest).ok()?;
        let g: Vec<f64> = (0..n).map(|j| phi[1 + j] / w).collect();
        let mut h = DMatrix::<f64>::zeros(n, n);
        let mut c = 1 + n;
        for j in 0..n {
            for k in j..n {
                let v = if j == k { phi[c] } else { phi[c] / std::f64::consts::SQRT_2 };
                h[(j, k)] = v;
                h[(k, j)] = v;
                c += 1;
            }
        }
        if g.iter().chain(h.iter()).any(|v| !v.is_finite()) {
            return None;
        }
        // Minimise g.s + s^T H s / 2 over the frame box |s|_inf <= 1 (projected gradient).
        let lipschitz = h.norm();
        let mut s = DVector::<f64>::zeros(n);
        let gv = DVector::from_vec(g);
        if lipschitz <= f64::EPSILON {
            s = gv.map(|v| {
                if v > 0.0 {
                    -1.0
                } else if v < 0.0 {
                    1.0
                } else {
                    0.0
                }
            });
        } else {
            for _ in 0..tol::MODEL_DESCENT_STEPS {
                let grad = &gv + &h * &s;
                s = (&s - grad / lipschitz).map(|v| v.clamp(-1.0, 1.0));
            }
        }
        let mesh = self.mesh_steps();
        #[allow(clippy::cast_precision_loss, clippy::cast_possible_truncation)]
        let mut m: Lattice =
            x.iter().zip(s.iter()).map(|(&xi, &si)| xi + mesh * (si * frame_f / mesh as f64).round() as i64).collect();
        self.project(&mut m);
        (m != *x).then_some(m)
    }
}

/// The `j`-th prime (0-based).
fn prime(j: usize) -> u64 {
    let mut count = 0;
    let mut p = 1u64;
    while count <= j {
        p += 1;
        if (2..p).take_while(|d| d * d <= p).all(|d| !p.is_multiple_of(d)) {
            count += 1;
        }
    }
    p
}

/// Van der Corput radical inverse of `t` in `base`, in `[0, 1)`.
fn radical_inverse(mut t: u64, base: u64) -> f64 {
    #[allow(clippy::cast_precision_loss)]
    let inv = 1.0 / base as f64;
    let (mut value, mut scale) = (0.0, inv);
    while t > 0 {
        #[allow(clippy::cast_precision_loss)]
        let digit = (t % base) as f64;
        value += digit * scale;
        t /= base;
        scale *= inv;
    }
    value
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn primes_and_halton() {
        assert_eq!((0..6).map(prime).collect::<Vec<_>>(), vec![2, 3, 5, 7, 11, 13]);
        assert!((radical_inverse(1, 2) - 0.5).abs() < 1e-15);
        assert!((radical_inverse(6, 2) - 0.375).abs() < 1e-15);
        assert!((radical_inverse(5, 3) - (2.0 / 3.0 + 1.0 / 9.0)).abs() < 1e-15);
    }

    #[test]
    fn householder_directions_are_orthogonal() {
        struct Zero;
        impl Objective for Zero {
            fn evaluate(&mut self, _x: &[f64]) -> Evaluation {
                Evaluation::feasible(0.0)
            }
        }
        let problem = Problem {
            variables: (0..5).map(|i| crate::Variable::clip(format!("x{i}"), -1.0, 1.0)).collect(),
            start: vec![0.0; 5],
        };
        let mut zero = Zero;
        let mut run = Run::new(&problem, &mut zero, MadsSettings::default());
        run.level = 6;
        let x = run.snap(&problem.start);
        let polls = run.poll_points(&x);
        assert_eq!(polls.len(), 10);
        for a in 0..5 {
            for b in 0..5 {
                let dot: f64 = polls[a].1.iter().zip(&polls[b].1).map(|(p, q)| p * q).sum();
                assert!((dot - if a == b { 1.0 } else { 0.0 }).abs() < 1e-12);
            }
        }
        // Every poll point lies on the mesh centred on x.
        let mesh = run.mesh_steps();
        for (m, _) in &polls {
            assert!(m.iter().zip(&x).all(|(p, q)| (p - q) % mesh == 0));
        }
    }
}
