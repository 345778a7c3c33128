//! One black-box evaluation of the 3-axis zone study (clustering, zones, plans,
//! time) on a built-in surface, repeated N times, for instruction counts:
//!
//! ```text
//! cargo build --release -p scallop-optim --example evaluation
//! valgrind --tool=callgrind --toggle-collect='evaluation::evaluate' \
//!     target/release/examples/evaluation choi 10 20
//! ```
//!
//! Arguments: surface (`choi`, `rubio`), K, repetitions. Prints the time of the
//! last evaluation's plan, so the work cannot be optimised away, and an FNV-1a
//! digest of the bits of every evaluation's `time_s` and of its partition's
//! cluster and zone labels: a speed change must leave the digest unchanged.
//! The mean wall time of one evaluation, and of its partition (clustering and
//! zones) alone, goes to stderr (the model's set-up is not counted).

use scallop_optim::study::{Fidelity, Formulation, MachiningModel};
use scallop_optim::surface::{SurfaceModel, SurfaceSettings, ZonePartition};

#[inline(never)]
fn evaluate(
    model: &SurfaceModel,
    k: usize,
    omega: &[f64; 4],
    directions_from: &scallop_optim::study::Design,
) -> (f64, ZonePartition) {
    let c0 = std::time::Instant::now();
    let p = model.partition(k, omega, Fidelity::BlackBox).expect("clusters");
    PART.with(|c| c.set(c.get() + c0.elapsed().as_secs_f64()));
    let d = directions_from;
    let time = model.assess(&p, Formulation::ThreeAxis, d, Fidelity::BlackBox).expect("plan").time_s;
    (time, p)
}

// Wall time spent in the partitions (s).
thread_local! { static PART: std::cell::Cell<f64> = const { std::cell::Cell::new(0.0) }; }
/// FNV-1a, 64 bits.
struct Fnv(u64);

impl Fnv {
    fn bytes(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
}

fn main() {
    let mut args = std::env::args().skip(1);
    let surface = args.next().unwrap_or_else(|| "choi".into());
    let k: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(10);
    let n: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(10);
    let set = scallop_surface::builtin(&surface).expect("choi or rubio");
    let model = SurfaceModel::new(&set.patches()[0], SurfaceSettings::default()).expect("valid settings");
    let omega = [0.9, 0.8, 1.0, 0.7];
    let p = model.partition(k, &omega, Fidelity::BlackBox).expect("clusters");
    let start = model.initial_design(k, Formulation::ThreeAxis, &p).expect("start");
    let mut time = 0.0;
    let mut digest = Fnv(0xcbf2_9ce4_8422_2325);
    let mut busy = std::time::Duration::ZERO;
    for i in 0..n {
        // Slightly different weights each time: the optimiser's polls move omega.
        let w = 0.01 * (i % 7) as f64;
        let clock = std::time::Instant::now();
        let (t, p) = evaluate(&model, k, &[omega[0] - w, omega[1], omega[2] - w, omega[3]], &start);
        busy += clock.elapsed();
        time = t;
        digest.bytes(&t.to_bits().to_le_bytes());
        let c = p.clustering();
        for labels in [&c.cluster_of_cell, &c.zone_of_cell] {
            for l in labels.iter() {
                digest.bytes(&l.to_le_bytes());
            }
        }
    }
    let per = 1e3 * busy.as_secs_f64() / n.max(1) as f64;
    println!("{surface} K = {k}: {n} evaluations, last plan {time:.3} s, digest {:016x}", digest.0);
    eprintln!("partition {:.3} ms", PART.with(|c| c.get()) * 1e3 / n as f64);
    eprintln!("{per:.3} ms per evaluation (wall clock, mean)");
}
