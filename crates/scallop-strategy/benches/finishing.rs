//! Criterion benchmark: finishing of the Choi surface at the specification's
//! settings (finishing.md 13, issue 3): bull-nose R = 5, r = 2 mm, sh = 0.01 mm,
//! V = 5 m/min, A = 6 m/s^2, J = 40 m/s^3, parallel planes along the steepest-slope
//! direction of the surface's PCA plane, path tolerance 0.01 mm, 0.5 mm
//! forward step. Single-threaded. Run: `cargo bench -p scallop-strategy --bench finishing`.

use criterion::{Criterion, criterion_group, criterion_main};
use scallop_analysis::{GridOptions, MachineLimits, ToolOptions, analyze, sample_patch};
use scallop_cutter::{Cutter, CutterShape};
use scallop_geom::Tolerances;
use scallop_mesh::MeshIndex;
use scallop_strategy::{Boundary, FinishingParams, Pattern, plan_finishing};

fn bench(c: &mut Criterion) {
    let set = scallop_surface::builtin("choi").expect("built-in surface");
    let tol = Tolerances { path: 0.01, gouge: 0.0 };
    let mesh = set.tessellate(tol.tessellation()).expect("tessellation").mesh;
    let index = MeshIndex::build(&mesh);
    let samples = sample_patch(&set.patches()[0], &GridOptions::default()).expect("samples");
    let machine = MachineLimits::from_thesis_units(5.0, 6.0, 40.0);
    let analysis = analyze(&samples, &ToolOptions::default(), &machine, 0.01).expect("analysis");
    let cutter = Cutter::new(CutterShape::Bull { radius: 5.0, corner: 2.0 }, 30.0).expect("cutter");
    let params = FinishingParams {
        direction: analysis.slope_direction_deg.to_radians(),
        pattern: Pattern::Zigzag,
        scallop_height: 0.01,
        boundary: Boundary::ContactInside,
        max_step: 0.5,
        clearance: 5.0,
        machine,
        plunge_feed: machine.feed / 2.0,
        rapid_rate: 10_000.0 / 60.0 * 6.0,
        sharp_corner: 30f64.to_radians(),
        blend_tolerance: 0.01,
    };
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("pool");
    let mut group = c.benchmark_group("finishing");
    group.sample_size(10);
    group.bench_function("choi_bull_5_2_sh_0.01", |b| {
        b.iter(|| pool.install(|| plan_finishing(&index, &cutter, &params, &tol).expect("plan")));
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
