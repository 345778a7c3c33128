//! Round trips (spec K16): every dialect and output mode on generated 5-axis paths (a
//! tilted circle, a pole crossing, an indexed 3+2 path) on the shipped machines; the
//! text is read back, replayed through the forward kinematics and compared with the
//! input CL path.

use scallop_geom::{Point3, Vec3};
use scallop_machine::program::{ClRecord, Motion, ProgramOptions, to_program};
use scallop_machine::{Kinematics, Machine, Pose};
use scallop_post::{Dialect, OutputMode, PostError, PostParams, RoundTrip, check_replay, program_text, replay};

const DIALECTS: [&str; 6] = ["linuxcnc", "fanuc", "siemens840d", "heidenhain", "heidenhain-iso", "plain"];

fn deg(v: f64) -> f64 {
    v.to_radians()
}

fn rec(tip: Point3, axis: Vec3, motion: Motion) -> ClRecord {
    ClRecord { pose: Pose::new(tip, axis), motion, feed: 1500.0 }
}

fn setup(name: &str) -> (Kinematics, f64, f64) {
    let m = Machine::builtin(name).expect("shipped machine");
    let length = if name == "mx330" { 100.0 } else { 0.0 };
    let z = if name == "mx330" { 20.0 } else { 60.0 };
    (Kinematics::new(&m, length), length, z)
}

/// Tip on a circle of radius 20, tool axis tilted 20 deg outwards: a full turn of C.
fn tilted_circle(z: f64) -> Vec<ClRecord> {
    let axis_at = |t: f64| Vec3::new(deg(20.0).sin() * t.cos(), deg(20.0).sin() * t.sin(), deg(20.0).cos());
    let mut r = vec![rec(Point3::new(20.0, 0.0, z + 30.0), axis_at(0.0), Motion::Rapid)];
    for i in 0..=72 {
        let t = deg(5.0 * f64::from(i));
        r.push(rec(Point3::new(20.0 * t.cos(), 20.0 * t.sin(), z), axis_at(t), Motion::Feed));
    }
    r
}

/// Tool axis from -30 to +30 deg through the pole about X while the tip moves along X.
fn pole_crossing(z: f64) -> Vec<ClRecord> {
    let axis_at = |phi: f64| Vec3::new(0.0, deg(phi).sin(), deg(phi).cos());
    let mut r = vec![rec(Point3::new(-15.0, 0.0, z + 30.0), axis_at(-30.0), Motion::Rapid)];
    for i in -30..=30 {
        r.push(rec(Point3::new(f64::from(i) * 0.5, 0.0, z), axis_at(f64::from(i)), Motion::Feed));
    }
    r
}

/// Two constant-axis (3+2) squares joined by rapids at clearance.
fn indexed(z: f64) -> Vec<ClRecord> {
    let mut r = Vec::new();
    for axis in [Vec3::new(0.0, -0.4, 1.0), Vec3::new(0.35, 0.2, 1.0)] {
        let a = axis.normalize();
        r.push(rec(Point3::new(-10.0, -10.0, z) + a * 40.0, a, Motion::Rapid));
        r.push(rec(Point3::new(-10.0, -10.0, z) + a * 5.0, a, Motion::Rapid));
        r.push(rec(Point3::new(-10.0, -10.0, z), a, Motion::Plunge));
        for (x, y) in [(10.0, -10.0), (10.0, 10.0), (-10.0, 10.0), (-10.0, -10.0)] {
            r.push(rec(Point3::new(x, y, z), a, Motion::Feed));
        }
        r.push(rec(Point3::new(-10.0, -10.0, z) + a * 40.0, a, Motion::Rapid));
    }
    r
}

fn params(mode: OutputMode, length: f64, opts: &ProgramOptions) -> PostParams {
    PostParams {
        program: "1234".into(),
        mode,
        tool: 3,
        tool_length: length,
        spindle: 12000.0,
        tol_pos: opts.tol_pos,
        tol_ang: opts.tol_ang,
        predicted_time: Some(12.5),
    }
}

fn expect_supported(dialect: &Dialect, machine: &Machine, mode: OutputMode) -> bool {
    mode != OutputMode::Tcp || (dialect.tcp.is_some() && machine.tcp().supported)
}

