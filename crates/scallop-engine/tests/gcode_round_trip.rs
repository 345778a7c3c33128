//! The emitted 3-axis G-code parsed back with the independent `gcode` crate and
//! replayed by a small modal interpreter written here (G0/G1/G2/G3, G17/G18/G19,
//! G90/G91, G20/G21, F): every move endpoint must match the toolpath within 1e-4 mm,
//! and every toolpath vertex an arc replaces must lie within the arc share of the
//! path tolerance (+ 1e-4 mm of rounding) of the replayed arc. LinuxCNC, Fanuc and
//! grbl; a real finishing of the Choi surface and random toolpaths (proptest).

use gcode::{Code, Value};
use proptest::prelude::*;
use scallop_engine::{ARC_SHARE, FinishJob, OutputOptions, run_finishing};
use scallop_geom::Point3;
use scallop_post::{Dialect, ProgramInfo, write_fitted};
use scallop_toolpath::{FittedPath, Move, MoveKind, Segment, Toolpath, fit_arcs};

const DIALECTS: [&str; 3] = ["linuxcnc", "fanuc", "grbl"];
const ROUND_TRIP: f64 = 1e-4;

/// One replayed motion block.
#[derive(Debug, Clone, Copy)]
struct Replayed {
    motion: u32,
    from: [f64; 3],
    to: [f64; 3],
    /// Arc centre (absolute, mm) and plane `(u, v, n)` indices.
    center: [f64; 3],
    plane: (usize, usize, usize),
    feed: f64,
}

fn literal(v: &Value) -> f64 {
    match v {
        Value::Literal(x) => f64::from(*x),
        other => panic!("{other:?} in scallop output"),
    }
}

/// Replays `text` from the machine origin.
fn replay(text: &str) -> Vec<Replayed> {
    let program = gcode::parse(text).unwrap_or_else(|e| panic!("gcode crate rejects the program: {e:?}\n{text}"));
    let (mut absolute, mut scale, mut motion, mut feed) = (true, 1.0, 0u32, 0.0);
    let mut plane = (0usize, 1usize, 2usize);
    let mut pos = [0.0f64; 3];
    let mut out = Vec::new();
    for block in &program.blocks {
        let mut words: Vec<(char, f64)> = Vec::new();
        for code in &block.codes {
            match code {
                Code::General(g) => {
                    match (g.number.major(), g.number.minor()) {
                        (n @ 0..=3, None) => motion = n,
                        (17, None) => plane = (0, 1, 2),
                        (18, None) => plane = (2, 0, 1),
                        (19, None) => plane = (1, 2, 0),
                        (20, None) => scale = 25.4,
                        (21, None) => scale = 1.0,
                        (90, None) => absolute = true,
                        (91, None) => absolute = false,
                        (93, None) => panic!("inverse time in 3-axis output"),
                        _ => {}
                    }
                    words.extend(g.args.iter().map(|a| (a.letter.to_ascii_uppercase(), literal(&a.value))));
                }
                Code::Miscellaneous(m) => {
                    words.extend(m.args.iter().map(|a| (a.letter.to_ascii_uppercase(), literal(&a.value))))
                }
                Code::ToolChange(_) => {}
                _ => {}
            }
        }
        words.extend(block.word_addresses.iter().map(|w| (w.letter.to_ascii_uppercase(), literal(&w.value))));
        let get = |l: char| words.iter().find(|(c, _)| *c == l).map(|(_, v)| *v);
        if let Some(f) = get('F') {
            feed = f * scale;
        }
        let mut to = pos;
        let mut moved = false;
        for (i, l) in ['X', 'Y', 'Z'].into_iter().enumerate() {
            if let Some(v) = get(l) {
                to[i] = if absolute { v * scale } else { pos[i] + v * scale };
                moved = true;
            }
        }
        if !moved {
            continue;
        }
        let mut center = pos;
        if motion >= 2 {
            assert!(get('R').is_none(), "R arcs are not emitted by these dialects");
            for (i, l) in ['I', 'J', 'K'].into_iter().enumerate() {
                center[i] = pos[i] + get(l).unwrap_or(0.0) * scale;
            }
        }
        out.push(Replayed { motion, from: pos, to, center, plane, feed });
        pos = to;
    }
    out
}

fn p3(a: [f64; 3]) -> Point3 {
    Point3::new(a[0], a[1], a[2])
}

/// Distance from `p` to the replayed arc (radial and normal error at `p`'s angle;
/// outside the swept range, the distance to the nearer end).
fn distance_to_arc(r: &Replayed, p: &Point3) -> f64 {
    let (u, v, n) = r.plane;
    let c = (r.center[u], r.center[v]);
    let radius = (r.from[u] - c.0).hypot(r.from[v] - c.1);
    let ang = |x: f64, y: f64| (y - c.1).atan2(x - c.0);
    let a0 = ang(r.from[u], r.from[v]);
    let sign = if r.motion == 3 { 1.0 } else { -1.0 };
    let sweep = (sign * (ang(r.to[u], r.to[v]) - a0)).rem_euclid(std::f64::consts::TAU);
    let s = (sign * (ang(p[u], p[v]) - a0)).rem_euclid(std::f64::consts::TAU);
    let ends = (p - p3(r.from)).norm().min((p - p3(r.to)).norm());
    if s > sweep {
        return ends;
    }
    let radial = (p[u] - c.0).hypot(p[v] - c.1) - radius;
    let normal = p[n] - (r.from[n] + (r.to[n] - r.from[n]) * s / sweep);
    radial.hypot(normal).min(ends)
}

