//! Criterion benchmark of the stock simulation of the Choi finishing program
//! (`FinishJob::choi_demo`: bull-nose R 5 r 2, sh 0.01 mm): the program is
//! planned once, then simulated and verified (cut, shank and holder against
//! the stock and the part, scallop beyond R from the edge) on a 0.05 mm z-map,
//! on 1 and 2 threads. Run: `cargo bench -p scallop-engine --bench choi_sim`.

use criterion::{Criterion, criterion_group, criterion_main};
use scallop_engine::{FinishJob, prepare_part, run_finishing};
use scallop_geom::{Aabb3, Point3};
use scallop_sim::{VerifyOptions, simulate};

fn bench(c: &mut Criterion) {
    let job = FinishJob::choi_demo();
    let path = run_finishing(&job).expect("the demo plans").toolpath;
    let prepared = prepare_part(&job.part, &job.tolerances).expect("the demo part");
    let b = prepared.mesh.bounds();
    let r = job.cutter.radius();
    let stock = Aabb3 {
        min: Point3::new(b.min.x - r, b.min.y - r, b.min.z - 1.0),
        max: Point3::new(b.max.x + r, b.max.y + r, b.max.z + 1.0),
    };
    let options = VerifyOptions {
        gouge_tolerance: job.tolerances.gouge + prepared.chordal_error + job.tolerances.path,
        scallop_margin: r,
        ..VerifyOptions::default()
    };
    let mut group = c.benchmark_group("simulate_choi_0.05");
    group.sample_size(10);
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
        group.bench_function(format!("{threads}_thread"), |bench| {
            bench.iter(|| {
                pool.install(|| simulate(stock, 0.05, &job.cutter, &path, &prepared.index, &options).expect("no gouge"))
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