fn round_trip_all(path_name: &str, make: fn(f64) -> Vec<ClRecord>, modes: &[OutputMode]) {
    // Every machine x dialect x mode that the dialect and the machine support is written,
    // read back and replayed; the refused ones must be exactly the unsupported ones.
    let opts = ProgramOptions::default();
    let mut checked = 0;
    for name in Machine::builtin_names() {
        let (kin, length, z) = setup(name);
        let records = make(z);
        let program = to_program(&kin, &records, None, &opts).unwrap_or_else(|e| panic!("{name} {path_name}: {e}"));
        for dialect_name in DIALECTS {
            let dialect = Dialect::builtin(dialect_name).expect("shipped dialect");
            for &mode in modes {
                let what = format!("{name} / {dialect_name} / {} / {path_name}", mode.name());
                let text = match program_text(&program, &kin, &dialect, &params(mode, length, &opts)) {
                    Ok(t) => t,
                    Err(PostError::Unsupported { .. }) if !expect_supported(&dialect, kin.machine(), mode) => continue,
                    Err(e) => panic!("{what}: {e}"),
                };
                assert!(expect_supported(&dialect, kin.machine(), mode), "{what}: should be refused");
                let blocks = replay(&text, &dialect, &kin).unwrap_or_else(|e| panic!("{what}: {e}\n{text}"));
                let r = check_replay(&blocks, &records, &kin, &dialect, opts.tol_pos, opts.tol_ang)
                    .unwrap_or_else(|e| panic!("{what}: {e}\n{text}"));
                assert!(r.max_rate_ratio <= 1.0 + 1e-9, "{what}: {r:?}");
                checked += 1;
            }
        }
    }
    assert!(checked >= 7 * DIALECTS.len(), "{path_name}: only {checked} combinations checked");
}

#[test]
fn tilted_circle_round_trips_in_every_dialect_joint_and_tcp() {
    round_trip_all("tilted circle", tilted_circle, &[OutputMode::Joint, OutputMode::Tcp]);
}

#[test]
fn pole_crossing_round_trips_in_every_dialect_joint_and_tcp() {
    round_trip_all("pole crossing", pole_crossing, &[OutputMode::Joint, OutputMode::Tcp]);
}

#[test]
fn indexed_path_round_trips_in_every_dialect_and_mode() {
    round_trip_all("indexed 3+2", indexed, &[OutputMode::Joint, OutputMode::Tcp, OutputMode::TiltedPlane]);
}

fn text_for(
    machine: &str,
    dialect: &str,
    mode: OutputMode,
    make: fn(f64) -> Vec<ClRecord>,
) -> Result<String, PostError> {
    let (kin, length, z) = setup(machine);
    let opts = ProgramOptions::default();
    let program = to_program(&kin, &make(z), None, &opts).expect("plans");
    program_text(&program, &kin, &Dialect::builtin(dialect).expect("shipped"), &params(mode, length, &opts))
}

/// Replays `text` in `dialect` on `machine` and checks it against the records of
/// `make` (as [`text_for`] posted them).
fn replay_check(
    machine: &str,
    dialect: &str,
    text: &str,
    make: fn(f64) -> Vec<ClRecord>,
) -> Result<RoundTrip, PostError> {
    let (kin, _, z) = setup(machine);
    let dialect = Dialect::builtin(dialect).expect("shipped");
    let opts = ProgramOptions::default();
    let blocks = replay(text, &dialect, &kin).expect("reads");
    check_replay(&blocks, &make(z), &kin, &dialect, opts.tol_pos, opts.tol_ang)
}

#[test]
fn tilted_plane_codes_per_dialect() {
    let fanuc = text_for("ucp710", "fanuc", OutputMode::TiltedPlane, indexed).expect("fanuc");
    assert_eq!(fanuc.matches("G68.2 X0 Y0 Z0 I").count(), 2, "{fanuc}");
    assert_eq!(fanuc.matches("G53.1").count(), 2);
    assert_eq!(fanuc.matches("G69").count(), 2);
    let siemens = text_for("ucp710", "siemens840d", OutputMode::TiltedPlane, indexed).expect("840d");
    assert_eq!(siemens.matches("CYCLE800(0,\"TC1\",200000,57,").count(), 2, "{siemens}");
    let heidenhain = text_for("ucp710", "heidenhain", OutputMode::TiltedPlane, indexed).expect("tnc");
    assert_eq!(heidenhain.matches("PLANE SPATIAL SPA").count(), 2, "{heidenhain}");
    assert!(heidenhain.contains("PLANE RESET STAY"));
    // LinuxCNC has no tilted-plane code: joint space with the rotaries held.
    let linuxcnc = text_for("linuxcnc-xyzac-trt", "linuxcnc", OutputMode::TiltedPlane, indexed).expect("lcnc");
    assert!(linuxcnc.contains("rotaries held") && !linuxcnc.contains("G68.2"), "{linuxcnc}");
    // Simultaneous 5-axis moves cannot be written in tilted planes.
    let refused = text_for("ucp710", "fanuc", OutputMode::TiltedPlane, tilted_circle);
    assert!(matches!(refused, Err(PostError::Unsupported { .. })), "{refused:?}");
}

