//! Criterion benchmarks of the drop-cutter kernel on generated meshes
//! (`dense_freeform`: a 45,000-triangle wavy terrain; `sphere`: a 20,000-triangle
//! UV sphere, the worst case of many small sloped facets), per cutter shape,
//! single-threaded. Run: `cargo bench -p scallop-cutter --bench drop`.

mod common;

use std::f64::consts::PI;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use scallop_cutter::{Cutter, CutterShape, drop_grid};
use scallop_geom::Point3;

fn bench(c: &mut Criterion) {
    let terrain = common::terrain();
    let sphere = common::grid_mesh(100, |u, v| {
        let (theta, phi) = (2.0 * PI * u, PI * (0.02 + 0.48 * v));
        Point3::new(40.0 * phi.sin() * theta.cos(), 40.0 * phi.sin() * theta.sin(), 40.0 * phi.cos())
    });
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("pool");
    let shapes = [
        ("ball", CutterShape::Ball { radius: 2.5 }),
        ("flat", CutterShape::Flat { radius: 2.5 }),
        ("bull", CutterShape::Bull { radius: 2.5, corner: 0.625 }),
        ("cone", CutterShape::Cone { radius: 2.5, half_angle: PI / 4.0 }),
    ];
    for (mesh_name, index, lo, hi) in [("dense_freeform", &terrain, 0.0, 100.0), ("sphere", &sphere, -40.0, 40.0)] {
        let xs: Vec<f64> = (0..100).map(|i| lo + (hi - lo) * f64::from(i) / 99.0).collect();
        let ys = xs.clone();
        let mut group = c.benchmark_group(format!("drop_grid_1thread/{mesh_name}"));
        group.throughput(Throughput::Elements((xs.len() * ys.len()) as u64));
        group.sample_size(10);
        for (name, shape) in shapes {
            let cutter = Cutter::new(shape, 20.0).expect("valid cutter");
            group.bench_function(name, |b| {
                b.iter(|| pool.install(|| drop_grid(&cutter, index, &xs, &ys, -100.0, &|_| {})))
            });
        }
        group.finish();
    }
}

/// The same kernel on 1 and 2 threads over a finer grid (250,000 points on the
/// terrain): the ratio of the two medians is the thread scaling.
fn scaling(c: &mut Criterion) {
    let terrain = common::terrain();
    let xs: Vec<f64> = (0..500).map(|i| 100.0 * f64::from(i) / 499.0).collect();
    let ys = xs.clone();
    let mut group = c.benchmark_group("drop_grid_threads/dense_freeform");
    group.throughput(Throughput::Elements((xs.len() * ys.len()) as u64));
    group.sample_size(10);
    for (name, shape) in [
        ("ball", CutterShape::Ball { radius: 2.5 }),
        ("flat", CutterShape::Flat { radius: 2.5 }),
        ("bull", CutterShape::Bull { radius: 2.5, corner: 0.625 }),
        ("cone", CutterShape::Cone { radius: 2.5, half_angle: PI / 4.0 }),
    ] {
        let cutter = Cutter::new(shape, 20.0).expect("valid cutter");
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
            group.bench_function(format!("{name}/{threads}"), |b| {
                b.iter(|| pool.install(|| drop_grid(&cutter, &terrain, &xs, &ys, -100.0, &|_| {})))
            });
        }
    }
    group.finish();
}

criterion_group!(benches, bench, scaling);
criterion_main!(benches);
