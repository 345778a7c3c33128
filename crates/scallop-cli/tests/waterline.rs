//! Smoke tests of `scallop waterline`: CSV and JSON output, summary, errors.

mod common;

use common::{pyramid_stl, scallop, scratch};

/// A flat cutter of radius 1 with its tip at z cuts the pyramid where its disk
/// meets the pyramid's cross-section above z (the square of half-width 5 - z
/// around (5, 5)): the contour is that square offset by 1, so its largest x is
/// 5 + (5 - z) + 1.
#[test]
fn waterline_writes_csv_and_json_loops() {
    let dir = scratch("loops");
    let stl = dir.join("pyramid.stl");
    std::fs::write(&stl, pyramid_stl()).expect("stl");
    let csv = dir.join("loops.csv");
    let out = scallop()
        .args(["waterline", "--mesh"])
        .arg(&stl)
        .args(["--cutter", "flat", "--diameter", "2", "--z", "2.5", "--z", "1:3:1", "--json", "-o"])
        .arg(&csv)
        .output()
        .expect("run");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json summary");
    assert_eq!(summary["levels"].as_array().map(Vec::len), Some(4));
    assert_eq!(summary["loops"], 4);
    let text = std::fs::read_to_string(&csv).expect("csv");
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("loop,x,y,z"));
    let rows: Vec<[f64; 4]> = lines
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|t| t.parse().expect("number")).collect();
            [v[0], v[1], v[2], v[3]]
        })
        .collect();
    for (k, z) in [2.5, 1.0, 2.0, 3.0].into_iter().enumerate() {
        let x_max = rows.iter().filter(|r| r[0] == k as f64).map(|r| r[1]).fold(f64::MIN, f64::max);
        assert!(rows.iter().filter(|r| r[0] == k as f64).all(|r| r[3] == z));
        assert!((x_max - (11.0 - z)).abs() < 1e-6, "z {z}: largest x {x_max}");
    }
    let json = dir.join("loops.json");
    let out = scallop()
        .args(["waterline", "--mesh"])
        .arg(&stl)
        .args(["--cutter", "ball", "--diameter", "2", "--z", "2", "-o"])
        .arg(&json)
        .output()
        .expect("run");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let loops: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).expect("json")).expect("parse");
    assert_eq!(loops["loops"][0]["outer"], true);
    assert!(loops["loops"][0]["points"].as_array().is_some_and(|p| p.len() > 8));
}

#[test]
fn waterline_rejects_bad_input_with_exit_code_1() {
    let dir = scratch("bad");
    let stl = dir.join("pyramid.stl");
    std::fs::write(&stl, pyramid_stl()).expect("stl");
    let cases: [(&[&str], &str); 4] = [
        (&["--z", "7"], "give levels in that range"),
        (&["--z", "abc"], "not a number"),
        (&["--z", "2", "--step", "0"], "grid step"),
        (&["--z", "2", "--chord-tolerance", "-1"], "chord_tolerance"),
    ];
    for (extra, message) in cases {
        let out = scallop()
            .args(["waterline", "--mesh"])
            .arg(&stl)
            .args(["--cutter", "ball", "--diameter", "2", "-o"])
            .arg(dir.join("x.csv"))
            .args(extra)
            .output()
            .expect("run");
        assert_eq!(out.status.code(), Some(1), "{extra:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(message), "{extra:?}: {err}");
    }
}
