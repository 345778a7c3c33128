//! Real 5-axis programs (issue 19): minimal cases of what used to be refused (a
//! reorientation in place on a rapid and on a cut, a cut near the pole, a genuine large
//! reorientation while cutting, a link that changes branch) and a generated corpus of
//! realistic paths (a swarf-cut impeller channel with in-place reorientations between
//! blades, a hull-like surface finished along its normal through and near the pole, long
//! C windings that must unwind, passes whose branch changes on the links). Each is posted
//! in every dialect and mode, read back, replayed through the forward kinematics and
//! checked against its CL records; the joints stay within their strokes and speeds, and
//! the branch changes and unwindings are counted against the minimum the path needs.

mod corpus;

use corpus::paths::{
    CASES, alternating, big_reorient_cut, hull, impeller, link_flip, near_pole_cut, same_tip_feed, short_c_trunnion,
    windings,
};
use scallop_machine::program::{ClRecord, MachineProgram, Motion, ProgramOptions, to_program, verify};
use scallop_machine::{Kinematics, Machine};
use scallop_post::{Dialect, OutputMode, PostError, PostParams, check_replay, program_text, replay};

const DIALECTS: [&str; 7] = ["linuxcnc", "fanuc", "siemens840d", "heidenhain", "heidenhain-iso", "plain", "grbl"];
const MODES: [OutputMode; 3] = [OutputMode::Joint, OutputMode::Tcp, OutputMode::TiltedPlane];

fn trunnion() -> Kinematics {
    Kinematics::new(&Machine::builtin("linuxcnc-xyzac-trt").expect("shipped machine"), 0.0)
}

/// What posting one path everywhere gave.
struct Posted {
    program: MachineProgram,
    /// Programs written and replayed.
    written: usize,
}

/// Plans `records` on `kin`, verifies the joint program (strokes, tolerance, speeds), and
/// writes it in every dialect and mode: each text is read back and replayed against the
/// records. The only refusals allowed are grbl (a 3-axis controller) and tilted planes
/// for a path that changes the tool axis while cutting.
fn post_everywhere(name: &str, kin: &Kinematics, records: &[ClRecord]) -> Posted {
    let opts = ProgramOptions::default();
    let program = to_program(kin, records, None, &opts).unwrap_or_else(|e| panic!("{name}: {e}"));
    let v = verify(kin, &program, &opts).unwrap_or_else(|e| panic!("{name}: {e}"));
    assert!(v.max_tip_deviation <= opts.tol_pos && v.max_rate_ratio <= 1.0 + 1e-9, "{name}: {v:?}");
    let simultaneous = program
        .blocks
        .windows(2)
        .any(|w| w[1].motion != Motion::Rapid && w[1].pose.axis.cross(&w[0].pose.axis).norm() > opts.tol_ang.sin());
    let mut written = 0;
    for dialect_name in DIALECTS {
        let dialect = Dialect::builtin(dialect_name).expect("shipped dialect");
        for mode in MODES {
            let what = format!("{name} / {dialect_name} / {}", mode.name());
            let params = PostParams::new("19", mode, 4, 0.0, 10000.0, &opts);
            let text = match program_text(&program, kin, &dialect, &params) {
                Ok(t) => t,
                Err(PostError::Unsupported { what: w, .. })
                    if dialect_name == "grbl"
                        || (mode == OutputMode::Tcp && dialect.tcp.is_none())
                        || (mode == OutputMode::TiltedPlane && simultaneous && w.contains("cutting move")) =>
                {
                    continue;
                }
                Err(e) => panic!("{what}: {e}"),
            };
            let blocks = replay(&text, &dialect, kin).unwrap_or_else(|e| panic!("{what}: {e}\n{text}"));
            let r = check_replay(&blocks, records, kin, &dialect, opts.tol_pos, opts.tol_ang)
                .unwrap_or_else(|e| panic!("{what}: {e}\n{text}"));
            assert!(r.max_rate_ratio <= 1.0 + 1e-9, "{what}: {r:?}");
            written += 1;
        }
    }
    // Joint and TCP output in the five 5-axis dialects and the plain one.
    assert!(written >= 12, "{name}: only {written} programs written");
    Posted { program, written }
}

