//! Smoke tests of `scallop rough5`: the zero-tilt program of the closed
//! pocket is proven, posted for the UCP 710 (840D, TRAORI) and reported with
//! consistent metrics (spec 12.1 item 6); the six orientation cases of the
//! thesis (Ch. 3 §2.3) run on one pass with their pitch traces and times;
//! the 3+2 baseline (`--baseline 3+2`) is proven and posted with its setups;
//! bad settings exit 1.

mod common;

use common::{read_json, rejected, scallop, scratch, succeeded};

#[test]
fn rough5_writes_a_proven_program_and_its_metrics() {
    let dir = scratch("rough5");
    succeeded(
        scallop()
            .args(["rough5", "--part", "pocket", "--tilt", "zero", "--ap", "6", "--voxel", "1.5", "--step", "2"])
            .args(["--resolution", "1", "--json", "--block-times", "-o"])
            .arg(&dir),
    );
    let report = read_json(&dir.join("report.json"));
    let m = &report["metrics"];
    // The machine time by role and kind adds up to the machine time; block_times.csv has every
    // block but the first (the start).
    let shares = report["time_breakdown"].as_array().expect("time_breakdown");
    let summed: f64 = shares.iter().map(|s| s["time_s"].as_f64().unwrap_or(f64::NAN)).sum();
    let machining = m["machining_time_s"].as_f64().unwrap_or(f64::NAN);
    assert!((summed - machining).abs() <= 1e-6 * machining, "{summed} against {machining}");
    assert!(shares.iter().any(|s| s["label"] == "cut feed"), "{shares:?}");
    let csv = std::fs::read_to_string(dir.join("block_times.csv")).expect("block_times.csv");
    assert_eq!(csv.lines().count() as u64, report["blocks"].as_u64().unwrap_or(0), "a header and one line per block");
    let num = |k: &str| m[k].as_f64().unwrap_or(f64::NAN);
    assert!(num("remaining_percent") > 0.0 && num("remaining_percent") < 100.0);
    assert!(num("gouge_depth_mm") <= 1.0);
    // Removal rate times time is the removed volume; the %/s rate is (100 - V_r) / t.
    let t = num("machining_time_s");
    assert!((num("removal_rate_mm3_s") * t - num("removed_volume_mm3")).abs() <= 1e-6 * num("removed_volume_mm3"));
    assert!((num("removal_rate_percent_s") * t - (100.0 - num("remaining_percent"))).abs() < 1e-9);
    // The minimum stick-out lies between the flutes (30 mm) and the tool's 41 mm; a move sets it
    // unless the flutes alone suffice.
    let stick = num("min_stick_out_mm");
    assert!((30.0..=41.0).contains(&stick), "{stick}");
    assert_eq!(m["min_stick_out_move"].is_null(), stick <= 30.0, "{m}");
    let nc = std::fs::read_to_string(dir.join("program.nc")).expect("program");
    assert!(nc.contains("TRAORI"));
    assert!(report["post_error"].is_null());
}

#[test]
fn rough5_baseline_3plus2_is_proven_posted_and_reports_its_setups() {
    let dir = scratch("rough5-3plus2");
    succeeded(
        scallop()
            .args(["rough5", "--part", "pocket", "--baseline", "3+2", "--ap", "6", "--resolution", "1", "--json"])
            .arg("-o")
            .arg(&dir),
    );
    let report = read_json(&dir.join("report.json"));
    let num = |k: &str| report["metrics"][k].as_f64().unwrap_or(f64::NAN);
    assert!(num("remaining_percent") > 0.0 && num("remaining_percent") < 100.0);
    assert!(num("gouge_depth_mm") <= 1.0);
    assert!(num("machining_time_s") > 0.0);
    let setups = report["setups"].as_array().expect("setups");
    // The z-level setup (axis +Z) first, then at least one tilted rest setup.
    assert!(setups.len() >= 2, "{setups:?}");
    assert!(setups[0]["tilt_deg"].as_f64().unwrap_or(f64::NAN).abs() < 1e-9);
    assert!(setups[1..].iter().all(|u| u["tilt_deg"].as_f64().unwrap_or(0.0) > 1.0));
    assert!(std::fs::read_to_string(dir.join("program.nc")).expect("program").contains("TRAORI"));
    let out = scallop().args(["rough5", "--baseline", "4+1", "-o"]).arg(&dir).output().expect("run");
    assert!(!out.status.success());
}

#[test]
fn rough5_refuses_bad_settings() {
    let dir = scratch("rough5-bad");
    let out = scallop().args(["rough5", "--step", "0", "-o"]).arg(&dir).output().expect("run");
    assert!(rejected(&out).contains("--step"));
    let out = scallop().args(["rough5", "--flutes", "50", "-o"]).arg(&dir).output().expect("run");
    assert!(rejected(&out).contains("--stick-out"));
    for cutting in [["2.5", "0.08", "15000"], ["2", "0", "15000"]] {
        let out = scallop().args(["rough5", "--cutting"]).args(cutting).arg("-o").arg(&dir).output().expect("run");
        assert!(rejected(&out).contains("--cutting"));
    }
}

#[test]
fn rough5_orientation_cases_report_six_pitch_traces_and_times() {
    let dir = scratch("rough5-cases");
    succeeded(
        scallop()
            .args(["rough5", "--part", "pocket", "--orientation-cases", "--ap", "6", "--voxel", "1.5", "--step", "2"])
            .args(["--json", "-o"])
            .arg(&dir),
    );
    let summary = read_json(&dir.join("orientation.json"));
    let cases = summary["cases"].as_array().expect("cases");
    assert_eq!(cases.len(), 6);
    for c in cases {
        let num = |k: &str| c[k].as_f64().unwrap_or(f64::NAN);
        // Eq. 3.17-3.19 as corrected hold at the solution; F is not above SPU's.
        assert!(num("constraint_violation") <= 1e-9, "{c}");
        assert!(num("objective") <= num("spu_objective") + 1e-12, "{c}");
        assert!(num("machining_time_s") > 0.0 && c["points"].as_u64().unwrap_or(0) > 10, "{c}");
    }
    assert!(cases[0]["time_gain_percent"].as_f64().unwrap_or(f64::NAN).abs() < 1e-12);
    let csv = std::fs::read_to_string(dir.join("orientation.csv")).expect("csv");
    for case in 1..=6 {
        let rows = csv.lines().filter(|l| l.starts_with(&format!("{case},"))).count() as u64;
        assert_eq!(rows, cases[case - 1]["points"].as_u64().unwrap_or(0), "case {case}");
    }
}
