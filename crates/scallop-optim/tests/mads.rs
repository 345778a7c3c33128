//! The native OrthoMADS on analytic problems with known minima: smooth
//! (Rosenbrock), nonsmooth (an L1 valley), constrained (a disk), periodic
//! variables; and its bookkeeping (budget, cache, determinism, never worse than
//! the start).

#![allow(
    clippy::unwrap_used,
    clippy::float_cmp,
    reason = "tests: a panic is the failure report; exact zeros and counts"
)]

use std::collections::HashSet;
use std::f64::consts::{FRAC_PI_2, PI};

use proptest::prelude::*;
use scallop_optim::{
    Barrier, BlackBoxOptimizer, Boundary, CostModel, Evaluation, MadsSettings, Objective, OrthoMads, Outcome, Problem,
    StopReason, Variable,
};

/// A closure objective that records every point it is asked for.
struct Recorder<F: FnMut(&[f64]) -> Evaluation> {
    f: F,
    surrogate: Option<fn(&[f64]) -> Evaluation>,
    seen: Vec<Vec<f64>>,
    surrogate_calls: usize,
}

impl<F: FnMut(&[f64]) -> Evaluation> Recorder<F> {
    fn new(f: F) -> Self {
        Recorder { f, surrogate: None, seen: Vec::new(), surrogate_calls: 0 }
    }
}

impl<F: FnMut(&[f64]) -> Evaluation> Objective for Recorder<F> {
    fn evaluate(&mut self, x: &[f64]) -> Evaluation {
        self.seen.push(x.to_vec());
        (self.f)(x)
    }
    fn surrogate(&mut self, x: &[f64]) -> Option<Evaluation> {
        self.surrogate_calls += usize::from(self.surrogate.is_some());
        self.surrogate.map(|s| s(x))
    }
}

fn rosenbrock(x: &[f64]) -> f64 {
    x.windows(2).map(|w| 100.0 * (w[1] - w[0] * w[0]).powi(2) + (1.0 - w[0]).powi(2)).sum()
}

fn boxed(n: usize, lo: f64, hi: f64, start: &[f64]) -> Problem {
    Problem { variables: (0..n).map(|i| Variable::clip(format!("x{i}"), lo, hi)).collect(), start: start.to_vec() }
}

fn run(problem: &Problem, settings: MadsSettings, f: impl FnMut(&[f64]) -> Evaluation) -> Outcome {
    OrthoMads { settings }.minimize(problem, &mut Recorder::new(f)).unwrap()
}

#[test]
fn rosenbrock_2d_converges_with_and_without_model_search() {
    let problem = boxed(2, -2.0, 2.0, &[-1.2, 1.0]);
    for model_search in [false, true] {
        let settings = MadsSettings { budget: 2000.0, model_search, ..MadsSettings::default() };
        let out = run(&problem, settings, |x| Evaluation::feasible(rosenbrock(x)));
        assert!(out.best_eval.value < 1e-3, "model search {model_search}: {:?}", out.best_eval);
        assert!((out.best[0] - 1.0).abs() < 0.05 && (out.best[1] - 1.0).abs() < 0.1, "{:?}", out.best);
    }
}

#[test]
fn rosenbrock_4d_converges() {
    let problem = boxed(4, -2.0, 2.0, &[-1.2, 1.0, -1.2, 1.0]);
    let settings = MadsSettings { budget: 6000.0, model_search: true, ..MadsSettings::default() };
    let out = run(&problem, settings, |x| Evaluation::feasible(rosenbrock(x)));
    assert!(out.best_eval.value < 1e-2, "{:?}", out.best_eval);
    assert!(out.best_eval.value < 1e-3 * out.start_eval.value);
}

#[test]
fn nonsmooth_valley_converges() {
    // |x - 0.3| + |y + 0.7|: no gradient at the minimum, a kink along both lines.
    let problem = boxed(2, -3.0, 3.0, &[2.0, 1.5]);
    let out = run(&problem, MadsSettings { budget: 1500.0, ..MadsSettings::default() }, |x| {
        Evaluation::feasible((x[0] - 0.3).abs() + (x[1] + 0.7).abs())
    });
    // The run stops at Delta^m < 1e-9, where the frame is 0.1 * 2^-14 = 6e-6 of the range (6 here).
    assert!(out.best_eval.value < 5e-4, "{:?}", out.best_eval);
}