/// Blocks whose pole axis (C) turns more than 90 deg: `(on cutting or link blocks, on rapids)`.
/// A branch flip turns it by 180 deg; continuous motion is subdivided far below that.
fn pole_jumps(kin: &Kinematics, program: &MachineProgram) -> (usize, usize) {
    let c = kin.pole_axis();
    let (mut moving, mut rapid) = (0, 0);
    for w in program.blocks.windows(2) {
        if (w[1].joints[c] - w[0].joints[c]).abs() > std::f64::consts::FRAC_PI_2 {
            if w[1].motion == Motion::Rapid { rapid += 1 } else { moving += 1 }
        }
    }
    (moving, rapid)
}

// ------------------------------------------------------------------ the minimal cases

#[test]
fn issue_19_minimal_cases_post_in_every_dialect_and_mode() {
    let kin = trunnion();
    for (name, make) in CASES {
        let posted = post_everywhere(name, &kin, &make());
        assert!(posted.written >= 12, "{name}");
    }
    // The cuts turn C by far more than the old 30 deg limit, continuously.
    for (make, at_least) in [(near_pole_cut as fn() -> Vec<ClRecord>, 35.0), (big_reorient_cut, 45.0)] {
        let p = to_program(&kin, &make(), None, &ProgramOptions::default()).expect("posts");
        let c: Vec<f64> = p.blocks.iter().map(|b| b.words[4]).collect();
        assert!((c[c.len() - 1] - c[1]).abs() > at_least, "{c:?}");
        assert_eq!(pole_jumps(&kin, &p).0, 0, "no flip while cutting: {c:?}");
    }
}

#[test]
fn issue_19_a_link_that_changes_branch_retracts_reorients_and_comes_back() {
    let kin = trunnion();
    let records = link_flip();
    let opts = ProgramOptions::default();
    let p = to_program(&kin, &records, None, &opts).expect("posts");
    let link = records.iter().position(|r| r.motion == Motion::Link).expect("a link");
    let blocks: Vec<_> = p.blocks.iter().filter(|b| b.cl_index == link).collect();
    assert_eq!(blocks.len(), 3, "retract, reorient, approach: {blocks:?}");
    let (before, after) = (&records[link - 1].pose, &records[link].pose);
    // Retract along the old tool axis, reorient at the retract distance, come back.
    assert!((blocks[0].pose.tip - (before.tip + before.axis * opts.retract)).norm() < 1e-9);
    assert_eq!(blocks[1].motion, Motion::Rapid);
    assert!((blocks[1].pose.tip - (after.tip + after.axis * opts.retract)).norm() < 1e-9);
    assert!((blocks[2].pose.tip - after.tip).norm() < 1e-9);
    // The retract and the approach keep the rotaries (straight moves along the tool axis).
    let k = p.blocks.iter().position(|b| b.cl_index == link).expect("link blocks");
    for (a, b) in [(k - 1, k), (k + 1, k + 2)] {
        let (qa, qb) = (p.blocks[a].joints, p.blocks[b].joints);
        assert!((qa[3] - qb[3]).abs() < 1e-12 && (qa[4] - qb[4]).abs() < 1e-12, "{qa:?} {qb:?}");
    }
    // The branch changes on the link (C turns by half a turn), never while cutting.
    assert_eq!(pole_jumps(&kin, &p), (0, 1));
}

