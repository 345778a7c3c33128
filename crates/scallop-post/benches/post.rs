//! Inverse kinematics plus post-processing of a 10^6-pose simultaneous 5-axis path
//! (issue 5's speed criterion: under 1 s single-threaded). The path is a helical sweep
//! with the tool axis tilted 30 degrees and swinging +-69 degrees around the vertical, on
//! the LinuxCNC `xyzac-trt` machine in joint-space output with inverse-time feeds.
//!
//! `cargo bench -p scallop-post --bench post`

use criterion::{Criterion, criterion_group, criterion_main};
use scallop_geom::{Point3, Vec3};
use scallop_machine::program::{ClRecord, Motion, ProgramOptions, to_program};
use scallop_machine::{Kinematics, Machine, Pose};
use scallop_post::{Dialect, OutputMode, PostParams, program_text};

/// `n` poses: a spiral over a 60 mm disc with a slowly precessing 30 degree tilt.
fn poses(n: usize) -> Vec<ClRecord> {
    let tilt = 30f64.to_radians();
    let mut out = Vec::with_capacity(n + 1);
    let start = Pose::new(Point3::new(0.0, 0.0, 80.0), Vec3::z());
    out.push(ClRecord { pose: start, motion: Motion::Rapid, feed: 2000.0 });
    for i in 0..n {
        let t = i as f64 * 1e-3;
        let r = 10.0 + 20.0 * (t * 0.05).sin().abs();
        let phase = t * 3.0;
        let tip = Point3::new(r * phase.cos(), r * phase.sin(), 40.0 + 5.0 * (t * 0.1).sin());
        let precess = 1.2 * (t * 0.7).sin(); // swings +-69 deg: no winding past the C stroke
        let axis = Vec3::new(tilt.sin() * precess.cos(), tilt.sin() * precess.sin(), tilt.cos());
        out.push(ClRecord { pose: Pose::new(tip, axis), motion: Motion::Feed, feed: 2000.0 });
    }
    out
}

fn bench(c: &mut Criterion) {
    let machine = Machine::builtin("linuxcnc-xyzac-trt").expect("shipped machine");
    let kin = Kinematics::new(&machine, 0.0);
    let dialect = Dialect::builtin("linuxcnc").expect("shipped dialect");
    let records = poses(1_000_000);
    let options = ProgramOptions::default();
    let params = PostParams {
        program: "1".into(),
        mode: OutputMode::Joint,
        tool: 1,
        tool_length: 0.0,
        spindle: 12000.0,
        tol_pos: options.tol_pos,
        tol_ang: options.tol_ang,
        predicted_time: None,
    };
    let one = rapid_free_check(&kin, &records, &options);
    let mut group = c.benchmark_group("post_1e6");
    group.sample_size(10);
    group.bench_function("ik_and_post_xyzac_trt_joint_g93", |b| {
        b.iter(|| {
            let program = to_program(&kin, &records, None, &options).expect("reachable");
            let text = program_text(&program, &kin, &dialect, &params).expect("post");
            assert!(text.len() > one);
            text.len()
        });
    });
    group.bench_function("ik_only", |b| {
        b.iter(|| to_program(&kin, &records, None, &options).expect("reachable").blocks.len());
    });
    group.finish();
}

/// Number of blocks (a sanity floor for the benchmark's output size): every pose is reached.
fn rapid_free_check(kin: &Kinematics, records: &[ClRecord], options: &ProgramOptions) -> usize {
    to_program(kin, &records[..1000], None, options).expect("reachable").blocks.len()
}

criterion_group!(benches, bench);
criterion_main!(benches);