#[test]
fn tcp_codes_per_dialect() {
    let fanuc = text_for("ucp710", "fanuc", OutputMode::Tcp, tilted_circle).expect("fanuc");
    assert!(fanuc.contains("\nG43.4 H3\n") && fanuc.contains("\nG49\n"), "{fanuc}");
    assert!(!fanuc.contains("G93"), "TCP output uses the tip feed");
    let siemens = text_for("ucp710", "siemens840d", OutputMode::Tcp, tilted_circle).expect("840d");
    assert!(siemens.contains(" TRAORI\n") && siemens.contains(" TRAFOOF\n"), "{siemens}");
    assert!(siemens.contains("C=DC("), "modulo C of the UCP 710 is written DC()");
    let tnc = text_for("ucp710", "heidenhain", OutputMode::Tcp, tilted_circle).expect("tnc");
    assert!(tnc.contains("FUNCTION TCPM F TCP AXIS POS PATHCTRL AXIS") && tnc.contains("FUNCTION RESET TCPM"));
    // LinuxCNC: the configuration's codes from the machine description, never hard-coded.
    let lcnc = text_for("linuxcnc-xyzac-trt", "linuxcnc", OutputMode::Tcp, tilted_circle).expect("lcnc");
    assert!(lcnc.contains("\nM428\n") && lcnc.contains("\nM429\n"), "{lcnc}");
    // The MX330 description declares no TCP.
    let refused = text_for("mx330", "fanuc", OutputMode::Tcp, tilted_circle);
    assert!(matches!(refused, Err(PostError::Unsupported { .. })), "{refused:?}");
}

#[test]
fn joint_output_conventions() {
    let lcnc = text_for("linuxcnc-xyzac-trt", "linuxcnc", OutputMode::Joint, tilted_circle).expect("lcnc");
    // Every G93 feed block carries F (LinuxCNC rejects a G93 G1 without F); G94 before rapids and at the end.
    let mut g93 = false;
    for line in lcnc.lines() {
        if line.contains("G93") {
            g93 = true;
        }
        if line.contains("G94") {
            g93 = false;
        }
        if g93 && line.starts_with(['G', 'X', 'Y', 'Z', 'A', 'C']) && !line.starts_with("G0") {
            assert!(line.contains(" F"), "G93 block without F: {line}");
        }
        assert!(!(g93 && line.contains("G0 ")), "rapid in G93: {line}");
    }
    assert!(lcnc.contains("G43 H3"), "controller-applied tool length");
    let siemens = text_for("ucp710", "siemens840d", OutputMode::Joint, tilted_circle).expect("840d");
    let numbers: Vec<u64> =
        siemens.lines().map(|l| l[1..l.find(' ').expect("N word")].parse().expect("number")).collect();
    assert!(numbers.windows(2).all(|w| w[1] == w[0] + 10), "N10, N20, ...");
    let tnc = text_for("ucp710", "heidenhain", OutputMode::Joint, tilted_circle).expect("tnc");
    assert!(tnc.starts_with("0 ; scallop"), "{tnc}");
    assert!(tnc.contains("BEGIN PGM 1234 MM") && tnc.contains("END PGM 1234 MM"));
    assert!(tnc.contains(" FT") && tnc.contains(" FMAX"), "{tnc}");
    assert!(tnc.lines().enumerate().all(|(i, l)| l.starts_with(&format!("{i} "))), "numbered from 0");
    // Header: tool, tolerances and the predicted time.
    assert!(lcnc.contains("tool T3") && lcnc.contains("path 0.0050 mm") && lcnc.contains("predicted time 12.5 s"));
    // Modal suppression: no line repeats the previous motion words.
    assert!(lcnc.lines().collect::<Vec<_>>().windows(2).all(|w| w[0] != w[1] || !w[0].starts_with('X')));
}