#[test]
fn issue_19_replay_pairs_records_sharing_a_tip_by_order() {
    // A program that reaches the second of two same-tip records with the first one's
    // axis is still an error (the pairing is by order, not a looser check).
    let kin = trunnion();
    let records = same_tip_feed();
    let opts = ProgramOptions::default();
    let good = to_program(&kin, &records, None, &opts).expect("posts");
    let mut bad = good.clone();
    // Drop the in-place reorientation: the cut goes on with the first axis.
    bad.blocks.retain(|b| b.cl_index != 2);
    let d = Dialect::builtin("linuxcnc").expect("shipped");
    let params = PostParams::new("1", OutputMode::Joint, 1, 0.0, 8000.0, &opts);
    let ok = program_text(&good, &kin, &d, &params).expect("writes");
    check_replay(&replay(&ok, &d, &kin).expect("reads"), &records, &kin, &d, opts.tol_pos, opts.tol_ang)
        .expect("the good program replays");
    let text = program_text(&bad, &kin, &d, &params).expect("writes");
    let err = check_replay(&replay(&text, &d, &kin).expect("reads"), &records, &kin, &d, opts.tol_pos, opts.tol_ang);
    assert!(matches!(&err, Err(PostError::Deviation { what, .. }) if what.contains("tool axis")), "{err:?}");
}

#[test]
fn issue_19_linuxcnc_applies_the_tool_offset_and_sets_the_kinematics() {
    let kin = trunnion();
    let opts = ProgramOptions::default();
    let p = to_program(&kin, &big_reorient_cut(), None, &opts).expect("posts");
    let d = Dialect::builtin("linuxcnc").expect("shipped");
    let text = |mode| {
        let params = PostParams::new("1", mode, 7, 0.0, 8000.0, &opts);
        program_text(&p, &kin, &d, &params).expect("writes")
    };
    // TCP: the trt kinematics read the tool length from the active offset, so G43 H<tool>
    // comes before the kinematics switch; M429 at the end.
    let tcp = text(OutputMode::Tcp);
    let (g43, m428) = (tcp.find("\nG43 H7\n").expect("G43 H7"), tcp.find("\nM428\n").expect("M428"));
    assert!(g43 < m428 && tcp.contains("\nM429\n"), "{tcp}");
    // Joint output: identity kinematics (M429) before the first motion, then G43 H<tool>.
    let joint = text(OutputMode::Joint);
    let (m429, g43) = (joint.find("\nM429\n").expect("M429"), joint.find("\nG43 H7\n").expect("G43"));
    let first_move = joint.find("\nG0 ").expect("a rapid");
    assert!(m429 < g43 && g43 < first_move && !joint.contains("M428"), "{joint}");
    // The same for the other dialects' TCP cancel in joint output.
    for (name, cancel) in
        [("siemens840d", " TRAFOOF\n"), ("heidenhain", " FUNCTION RESET TCPM\n"), ("heidenhain-iso", " M129\n")]
    {
        let d = Dialect::builtin(name).expect("shipped");
        let params = PostParams::new("1", OutputMode::Joint, 7, 0.0, 8000.0, &opts);
        let t = program_text(&p, &kin, &d, &params).expect("writes");
        let first_move = t.find(" G0 ").or_else(|| t.find(" L ")).expect("a move");
        assert!(t.find(cancel).is_some_and(|k| k < first_move), "{name}: {t}");
    }
}

// ------------------------------------------------------------------ the corpus

#[test]
fn corpus_impeller_channel_posts_without_flips() {
    let kin = trunnion();
    let posted = post_everywhere("impeller", &kin, &impeller());
    // Every blade is reachable on one branch (A to -55 deg): no branch flip anywhere, and
    // C advances by the blade pitch on the in-place reorientations.
    assert_eq!(pole_jumps(&kin, &posted.program), (0, 0));
}

#[test]
fn corpus_hull_through_and_near_the_pole_posts_without_flips() {
    let kin = trunnion();
    let records = hull();
    let posted = post_everywhere("hull", &kin, &records);
    // Near the pole C turns about half a turn in a few millimetres, continuously.
    let c = kin.pole_axis();
    let p = &posted.program;
    let row = |y: f64| p.blocks.iter().filter(move |b| (records[b.cl_index].pose.tip.y - y).abs() < 1e-9);
    let span = |y: f64| {
        let cs: Vec<f64> = row(y).map(|b| b.joints[c]).collect();
        cs.iter().copied().fold(f64::NEG_INFINITY, f64::max) - cs.iter().copied().fold(f64::INFINITY, f64::min)
    };
    let near = span(3.0).to_degrees();
    assert!(near > 150.0, "C span near the pole {near}");
    // The path needs no flip: none is made.
    assert_eq!(pole_jumps(&kin, p), (0, 0));
}

