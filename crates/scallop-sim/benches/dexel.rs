//! Criterion benchmark of the tri-dexel stock: a 3+2 finishing-like raster
//! of a ball R 3 mm tilted 20 degrees (fixed axis) over a 50 x 50 mm wavy
//! part, passes 1 mm apart, cutter locations every 1 mm along them from the
//! exact offset of the analytic surface (2,703 moves), cut and verified on a
//! 0.2 mm tri-dexel stock (250 x 250 Z rays, 250 x 33 X and Y rays), on 1 and
//! 2 threads. Run: `cargo bench -p scallop-sim --bench dexel`.
//!
//! With `SCALLOP_BENCH_ONCE=1` the binary runs the workload once on one
//! thread and exits, for instruction counts:
//! `SCALLOP_BENCH_ONCE=1 valgrind --tool=callgrind target/release/deps/dexel-*`.

#[path = "../tests/common/mod.rs"]
mod common;

use criterion::{Criterion, criterion_group};
use scallop_cutter::{Cutter, CutterShape};
use scallop_geom::{Aabb3, Point3, Vec3};
use scallop_mesh::TriMesh;
use scallop_sim::{DexelOptions, DexelPart, ToolMove, VerifyOptions, simulate_dexel};
use scallop_toolpath::MoveKind;

const SIZE: f64 = 50.0;
const R: f64 = 3.0;

fn surface(x: f64, y: f64) -> (f64, Vec3) {
    let f = 1.5 * (0.13 * x).sin() * (0.09 * y).cos() + 0.5 * (0.31 * x + 0.17 * y).sin();
    let fx = 1.5 * 0.13 * (0.13 * x).cos() * (0.09 * y).cos() + 0.5 * 0.31 * (0.31 * x + 0.17 * y).cos();
    let fy = -1.5 * 0.09 * (0.13 * x).sin() * (0.09 * y).sin() + 0.5 * 0.17 * (0.31 * x + 0.17 * y).cos();
    (f, Vec3::new(-fx, -fy, 1.0).normalize())
}

fn part() -> DexelPart {
    let soup = common::height_field(SIZE, 100, |x, y| surface(x, y).0);
    DexelPart::new(&TriMesh::from_soup(&soup).expect("generated mesh is valid").0)
}

/// Ball centres on the surface's offset at contact points on a 1 mm grid.
fn raster() -> Vec<ToolMove> {
    let tilt = 20f64.to_radians();
    let a = Vec3::new(0.0, tilt.sin(), tilt.cos());
    let tip = |x: f64, y: f64| {
        let (z, n) = surface(x, y);
        Point3::new(x, y, z) + R * n - R * a
    };
    let mut moves = Vec::new();
    for j in 0..=50 {
        let y = f64::from(j);
        let xs: Vec<f64> =
            if j % 2 == 0 { (0..=50).map(f64::from).collect() } else { (0..=50).rev().map(f64::from).collect() };
        let first = tip(xs[0], y);
        moves.push(ToolMove::new(MoveKind::Rapid, Point3::new(first.x, first.y, 12.0), a));
        for (k, &x) in xs.iter().enumerate() {
            let kind = if k == 0 { MoveKind::Plunge } else { MoveKind::Feed };
            moves.push(ToolMove::new(kind, tip(x, y), a));
        }
        let last = tip(xs[50], y);
        moves.push(ToolMove::new(MoveKind::Retract, Point3::new(last.x, last.y, 12.0), a));
    }
    moves
}

fn run(cutter: &Cutter, moves: &[ToolMove], part: &DexelPart) {
    let stock = Aabb3 { min: Point3::new(0.0, 0.0, -4.0), max: Point3::new(SIZE, SIZE, 2.6) };
    let options = VerifyOptions { gouge_tolerance: 0.01, ..VerifyOptions::default() };
    let sim = simulate_dexel(stock, 0.2, cutter, moves, part, &DexelOptions::default(), &options).expect("no gouge");
    assert!(sim.verification.max_scallop < 0.2);
}

fn bench(c: &mut Criterion) {
    let part = part();
    let ball = Cutter::new(CutterShape::Ball { radius: R }, 10.0).expect("valid cutter");
    let moves = raster();
    let mut group = c.benchmark_group("dexel_3+2_raster_50mm_0.2");
    group.sample_size(10);
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
        group.bench_function(format!("{threads}_thread"), |b| b.iter(|| pool.install(|| run(&ball, &moves, &part))));
    }
    group.finish();
}

criterion_group!(benches, bench);

fn main() {
    if std::env::var_os("SCALLOP_BENCH_ONCE").is_some() {
        let ball = Cutter::new(CutterShape::Ball { radius: R }, 10.0).expect("valid cutter");
        let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("pool");
        let (part, moves) = (part(), raster());
        pool.install(|| run(&ball, &moves, &part));
        return;
    }
    benches();
    Criterion::default().configure_from_args().final_summary();
}