#[test]
fn disk_constraint_with_both_barriers() {
    // min (x - 2)^2 + (y - 2)^2  s.t.  x^2 + y^2 <= 1: optimum at (1, 1)/sqrt(2),
    // f* = 2 (2 - 1/sqrt(2))^2 (on the boundary).
    let f = |x: &[f64]| Evaluation {
        value: (x[0] - 2.0).powi(2) + (x[1] - 2.0).powi(2),
        violation: (x[0] * x[0] + x[1] * x[1] - 1.0).max(0.0),
    };
    let optimum = 2.0 * (2.0 - 0.5f64.sqrt()).powi(2);
    let cases =
        [(Barrier::Progressive, [-0.5, 0.0]), (Barrier::Extreme, [-0.5, 0.0]), (Barrier::Progressive, [-1.5, 1.8])];
    for (barrier, start) in cases {
        let problem = boxed(2, -2.0, 2.0, &start);
        let out = run(&problem, MadsSettings { budget: 2000.0, barrier, ..MadsSettings::default() }, f);
        assert_eq!(out.best_eval.violation, 0.0, "{barrier:?} from {start:?}");
        // At an active constraint the feasible descent cone narrows to nothing near the
        // optimum; with the 12.9 stop rule (Delta^m < 1e-9, at most 14 net refinements)
        // MADS ends within a few percent of it, far below the start value.
        assert!(out.best_eval.value < optimum * 1.03, "{barrier:?} from {start:?}: {:?}", out.best_eval);
        assert!(out.best_eval.value >= optimum - 1e-9);
    }
    // The extreme barrier refuses an infeasible start.
    let problem = boxed(2, -2.0, 2.0, &[1.5, 1.5]);
    let settings = MadsSettings { barrier: Barrier::Extreme, ..MadsSettings::default() };
    assert!(OrthoMads { settings }.minimize(&problem, &mut Recorder::new(f)).is_err());
}

#[test]
fn periodic_direction_wraps_through_pi() {
    // sin^2(theta - 0.05) on [0, pi): from 3.0 the way down goes through pi = 0.
    let problem = Problem { variables: vec![Variable::periodic("theta", 0.0, PI)], start: vec![3.0] };
    let out = run(&problem, MadsSettings { budget: 300.0, ..MadsSettings::default() }, |x| {
        Evaluation::feasible((x[0] - 0.05).sin().powi(2))
    });
    assert!(out.best_eval.value < 1e-10, "{:?}", out);
    assert!((out.best[0] - 0.05).abs() < 1e-4);
}

#[test]
fn tilt_and_azimuth_wrap_jointly() {
    // Distance between the tool axis a(phi, psi) and a target axis whose
    // azimuth is just below 0: reached by crossing psi = 0 with phi -> -phi.
    let axis = |phi: f64, psi: f64| [phi.sin() * psi.cos(), phi.sin() * psi.sin(), phi.cos()];
    let target = axis(0.6, -0.1);
    let problem = Problem {
        variables: vec![
            Variable::clip("phi", -FRAC_PI_2, FRAC_PI_2),
            Variable { name: "psi".into(), lower: 0.0, upper: PI, boundary: Boundary::Azimuth { tilt: 0 } },
        ],
        start: vec![0.5, 0.3],
    };
    let out = run(&problem, MadsSettings { budget: 600.0, ..MadsSettings::default() }, |x| {
        let a = axis(x[0], x[1]);
        Evaluation::feasible(a.iter().zip(&target).map(|(p, q)| (p - q).powi(2)).sum())
    });
    assert!(out.best_eval.value < 1e-8, "{out:?}");
    let a = axis(out.best[0], out.best[1]);
    assert!(a.iter().zip(&target).all(|(p, q)| (p - q).abs() < 1e-4));
}

#[test]
fn deterministic_for_a_seed_and_seeds_matter() {
    let problem = boxed(3, -2.0, 2.0, &[1.5, -1.0, 0.5]);
    let f = |x: &[f64]| Evaluation::feasible(rosenbrock(x) + (x[2] * 7.0).sin().abs());
    let settings = MadsSettings { budget: 400.0, model_search: true, ..MadsSettings::default() };
    let a = run(&problem, settings, f);
    let b = run(&problem, settings, f);
    assert_eq!(a, b);
    let c = run(&problem, MadsSettings { seed: 7, ..settings }, f);
    assert_ne!(a.history, c.history);
}