/// Checks the replay of `fitted` (written from `path`) within `arc_tol` for arcs.
fn check(path: &Toolpath, fitted: &FittedPath, text: &str, arc_tol: f64, dialect: &Dialect) {
    let blocks = replay(text);
    assert_eq!(blocks.len(), fitted.segments.len(), "one block per segment\n{text}");
    let feed_unit = 10f64.powi(-i32::try_from(dialect.feed_decimals).expect("small"));
    let mut first = 0;
    for ((b, seg), &last) in blocks.iter().zip(&fitted.segments).zip(&fitted.last) {
        let m = path.moves()[last];
        let err = (p3(b.to) - m.to).norm();
        assert!(err <= ROUND_TRIP, "{}: endpoint of move {last} off by {err}", dialect.name);
        match seg {
            Segment::Line(line) => {
                let rapid = matches!(line.kind, MoveKind::Rapid | MoveKind::Retract);
                assert_eq!(b.motion, if rapid { 0 } else { 1 }, "{}: move {last}", dialect.name);
                if !rapid {
                    let want = if line.kind == MoveKind::Plunge { path.plunge_feed } else { path.feed };
                    assert!((b.feed - want).abs() <= feed_unit, "{}: feed {} for {want}", dialect.name, b.feed);
                }
            }
            Segment::Arc(_) => {
                assert!(b.motion == 2 || b.motion == 3);
                assert!((b.feed - path.feed).abs() <= feed_unit);
                for (k, v) in path.moves()[first..=last].iter().enumerate() {
                    let d = distance_to_arc(b, &v.to);
                    assert!(d <= arc_tol + ROUND_TRIP, "{}: vertex {} off its arc by {d}", dialect.name, first + k);
                }
            }
        }
        first = last + 1;
    }
}

fn write(fitted: &FittedPath, dialect: &Dialect) -> String {
    let info = ProgramInfo { program: "1234".into(), tool: 2, spindle: 12000.0, indexed_rotaries: Vec::new() };
    let mut out = Vec::new();
    write_fitted(fitted, dialect, &info, &["round trip"], &mut out).expect("in memory");
    String::from_utf8(out).expect("utf-8")
}

#[test]
fn choi_finishing_replays_within_1e4_in_every_3_axis_dialect_with_and_without_arcs() {
    for arcs in [false, true] {
        let mut job = FinishJob::choi_demo();
        job.direction_deg = Some(90.0); // passes in YZ planes: G19 arcs
        job.output = OutputOptions { arc_fitting: arcs, ..OutputOptions::linuxcnc() };
        let out = run_finishing(&job).expect("plans");
        if arcs {
            assert!(out.fitted.arcs() > 100, "only {} arcs", out.fitted.arcs());
        }
        let arc_tol = ARC_SHARE * job.tolerances.path;
        for name in DIALECTS {
            let dialect = Dialect::builtin(name).expect("shipped");
            check(&out.toolpath, &out.fitted, &write(&out.fitted, &dialect), arc_tol, &dialect);
        }
        // The engine's own program replays too.
        check(&out.toolpath, &out.fitted, &out.gcode, arc_tol, &job.output.dialect);
    }
}

fn kind_strategy() -> impl Strategy<Value = MoveKind> {
    prop_oneof![
        Just(MoveKind::Rapid),
        Just(MoveKind::Plunge),
        Just(MoveKind::Feed),
        Just(MoveKind::Link),
        Just(MoveKind::Retract)
    ]
}

/// Random moves, and random arcs (sampled circles in random principal planes).
fn path_strategy() -> impl Strategy<Value = Toolpath> {
    let line = (kind_strategy(), -500.0..500.0f64, -500.0..500.0f64, -200.0..200.0f64)
        .prop_map(|(k, x, y, z)| vec![Move::new(k, Point3::new(x, y, z))]);
    let arc = (0..3usize, 1.0..200.0f64, -3.0..3.0f64, 0.1..2.5f64, -5.0..5.0f64, 3..60usize).prop_map(
        |(plane, radius, a0, turn, drift, n)| {
            let (u, v, w) = [(0, 1, 2), (2, 0, 1), (1, 2, 0)][plane];
            (0..=n)
                .map(|i| {
                    #[allow(clippy::cast_precision_loss, reason = "small counts")]
                    let s = i as f64 / n as f64;
                    let mut p = Point3::new(10.0, -20.0, 5.0);
                    p[u] += radius * (a0 + turn * s).cos();
                    p[v] += radius * (a0 + turn * s).sin();
                    p[w] += drift * s;
                    Move::new(MoveKind::Feed, p)
                })
                .collect::<Vec<_>>()
        },
    );
    (100.0..20_000.0f64, prop::collection::vec(prop_oneof![line, arc], 1..12)).prop_map(|(feed, parts)| {
        let mut path = Toolpath::new(feed.round());
        path.push(Move::new(MoveKind::Rapid, Point3::new(0.0, 0.0, 50.0)));
        for m in parts.into_iter().flatten() {
            path.push(m);
        }
        path
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn random_toolpaths_replay_within_1e4(path in path_strategy(), tol in 1e-3..0.05f64) {
        for name in DIALECTS {
            let dialect = Dialect::builtin(name).expect("shipped");
            let lines = FittedPath::lines(&path);
            check(&path, &lines, &write(&lines, &dialect), tol, &dialect);
            let arcs = fit_arcs(&path, tol);
            check(&path, &arcs, &write(&arcs, &dialect), tol, &dialect);
        }
    }
}
