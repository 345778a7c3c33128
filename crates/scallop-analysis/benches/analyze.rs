//! Criterion benchmark of the tool-choice pipeline on `dense_freeform`: the Choi
//! surface sampled on a 1000 x 1000 cell-centre grid, then PCA and the advisor
//! (`sample_patch` + `analyze`), single-threaded and on the default rayon pool.
//! Target: < 100 ms single-threaded. Run: `cargo bench -p scallop-analysis --bench analyze`.

use criterion::{Criterion, criterion_group, criterion_main};
use scallop_analysis::{GridOptions, MachineLimits, ToolOptions, analyze, sample_patch};

fn bench(c: &mut Criterion) {
    let set = scallop_surface::builtin("choi").expect("built-in surface");
    let patch = &set.patches()[0];
    let grid = GridOptions { cells_u: 1000, cells_v: 1000 };
    let (tools, machine) = (ToolOptions::default(), MachineLimits::default());
    let run = || {
        let samples = sample_patch(patch, &grid).expect("valid grid");
        analyze(&samples, &tools, &machine, 0.01).expect("Choi is not degenerate")
    };
    let mut group = c.benchmark_group("analyze_choi_1000x1000");
    group.sample_size(20);
    let single = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("pool");
    group.bench_function("single_thread", |b| b.iter(|| single.install(run)));
    group.bench_function("default_pool", |b| b.iter(run));
    let samples = sample_patch(patch, &grid).expect("valid grid");
    group.bench_function("analyze_only_single_thread", |b| {
        b.iter(|| single.install(|| analyze(&samples, &tools, &machine, 0.01).expect("valid")))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