#[test]
fn corpus_long_c_windings_unwind_on_rapids_only() {
    // The trunnion with a C stroke of +-200 deg: every full circle needs its own winding,
    // so the path needs (passes - 1) unwindings, each on a rapid.
    let kin = Kinematics::new(&short_c_trunnion(), 0.0);
    let passes = 3;
    let posted = post_everywhere("windings", &kin, &windings(&kin, passes));
    let c = kin.pole_axis();
    let p = &posted.program;
    let unwinds = p
        .blocks
        .windows(2)
        .filter(|w| (w[1].joints[c] - w[0].joints[c]).abs() > std::f64::consts::PI)
        .inspect(|w| assert_eq!(w[1].motion, Motion::Rapid, "unwinding while cutting: {w:?}"))
        .count();
    assert_eq!(unwinds, passes - 1, "the minimum number of unwindings");
    assert!(p.blocks.iter().all(|b| b.words[c].abs() <= 200.0 + 1e-6));
    // Each pass turns C by a full turn (continuous winding while cutting).
    let feeds: Vec<f64> = p.blocks.iter().filter(|b| b.motion == Motion::Feed).map(|b| b.words[c]).collect();
    let (lo, hi) = feeds.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| (l.min(*v), h.max(*v)));
    assert!(hi - lo > 355.0, "C range while cutting {lo}..{hi}");
}

#[test]
fn corpus_branch_changes_on_links_are_the_minimum() {
    let kin = trunnion();
    let passes = 4;
    let records = alternating(passes);
    let posted = post_everywhere("alternating", &kin, &records);
    // Every pass changes side: (passes - 1) branch changes, each on a link (a retract,
    // a reorientation rapid, an approach), none while cutting.
    assert_eq!(pole_jumps(&kin, &posted.program), (0, passes - 1));
    let a = kin.tilt_axis();
    let side = |b: &scallop_machine::program::ProgramBlock| b.pose.axis.y > 0.0;
    for w in posted.program.blocks.windows(2) {
        if w[1].motion.is_cutting() {
            assert_eq!(side(&w[0]), side(&w[1]));
            assert!((w[1].joints[a] - w[0].joints[a]).abs() < 0.5, "{w:?}");
        }
    }
}

#[test]
fn corpus_windings_unwind_on_rapids_when_the_job_asks() {
    // On the trunnion's +-36000 deg C stroke the windings accumulate (the shortest moves);
    // with `unwind_rapids` every rapid brings C back within half a turn of zero.
    let kin = trunnion();
    let passes = 3;
    let records = windings(&kin, passes);
    let c = kin.pole_axis();
    let mut opts = ProgramOptions::default();
    let free = to_program(&kin, &records, None, &opts).expect("posts");
    let peak = |p: &MachineProgram| p.blocks.iter().map(|b| b.words[c].abs()).fold(0.0, f64::max);
    assert!(peak(&free) > 2.0 * 360.0, "windings accumulate: {}", peak(&free));
    opts.plan.unwind_rapids = true;
    let unwound = to_program(&kin, &records, None, &opts).expect("posts");
    verify(&kin, &unwound, &opts).expect("verifies");
    for b in unwound.blocks.iter().filter(|b| b.motion == Motion::Rapid) {
        assert!(b.words[c].abs() <= 180.0 + 1e-9, "rapid at C {}", b.words[c]);
    }
    assert!(peak(&unwound) <= 360.0 + 1e-9, "{}", peak(&unwound));
    let d = Dialect::builtin("linuxcnc").expect("shipped");
    let params = PostParams::new("1", OutputMode::Joint, 1, 0.0, 8000.0, &opts);
    let text = program_text(&unwound, &kin, &d, &params).expect("writes");
    check_replay(&replay(&text, &d, &kin).expect("reads"), &records, &kin, &d, opts.tol_pos, opts.tol_ang)
        .expect("replays");
}
