//! Criterion benchmark of one black-box evaluation of the zone study on the
//! Choi surface (spec defaults: 80 x 80 clustering, 0.5 mm machining mesh,
//! bull-nose R 5 r 2, sh 0.01 mm), split into its two stages, and of the
//! surrogates S3 and S4, single-threaded. Target (issue 8): one black-box
//! evaluation at 80 x 80 under 5 ms single-threaded.
//! Run: `cargo bench -p scallop-optim --bench study`.

use criterion::{Criterion, criterion_group, criterion_main};
use scallop_optim::study::{Fidelity, Formulation, MachiningModel};
use scallop_optim::surface::{SurfaceModel, SurfaceSettings};

fn bench(c: &mut Criterion) {
    let set = scallop_surface::builtin("choi").expect("built-in surface");
    let model = SurfaceModel::new(&set.patches()[0], SurfaceSettings::default()).expect("valid settings");
    let single = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("pool");
    let mut group = c.benchmark_group("black_box_choi_80x80_0.5mm");
    group.sample_size(20);
    for k in [2, 5, 10] {
        let omega = [0.9, 0.8, 1.0, 0.7];
        let p = model.partition(k, &omega, Fidelity::BlackBox).expect("clusters");
        let d = model.initial_design(k, Formulation::ThreeAxis, &p).expect("start");
        group.bench_function(format!("k{k}_cluster"), |b| {
            b.iter(|| single.install(|| model.partition(k, &omega, Fidelity::BlackBox).expect("clusters")))
        });
        group.bench_function(format!("k{k}_plan_3axis"), |b| {
            b.iter(|| {
                single.install(|| model.assess(&p, Formulation::ThreeAxis, &d, Fidelity::BlackBox).expect("plan"))
            })
        });
        group.bench_function(format!("k{k}_plan_3plus2"), |b| {
            b.iter(|| {
                single.install(|| model.assess(&p, Formulation::ThreePlusTwo, &d, Fidelity::BlackBox).expect("plan"))
            })
        });
        let p3 = model.partition(k, &omega, Fidelity::S3).expect("clusters");
        group.bench_function(format!("k{k}_s3_with_clustering"), |b| {
            b.iter(|| {
                single.install(|| {
                    let p3 = model.partition(k, &omega, Fidelity::S3).expect("clusters");
                    model.assess(&p3, Formulation::ThreeAxis, &d, Fidelity::S3).expect("s3")
                })
            })
        });
        group.bench_function(format!("k{k}_s3_assess"), |b| {
            b.iter(|| single.install(|| model.assess(&p3, Formulation::ThreeAxis, &d, Fidelity::S3).expect("s3")))
        });
        let p4 = model.partition(k, &omega, Fidelity::S4).expect("clusters");
        group.bench_function(format!("k{k}_s4_assess"), |b| {
            b.iter(|| single.install(|| model.assess(&p4, Formulation::ThreeAxis, &d, Fidelity::S4).expect("s4")))
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
