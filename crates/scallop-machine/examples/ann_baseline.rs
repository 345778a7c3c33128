//! Trains the thesis's inverse-kinematics networks for the MX330 and prints their errors
//! next to Table V.3 and the exact inverse (kinematics.md 6, K17):
//! `cargo run --release -p scallop-machine --features ann-baseline --example ann_baseline -- [EPOCHS]`.

use scallop_machine::ann::{factorial_data, train_all};
use scallop_machine::{Kinematics, Machine};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let epochs: usize = std::env::args().nth(1).map_or(Ok(300), |s| s.parse())?;
    let kin = Kinematics::new(&Machine::builtin("mx330")?, 100.0);
    let data = factorial_data(&kin);
    let t0 = std::time::Instant::now();
    let results = train_all(&data, epochs, 2019);
    let train_s = t0.elapsed().as_secs_f64();
    println!(
        "| net | layers | MSE train | MSE test | MSE validation | thesis validation | RMSE test | max error test | best epoch |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for r in &results {
        let unit = if matches!(r.spec.joint, "A" | "C") { "deg" } else { "mm" };
        let inputs = if matches!(r.spec.joint, "A" | "C") { 2 } else { 5 };
        println!(
            "| {} | {}-{}-{}-1 | {:.2e} | {:.2e} | {:.2e} | {:.2e} | {:.3} {unit} | {:.3} {unit} | {} of {} |",
            r.spec.joint,
            inputs,
            r.spec.hidden[0],
            r.spec.hidden[1],
            r.mse[0],
            r.mse[1],
            r.mse[2],
            r.spec.thesis_validation_mse,
            r.rmse_test,
            r.max_error_test,
            r.epochs.1,
            r.epochs.0
        );
    }
    // Inference cost next to the exact inverse.
    let poses: Vec<_> = data.joints.iter().map(|q| kin.fk(q)).collect();
    let t0 = std::time::Instant::now();
    let mut sink = 0.0;
    for (k, p) in poses.iter().enumerate() {
        let sols = kin.ik(p, &data.joints[k])?;
        sink += sols.as_slice()[0].joints[0];
    }
    let ik_ns = t0.elapsed().as_secs_f64() * 1e9 / poses.len() as f64;
    let t0 = std::time::Instant::now();
    for k in 0..poses.len() {
        for (j, r) in results.iter().enumerate() {
            sink += r.net.predict(&data.inputs[j][k]);
        }
    }
    let ann_ns = t0.elapsed().as_secs_f64() * 1e9 / poses.len() as f64;
    println!(
        "\ntraining {train_s:.1} s ({epochs} epochs per net); per pose: five nets {ann_ns:.0} ns, exact inverse {ik_ns:.0} ns (checksum {sink:.3})"
    );
    Ok(())
}