#[test]
fn grbl_takes_three_axis_work_only() {
    let refused = text_for("generic-hh-ca", "grbl", OutputMode::Joint, tilted_circle);
    assert!(matches!(refused, Err(PostError::Unsupported { .. })), "{refused:?}");
    let flat = |z: f64| -> Vec<ClRecord> {
        let mut r = vec![rec(Point3::new(0.0, 0.0, z + 10.0), Vec3::z(), Motion::Rapid)];
        r.push(rec(Point3::new(0.0, 0.0, z), Vec3::z(), Motion::Plunge));
        r.push(rec(Point3::new(30.0, 5.0, z), Vec3::z(), Motion::Feed));
        r
    };
    let text = text_for("generic-hh-ca", "grbl", OutputMode::Joint, flat).expect("3-axis");
    assert!(!text.contains(" A") && !text.contains(" C") && !text.contains("G93") && !text.contains("M6"), "{text}");
    replay_check("generic-hh-ca", "grbl", &text, flat).expect("round trip");
}

#[test]
fn a_corrupted_word_is_caught_by_the_replay() {
    let text = text_for("ucp710", "fanuc", OutputMode::Joint, tilted_circle).expect("writes");
    // Change one A word by 0.01 deg.
    let line = text.lines().filter(|l| l.contains(" A")).nth(20).expect("a line with A");
    let word = line.split_whitespace().find(|w| w.starts_with('A')).expect("A word");
    let value: f64 = word[1..].parse().expect("number");
    let bad = text.replacen(line, &line.replace(word, &format!("A{:.4}", value + 0.01)), 1);
    let err = replay_check("ucp710", "fanuc", &bad, tilted_circle);
    assert!(matches!(err, Err(PostError::Deviation { .. })), "{err:?}");
}

#[test]
fn dialects_load_from_toml() {
    for n in Dialect::builtin_names() {
        Dialect::builtin(n).unwrap_or_else(|e| panic!("{n}: {e}"));
    }
    let text = "name = \"mine\"\ndecimals = 3\ncomment = [\";\", \"\"]\nline_numbers = { prefix = \"N\", start = 1, step = 1 }\nfeed_by_time = \"g93\"\ntilted_plane = \"g68_2\"\n";
    let d = Dialect::from_toml_str(text).expect("parses");
    assert_eq!(d.line_numbers.expect("numbers").start, 1);
    assert!(matches!(Dialect::from_toml_str("name = 1"), Err(PostError::Dialect { .. })));
    assert!(Dialect::from_toml_str("name = \"x\"\ndecimals = 3\ncomment = [\"(\", \")\"]\nbogus = 1").is_err());
}

#[test]
fn modulo_rotary_blocks_are_split_below_half_a_turn() {
    use scallop_machine::Joints;
    use scallop_machine::program::{MachineProgram, ProgramBlock};
    let (kin, length, _) = setup("ucp710");
    let block = |c_deg: f64, motion| {
        let joints = Joints::new(0.0, 0.0, 50.0, 0.0, deg(c_deg));
        let m = kin.machine();
        let mut words = [0.0; 5];
        for (i, a) in m.axes().iter().enumerate() {
            words[i] = a.to_nc_word(joints[i]);
        }
        ProgramBlock {
            motion,
            joints,
            words,
            pose: kin.fk(&joints),
            feed: 1000.0,
            inverse_time: Some(10.0),
            cl_index: 0,
        }
    };
    let program = MachineProgram {
        axis_names: kin.machine().axis_names().iter().map(|s| (*s).to_string()).collect(),
        blocks: vec![block(0.0, Motion::Rapid), block(270.0, Motion::Feed)],
        events: Vec::new(),
    };
    let opts = ProgramOptions::default();
    let d = Dialect::builtin("siemens840d").expect("shipped");
    let text = program_text(&program, &kin, &d, &params(OutputMode::Joint, length, &opts)).expect("writes");
    let c_words: Vec<&str> = text.split_whitespace().filter(|w| w.starts_with("C=DC(")).collect();
    assert_eq!(c_words, ["C=DC(0.0000)", "C=DC(135.0000)", "C=DC(270.0000)"], "{text}");
    let blocks = replay(&text, &d, &kin).expect("reads");
    let last = blocks.last().expect("blocks");
    // The control's shortest-path moves add up to the planned rotation.
    let c = kin.machine().axis_by_name("C").expect("C");
    assert!((kin.machine().axes()[c].to_nc_word(last.joints[c]) - 270.0).abs() < 1e-9);
    // Split blocks keep the block time: each piece gets twice the G93 word (10 -> 20).
    assert_eq!(text.matches(" F20.000").count(), 2, "{text}");
}
