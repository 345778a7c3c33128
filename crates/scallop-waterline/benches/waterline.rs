//! Criterion bench of the waterline kernel on a generated `sphere_on_plate`
//! (a tessellated hemisphere of radius 20 mm on a 100 x 100 mm plate): the
//! drop-cutter grid, one level, and five levels sharing one grid.

use std::f64::consts::PI;
use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use scallop_cutter::{Cutter, CutterShape};
use scallop_geom::Point3;
use scallop_mesh::{MeshIndex, TriMesh};
use scallop_waterline::{WaterlineGrid, WaterlineOptions, waterline};

fn sphere_on_plate() -> TriMesh {
    let (radius, n_lon, n_lat) = (20.0, 96, 48);
    let mut soup = Vec::new();
    let p = |x: f64, y: f64, z: f64| Point3::new(x, y, z);
    soup.push([p(-50., -50., 0.), p(50., -50., 0.), p(50., 50., 0.)]);
    soup.push([p(-50., -50., 0.), p(50., 50., 0.), p(-50., 50., 0.)]);
    let at = |i: usize, j: usize| {
        let (lon, lat) = (2.0 * PI * i as f64 / n_lon as f64, 0.5 * PI * j as f64 / n_lat as f64);
        p(radius * lat.cos() * lon.cos(), radius * lat.cos() * lon.sin(), radius * lat.sin())
    };
    for i in 0..n_lon {
        for j in 0..n_lat {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            soup.push([a, b, c]);
            if j + 1 < n_lat {
                soup.push([a, c, d]);
            }
        }
    }
    TriMesh::from_soup(&soup).expect("valid mesh").0
}

fn bench(c: &mut Criterion) {
    let mesh = sphere_on_plate();
    let index = MeshIndex::build(&mesh);
    let ball = Cutter::new(CutterShape::Ball { radius: 3.0 }, 30.0).expect("valid cutter");
    let options = WaterlineOptions::default();
    let mut group = c.benchmark_group("waterline_sphere_on_plate");
    group.sample_size(10);
    group.bench_function("ball_r3_one_level", |b| {
        b.iter(|| waterline(&ball, &index, black_box(10.0), &options).expect("level"));
    });
    group.bench_function("ball_r3_grid_only", |b| {
        b.iter(|| WaterlineGrid::new(&ball, &index, &options).expect("grid"));
    });
    group.bench_function("ball_r3_five_levels_one_grid", |b| {
        b.iter(|| {
            let grid = WaterlineGrid::new(&ball, &index, &options).expect("grid");
            [2.0, 6.0, 10.0, 14.0, 18.0].map(|z| grid.loops(z).expect("level").len())
        });
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
