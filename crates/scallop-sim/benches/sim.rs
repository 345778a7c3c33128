//! Criterion benchmark of the stock simulation: a raster finishing path over a
//! 60 x 60 mm wavy part (`dense_freeform`, 28,800 triangles), ball R = 3 mm,
//! passes 0.5 mm apart, CL points every 0.2 mm from the exact drop-cutter
//! (36,600 moves), simulated and verified on a 0.05 mm z-map (1,440,000
//! cells), on 1 and 2 threads. Run: `cargo bench -p scallop-sim --bench sim`.

#[path = "../tests/common/mod.rs"]
mod common;

use criterion::{Criterion, criterion_group, criterion_main};
use scallop_cutter::{Cutter, CutterShape, drop_grid};
use scallop_geom::{Aabb3, Point3};
use scallop_mesh::{MeshIndex, TriMesh};
use scallop_sim::{VerifyOptions, simulate};
use scallop_toolpath::{Move, MoveKind, Toolpath};

const SIZE: f64 = 60.0;

fn surface(x: f64, y: f64) -> f64 {
    3.0 * (0.13 * x).sin() * (0.09 * y).cos() + 1.0 * (0.31 * x + 0.17 * y).sin()
}

fn part() -> MeshIndex {
    let soup = common::height_field(SIZE, 120, surface);
    MeshIndex::build(&TriMesh::from_soup(&soup).expect("generated mesh is valid").0)
}

fn raster(cutter: &Cutter, part: &MeshIndex) -> Toolpath {
    let xs: Vec<f64> = (0..=300).map(|i| SIZE * f64::from(i) / 300.0).collect();
    let ys: Vec<f64> = (0..=120).map(|j| SIZE * f64::from(j) / 120.0).collect();
    let cl = drop_grid(cutter, part, &xs, &ys, -10.0, &|_| {});
    let mut t = Toolpath::new(2000.0);
    for j in 0..ys.len() {
        let mut row: Vec<Point3> = cl[j * xs.len()..(j + 1) * xs.len()].iter().map(|c| c.tip).collect();
        if j % 2 == 1 {
            row.reverse();
        }
        t.push(Move::new(MoveKind::Rapid, Point3::new(row[0].x, row[0].y, 10.0)));
        t.push(Move::new(MoveKind::Plunge, row[0]));
        for q in &row[1..] {
            t.push(Move::new(MoveKind::Feed, *q));
        }
        let last = row[row.len() - 1];
        t.push(Move::new(MoveKind::Retract, Point3::new(last.x, last.y, 10.0)));
    }
    t
}

fn bench(c: &mut Criterion) {
    let part = part();
    let ball = Cutter::new(CutterShape::Ball { radius: 3.0 }, 20.0).expect("valid cutter");
    let path = raster(&ball, &part);
    let stock = Aabb3 { min: Point3::new(0.0, 0.0, -6.0), max: Point3::new(SIZE, SIZE, 5.0) };
    let options = VerifyOptions { gouge_tolerance: 0.01, ..VerifyOptions::default() };
    let mut group = c.benchmark_group("simulate_raster_60mm_0.05");
    group.sample_size(10);
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
        group.bench_function(format!("{threads}_thread"), |b| {
            b.iter(|| pool.install(|| simulate(stock, 0.05, &ball, &path, &part, &options).expect("no gouge")))
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
