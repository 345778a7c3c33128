//! Smoke tests of `scallop engagement`: a slot and a side cut in a pocket read
//! their closed forms; gouges, bad pockets and missing files exit with 1.

mod common;

use common::{rejected, scallop, scratch};

const POCKET: &str = r#"{"units":"mm","rings":[[[0,0],[100,0],[100,60],[0,60]],[[70,40],[80,40],[80,50],[70,50]]]}"#;

/// A slot along y = 20 from x = 10 to 90, then a pass 1.2 mm beside it (0.2 D), in G-code.
fn program(second_y: f64) -> String {
    format!("G21 G90\nG0 Z5\nG0 X10 Y20\nG1 Z-1 F1000\nG1 X90\nG0 Z5\nG0 X10 Y{second_y}\nG1 Z-1\nG1 X84\nG0 Z5\nM2\n")
}

#[test]
fn engagement_reports_a_slot_and_a_side_cut() {
    let dir = scratch("engagement");
    std::fs::write(dir.join("p.json"), POCKET).expect("pocket");
    std::fs::write(dir.join("x.nc"), program(21.2)).expect("program");
    let out = scallop()
        .current_dir(&dir)
        .args(["engagement", "--pocket", "p.json", "--program", "x.nc", "--tool-diameter", "6"])
        .args(["--stepover", "0.2", "--json", "--moves", "moves.csv", "--feeds", "feeds.csv"])
        .output()
        .expect("run");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    // Per move: the slot's move reads 180 degrees, the side cut's the target,
    // the rapids nothing.
    let csv = std::fs::read_to_string(dir.join("moves.csv")).expect("moves");
    let rows: Vec<Vec<&str>> = csv.lines().skip(1).map(|l| l.split(',').collect()).collect();
    let phi_of = |x0: &str, x1: &str| {
        rows.iter()
            .find(|r| r[2] == x0 && r[4] == x1 && r[1] == "Feed")
            .and_then(|r| r[7].parse::<f64>().ok())
            .unwrap_or(f64::NAN)
    };
    assert!((phi_of("10", "90") - 180.0).abs() <= 1.0, "{csv}");
    assert!((phi_of("10", "84") - 53.13).abs() <= 1.5, "{csv}");
    assert!(rows.iter().filter(|r| r[1] == "Rapid").all(|r| r[7] == "0.00"), "{csv}");
    let f: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    let num = |k: &str| f[k].as_f64().unwrap_or(f64::NAN);
    assert!((num("target_deg") - 53.13).abs() < 0.01);
    // The slot past its 6 mm entry: 74 mm at 180 degrees (within a sample).
    assert!((num("slot_mm") - 74.0).abs() <= 0.1 + 1e-9, "{f}");
    assert!((num("phi_max_deg") - 180.0).abs() <= 1.0, "{f}");
    assert_eq!((f["entries"].as_u64(), f["retracts"].as_u64()), (Some(2), Some(2)));
    assert!(num("time_jerk_limited_s") >= num("time_length_over_feed_s") && num("time_length_over_feed_s") > 0.0);
    // Where the time goes: the moves' durations sum to the cycle time, and no
    // move is faster than the feed (5000 mm/min) but the rapids.
    let feeds = std::fs::read_to_string(dir.join("feeds.csv")).expect("feeds");
    let rows: Vec<Vec<&str>> = feeds.lines().skip(1).map(|l| l.split(',').collect()).collect();
    let total: f64 = rows.iter().map(|r| r[7].parse::<f64>().unwrap_or(f64::NAN)).sum();
    assert!((total - num("time_jerk_limited_s")).abs() <= 1e-3 * total + 1e-3, "{total} s\n{feeds}");
    let fastest = rows
        .iter()
        .filter(|r| r[1] != "Rapid" && r[1] != "Retract")
        .map(|r| r[9].parse::<f64>().unwrap_or(f64::NAN))
        .fold(0.0f64, f64::max);
    assert!(fastest > 0.0 && fastest <= 5000.0 / 60.0 + 0.01, "{fastest} mm/s\n{feeds}");
    // Into the island (its wall at y = 40; the tool reaches y = 41): a gouge, exit 1.
    std::fs::write(dir.join("g.nc"), program(38.0).replace("X84", "X95")).expect("program");
    let out = scallop()
        .current_dir(&dir)
        .args(["engagement", "--pocket", "p.json", "--program", "g.nc", "--tool-diameter", "6", "--stepover", "0.2"])
        .output()
        .expect("run");
    let err = rejected(&out);
    assert!(err.contains("gouge"), "{err}");
}

#[test]
fn engagement_rejects_bad_input_with_exit_code_1() {
    let dir = scratch("engagement-bad");
    std::fs::write(dir.join("x.nc"), program(21.2)).expect("program");
    std::fs::write(dir.join("inch.json"), r#"{"units":"in","rings":[[[0,0],[1,0],[1,1]]]}"#).expect("pocket");
    std::fs::write(dir.join("two.json"), r#"{"units":"mm","rings":[[[0,0],[1,0]]]}"#).expect("pocket");
    for (pocket, why) in [("inch.json", "units"), ("two.json", "fewer than 3"), ("missing.json", "cannot read")] {
        let out = scallop()
            .current_dir(&dir)
            .args(["engagement", "--pocket", pocket, "--program", "x.nc", "--tool-diameter", "6", "--stepover", "0.2"])
            .output()
            .expect("run");
        assert!(rejected(&out).contains(why), "{pocket}");
    }
}
