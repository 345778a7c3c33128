//! Writes a generated 5-axis program (a tilted circle, then an indexed 3+2 square) for a
//! shipped machine in a dialect and mode: `cargo run -p scallop-post --example post_demo --
//! MACHINE DIALECT MODE` (modes: joint, tcp, tilted_plane). Used by `bench/linuxcnc/rs274.sh`.

use scallop_geom::{Point3, Vec3};
use scallop_machine::program::{ClRecord, Motion, ProgramOptions, to_program};
use scallop_machine::{Kinematics, Machine, Pose};
use scallop_post::{Dialect, OutputMode, PostParams, check_replay, program_text, replay};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let machine_name = args.first().map_or("linuxcnc-xyzac-trt", String::as_str);
    let dialect_name = args.get(1).map_or("linuxcnc", String::as_str);
    let mode = match args.get(2).map_or("joint", String::as_str) {
        "tcp" => OutputMode::Tcp,
        "tilted_plane" => OutputMode::TiltedPlane,
        _ => OutputMode::Joint,
    };
    let machine = Machine::builtin(machine_name)?;
    let length = if machine_name == "mx330" { 100.0 } else { 0.0 };
    let z = if machine_name == "mx330" { 20.0 } else { 60.0 };
    let kin = Kinematics::new(&machine, length);
    let tilt = 20f64.to_radians();
    let axis_at = |t: f64| Vec3::new(tilt.sin() * t.cos(), tilt.sin() * t.sin(), tilt.cos());
    let rec = |tip: Point3, axis: Vec3, motion| ClRecord { pose: Pose::new(tip, axis), motion, feed: 1500.0 };
    let mut records = vec![rec(Point3::new(20.0, 0.0, z + 30.0), axis_at(0.0), Motion::Rapid)];
    for i in 0..=72 {
        let t = (5.0 * f64::from(i)).to_radians();
        records.push(rec(Point3::new(20.0 * t.cos(), 20.0 * t.sin(), z), axis_at(t), Motion::Feed));
    }
    records.push(rec(Point3::new(20.0, 0.0, z) + axis_at(0.0) * 30.0, axis_at(0.0), Motion::Rapid));
    let a = Vec3::new(0.0, -0.4, 1.0).normalize();
    records.push(rec(Point3::new(-10.0, -10.0, z) + a * 30.0, a, Motion::Rapid));
    records.push(rec(Point3::new(-10.0, -10.0, z), a, Motion::Plunge));
    for (x, y) in [(10.0, -10.0), (10.0, 10.0), (-10.0, 10.0), (-10.0, -10.0)] {
        records.push(rec(Point3::new(x, y, z), a, Motion::Feed));
    }
    records.push(rec(Point3::new(-10.0, -10.0, z) + a * 30.0, a, Motion::Rapid));
    let opts = ProgramOptions::default();
    let program = to_program(&kin, &records, None, &opts)?;
    let dialect = Dialect::builtin(dialect_name)?;
    let params = PostParams {
        program: "1001".into(),
        mode,
        tool: 1,
        tool_length: length,
        spindle: 12000.0,
        tol_pos: opts.tol_pos,
        tol_ang: opts.tol_ang,
        predicted_time: None,
    };
    let text = program_text(&program, &kin, &dialect, &params)?;
    check_replay(&replay(&text, &dialect, &kin)?, &records, &kin, &dialect, opts.tol_pos, opts.tol_ang)?;
    print!("{text}");
    Ok(())
}
