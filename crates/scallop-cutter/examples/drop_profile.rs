//! Runs the drop-cutter on a generated terrain for profiling, e.g. under
//! `valgrind --tool=callgrind` (instruction counts do not depend on machine load):
//! `cargo build --release --example drop_profile -p scallop-cutter` then
//! `valgrind --tool=callgrind target/release/examples/drop_profile bull`.

#[path = "../benches/common/mod.rs"]
mod common;

use scallop_cutter::{Cutter, CutterShape, drop_grid};

fn main() {
    let shape = match std::env::args().nth(1).as_deref() {
        Some("flat") => CutterShape::Flat { radius: 2.5 },
        Some("bull") => CutterShape::Bull { radius: 2.5, corner: 0.625 },
        Some("cone") => CutterShape::Cone { radius: 2.5, half_angle: std::f64::consts::FRAC_PI_4 },
        _ => CutterShape::Ball { radius: 2.5 },
    };
    let index = common::terrain();
    let cutter = Cutter::new(shape, 20.0).expect("valid cutter");
    let xs: Vec<f64> = (0..200).map(|i| f64::from(i) * 0.5).collect();
    let ys: Vec<f64> = (0..50).map(|i| 10.0 + f64::from(i) * 0.5).collect();
    let start = std::time::Instant::now();
    let cl = drop_grid(&cutter, &index, &xs, &ys, -100.0, &|_| {});
    let dt = start.elapsed().as_secs_f64();
    let sum: f64 = cl.iter().map(|c| c.tip.z).sum();
    println!("{} points in {dt:.3} s ({:.0} pts/s), checksum {sum:.6}", cl.len(), cl.len() as f64 / dt);
}
