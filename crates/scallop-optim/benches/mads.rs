//! Criterion benchmark of the optimiser's own overhead: OrthoMADS with 1000
//! black-box evaluations of a function that costs nothing (the 14 variables of
//! a 3-axis study at K = 10, and the 34 of a 3+2 study at K = 10), with and
//! without the quadratic-model search, and with a free S3-like surrogate.
//! What it measures is what the optimiser adds to 1000 real evaluations.
//! Run: `cargo bench -p scallop-optim --bench mads`.

use criterion::{Criterion, criterion_group, criterion_main};
use scallop_optim::{BlackBoxOptimizer, CostModel, Evaluation, MadsSettings, Objective, OrthoMads, Problem, Variable};

struct Free {
    surrogate: bool,
}

impl Objective for Free {
    fn evaluate(&mut self, x: &[f64]) -> Evaluation {
        Evaluation::feasible(x.iter().enumerate().map(|(i, v)| (v - 0.1 * i as f64).sin().powi(2)).sum())
    }
    fn surrogate(&mut self, x: &[f64]) -> Option<Evaluation> {
        self.surrogate.then(|| Evaluation::feasible(x.iter().map(|v| v * v).sum()))
    }
}

fn problem(n: usize) -> Problem {
    Problem {
        variables: (0..n).map(|i| Variable::periodic(format!("theta_{i}"), 0.0, std::f64::consts::PI)).collect(),
        start: vec![1.0; n],
    }
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("orthomads_overhead_1000_evaluations");
    group.sample_size(20);
    for (name, n, model_search, surrogate) in [
        ("n14_poll_only", 14, false, false),
        ("n14_model_search", 14, true, false),
        ("n14_surrogate_ordering", 14, false, true),
        ("n34_poll_only", 34, false, false),
    ] {
        let p = problem(n);
        let settings =
            MadsSettings { budget: 1000.0, model_search, cost: CostModel::Fixed(0.0), ..MadsSettings::default() };
        group.bench_function(name, |b| {
            b.iter(|| OrthoMads { settings }.minimize(&p, &mut Free { surrogate }).expect("valid problem"))
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
