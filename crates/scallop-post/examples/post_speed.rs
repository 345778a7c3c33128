//! Times inverse kinematics and post of an N-pose 5-axis path once (profiling aid for
//! `benches/post.rs`): `cargo run --release -p scallop-post --example post_speed -- 100000`.

use scallop_geom::{Point3, Vec3};
use scallop_machine::program::{ClRecord, Motion, ProgramOptions, to_program};
use scallop_machine::{Kinematics, Machine, Pose};
use scallop_post::{Dialect, OutputMode, PostParams, program_text};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let n: usize = std::env::args().nth(1).map_or(Ok(100_000), |s| s.parse())?;
    let tilt = 30f64.to_radians();
    let mut records =
        vec![ClRecord { pose: Pose::new(Point3::new(0.0, 0.0, 80.0), Vec3::z()), motion: Motion::Rapid, feed: 2000.0 }];
    for i in 0..n {
        let t = i as f64 * 1e-3;
        let r = 10.0 + 20.0 * (t * 0.05).sin().abs();
        let phase = t * 3.0;
        let tip = Point3::new(r * phase.cos(), r * phase.sin(), 40.0 + 5.0 * (t * 0.1).sin());
        let precess = 1.2 * (t * 0.7).sin();
        let axis = Vec3::new(tilt.sin() * precess.cos(), tilt.sin() * precess.sin(), tilt.cos());
        records.push(ClRecord { pose: Pose::new(tip, axis), motion: Motion::Feed, feed: 2000.0 });
    }
    let kin = Kinematics::new(&Machine::builtin("linuxcnc-xyzac-trt")?, 0.0);
    let options = ProgramOptions::default();
    let t0 = std::time::Instant::now();
    let program = to_program(&kin, &records, None, &options)?;
    let t1 = t0.elapsed();
    let params = PostParams::new("1", OutputMode::Joint, 1, 0.0, 12000.0, &options);
    let text = program_text(&program, &kin, &Dialect::builtin("linuxcnc")?, &params)?;
    let t2 = t0.elapsed();
    let hash = text.bytes().fold(0xcbf2_9ce4_8422_2325_u64, |h, b| (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3));
    println!("output FNV-1a {hash:016x}");
    println!(
        "{n} poses, {} blocks, {} bytes: IK+plan {:.3} s, post {:.3} s",
        program.blocks.len(),
        text.len(),
        t1.as_secs_f64(),
        (t2 - t1).as_secs_f64()
    );
    Ok(())
}
