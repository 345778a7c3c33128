//! Runs the drop-cutter on a generated terrain for profiling, e.g. under
//! `valgrind --tool=callgrind` (instruction counts do not depend on machine load):
//! `cargo build --release --example drop_profile -p scallop-cutter` then
//! `valgrind --tool=callgrind target/release/examples/drop_profile bull`.

use scallop_cutter::{Cutter, CutterShape, drop_grid};
use scallop_geom::Point3;
use scallop_mesh::{MeshIndex, TriMesh};

fn main() {
    let shape = match std::env::args().nth(1).as_deref() {
        Some("flat") => CutterShape::Flat { radius: 2.5 },
        Some("bull") => CutterShape::Bull { radius: 2.5, corner: 0.625 },
        Some("cone") => CutterShape::Cone { radius: 2.5, half_angle: std::f64::consts::FRAC_PI_4 },
        _ => CutterShape::Ball { radius: 2.5 },
    };
    let n = 150u32;
    let f = |u: f64, v: f64| {
        let (x, y) = (100.0 * u, 100.0 * v);
        Point3::new(x, y, 5.0 * (x * 0.13).sin() * (y * 0.09).cos() + 2.0 * (0.31 * x + 0.17 * y).sin())
    };
    let s = |i: u32| f64::from(i) / f64::from(n);
    let mut soup = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let (a, b, c, d) = (f(s(i), s(j)), f(s(i + 1), s(j)), f(s(i), s(j + 1)), f(s(i + 1), s(j + 1)));
            soup.push([a, b, c]);
            soup.push([b, d, c]);
        }
    }
    let (mesh, _) = TriMesh::from_soup(&soup).expect("valid mesh");
    let index = MeshIndex::build(&mesh);
    let cutter = Cutter::new(shape, 20.0).expect("valid cutter");
    let xs: Vec<f64> = (0..200).map(|i| f64::from(i) * 0.5).collect();
    let ys: Vec<f64> = (0..50).map(|i| 10.0 + f64::from(i) * 0.5).collect();
    let start = std::time::Instant::now();
    let cl = drop_grid(&cutter, &index, &xs, &ys, -100.0, &|_| {});
    let dt = start.elapsed().as_secs_f64();
    let sum: f64 = cl.iter().map(|c| c.tip.z).sum();
    println!("{} points in {dt:.3} s ({:.0} pts/s), checksum {sum:.6}", cl.len(), cl.len() as f64 / dt);
}
