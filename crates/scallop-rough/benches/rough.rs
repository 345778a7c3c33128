//! Criterion bench of roughing planning on a generated terrain (a 90 x 50 mm
//! height field of 120 x 60 cells, hills up to 20 mm on a base, the size of
//! OpenCAMLib's `mount_rush` test part): a 6 mm flat end mill, 2 mm stepdown,
//! 20 % stepover, a stock 5 mm around. The figure with the real part is in
//! docs/benchmarks.md (`scallop run` on a job file).
//!
//! And the adaptive planner alone on a pocket of bench/freecad (the 100 x 60
//! mm rectangle with a round island of 24 mm, as `scallop pocket` gets it:
//! the tool-centre region of a 6 mm tool, 20 % stepover, chord tolerance
//! 0.001 mm); its figures beside FreeCAD's are in docs/benchmarks.md.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use scallop_contour::{Contour, Region};
use scallop_cutter::{Cutter, CutterShape};
use scallop_geom::{Aabb3, Point3};
use scallop_mesh::{MeshIndex, TriMesh};
use scallop_rough::{ClearOptions, Direction, Motion, Pattern, RoughSettings, plan_adaptive, plan_rough};

fn terrain() -> TriMesh {
    let (nx, ny, w, d) = (120, 60, 90.0, 50.0);
    let height = |i: usize, j: usize| {
        let (x, y) = (i as f64 / nx as f64, j as f64 / ny as f64);
        let hill = (std::f64::consts::PI * x).sin() * (std::f64::consts::PI * y).sin();
        5.0 + 15.0 * hill * (1.0 + 0.3 * (9.0 * x).sin() * (7.0 * y).cos())
    };
    let at = |i: usize, j: usize| Point3::new(w * i as f64 / nx as f64, d * j as f64 / ny as f64, height(i, j));
    let mut soup = Vec::with_capacity(2 * nx * ny);
    for i in 0..nx {
        for j in 0..ny {
            soup.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            soup.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    TriMesh::from_soup(&soup).expect("valid mesh").0
}

fn bench(c: &mut Criterion) {
    let mesh = terrain();
    let index = MeshIndex::build(&mesh);
    let b = index.bounds();
    let stock = Aabb3 {
        min: Point3::new(b.min.x - 5.0, b.min.y - 5.0, b.min.z),
        max: Point3::new(b.max.x + 5.0, b.max.y + 5.0, b.max.z + 5.0),
    };
    let cutter = Cutter::new(CutterShape::Flat { radius: 3.0 }, 40.0).expect("valid cutter");
    let settings = RoughSettings {
        stepdown: 2.0,
        stepover: 0.2,
        radial_allowance: 0.3,
        axial_allowance: 0.3,
        pattern: Pattern::Offset,
        direction: Direction::Climb,
    };
    let motion = Motion { clearance_z: b.max.z + 10.0, feed: 5000.0 };
    let mut group = c.benchmark_group("rough_terrain");
    group.sample_size(10);
    group.bench_function("flat_d6_stepdown2_stepover20", |bench| {
        bench.iter(|| plan_rough(&index, &cutter, black_box(&stock), &settings, &motion, 0.01).expect("plan"));
    });
    group.finish();
}

/// bench/freecad/pockets.py's `rectangle_island` as the tool-centre region of a 6 mm tool.
fn rectangle_island() -> Region {
    let outer = Contour::polygon(&[[0.0, 0.0], [100.0, 0.0], [100.0, 60.0], [0.0, 60.0]], true).expect("outer");
    let island: Vec<[f64; 2]> = (0..128)
        .rev()
        .map(|k| {
            let a = std::f64::consts::TAU * f64::from(k) / 128.0;
            [50.0 + 12.0 * a.cos(), 30.0 + 12.0 * a.sin()]
        })
        .collect();
    let hole = Contour::polygon(&island, true).expect("island");
    Region::with_holes(outer, vec![hole]).expect("pocket").offset(3.0)
}

fn adaptive(c: &mut Criterion) {
    let region = rectangle_island();
    let options = ClearOptions {
        tool_radius: 3.0,
        stepover: 1.2,
        direction: Direction::Climb,
        chord_tolerance: 1e-3,
        pattern: Pattern::Adaptive,
    };
    let mut group = c.benchmark_group("adaptive_pocket");
    group.sample_size(10);
    group.bench_function("rectangle_island_d6_stepover20", |bench| {
        bench.iter(|| plan_adaptive(black_box(&region), &options).expect("plan"));
    });
    group.finish();
}

criterion_group!(benches, bench, adaptive);
criterion_main!(benches);