#[test]
fn cache_hits_are_free_and_every_black_box_point_is_new() {
    // A coarse problem converges to the finest mesh, revisiting points.
    let problem = boxed(2, -1.0, 1.0, &[0.5, 0.5]);
    let mut rec = Recorder::new(|x: &[f64]| Evaluation::feasible((x[0] - 0.25).abs() + x[1].powi(2)));
    let settings = MadsSettings { budget: 5000.0, model_search: true, ..MadsSettings::default() };
    let out = OrthoMads { settings }.minimize(&problem, &mut rec).unwrap();
    assert_eq!(rec.seen.len(), out.evaluations);
    #[allow(clippy::cast_precision_loss)]
    let evaluations = out.evaluations as f64;
    assert_eq!(out.spent, evaluations);
    let distinct: HashSet<Vec<u64>> = rec.seen.iter().map(|x| x.iter().map(|v| v.to_bits()).collect()).collect();
    assert_eq!(distinct.len(), rec.seen.len(), "a point was evaluated twice");
    assert!(out.cache_hits > 0, "the run never revisited a point: {out:?}");
    assert_eq!(out.stop, StopReason::MeshConverged);
}

#[test]
fn surrogate_cost_is_charged_and_ordering_helps() {
    let problem = boxed(4, -2.0, 2.0, &[-1.2, 1.0, -1.2, 1.0]);
    let f = |x: &[f64]| Evaluation::feasible(rosenbrock(x));
    let mut plain = Recorder::new(f);
    let settings = MadsSettings { budget: 800.0, cost: CostModel::Fixed(0.05), ..MadsSettings::default() };
    let without = OrthoMads { settings }.minimize(&problem, &mut plain).unwrap();
    let mut guided = Recorder::new(f);
    guided.surrogate = Some(|x: &[f64]| Evaluation::feasible(rosenbrock(x)));
    let with = OrthoMads { settings }.minimize(&problem, &mut guided).unwrap();
    assert_eq!(with.surrogate_evaluations, guided.surrogate_calls);
    #[allow(clippy::cast_precision_loss)]
    let charged = with.evaluations as f64 + 0.05 * with.surrogate_evaluations as f64;
    assert!((with.spent - charged).abs() < 1e-9 && with.spent <= 800.0);
    // A perfect surrogate puts the best poll point first: fewer black-box calls per iteration.
    #[allow(clippy::cast_precision_loss)]
    let per_iteration = |o: &Outcome| o.evaluations as f64 / o.iterations as f64;
    assert!(per_iteration(&with) < per_iteration(&without), "{} vs {}", per_iteration(&with), per_iteration(&without));
}

#[test]
fn bad_settings_are_errors() {
    let problem = boxed(2, -1.0, 1.0, &[0.0, 0.0]);
    let f = |_: &[f64]| Evaluation::feasible(0.0);
    for settings in [
        MadsSettings { budget: 0.0, ..MadsSettings::default() },
        MadsSettings { budget: f64::NAN, ..MadsSettings::default() },
        MadsSettings { cost: CostModel::Fixed(-1.0), ..MadsSettings::default() },
    ] {
        assert!(OrthoMads { settings }.minimize(&problem, &mut Recorder::new(f)).is_err());
    }
    let outside = boxed(2, -1.0, 1.0, &[0.0, 3.0]);
    let err = OrthoMads::default().minimize(&outside, &mut Recorder::new(f)).unwrap_err();
    assert!(err.to_string().contains("x1"), "{err}");
    let nan_start = |_: &[f64]| Evaluation::feasible(f64::NAN);
    assert!(OrthoMads::default().minimize(&problem, &mut Recorder::new(nan_start)).is_err());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn budget_is_never_exceeded_and_the_start_is_never_beaten_by_worse(
        budget in 1.0f64..150.0,
        ratio in 0.0f64..0.7,
        start in proptest::collection::vec(-2.0f64..2.0, 3),
        seed in 0u64..1000,
        model_search in any::<bool>(),
    ) {
        let problem = boxed(3, -2.0, 2.0, &start);
        let mut rec = Recorder::new(|x: &[f64]| Evaluation::feasible(rosenbrock(x) + x[2].abs()));
        rec.surrogate = Some(|x: &[f64]| Evaluation::feasible(x.iter().map(|v| (v - 1.0).powi(2)).sum()));
        let settings = MadsSettings { budget, seed, cost: CostModel::Fixed(ratio), model_search, ..MadsSettings::default() };
        let out = OrthoMads { settings }.minimize(&problem, &mut rec).unwrap();
        prop_assert!(out.spent <= budget + 1e-9, "spent {} of {}", out.spent, budget);
        prop_assert!(out.best_eval.value <= out.start_eval.value);
        prop_assert!(out.history.windows(2).all(|w| w[1].best <= w[0].best && w[1].spent >= w[0].spent));
        prop_assert!(out.best.iter().all(|v| (-2.0..=2.0).contains(v)));
    }
}
