//! Smoke tests of `scallop rough5`: the zero-tilt program of the closed
//! pocket is proven, posted for the UCP 710 (840D, TRAORI) and reported with
//! consistent metrics (spec 12.1 item 6); bad settings exit 1.

mod common;

use common::{rejected, scallop, scratch};

#[test]
fn rough5_writes_a_proven_program_and_its_metrics() {
    let dir = scratch("rough5");
    let out = scallop()
        .args(["rough5", "--part", "pocket", "--tilt", "zero", "--ap", "6", "--voxel", "1.5", "--step", "2"])
        .args(["--resolution", "1", "--json", "-o"])
        .arg(&dir)
        .output()
        .expect("run");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("report.json")).expect("report")).expect("json");
    let m = &report["metrics"];
    let num = |k: &str| m[k].as_f64().unwrap_or(f64::NAN);
    assert!(num("remaining_percent") > 0.0 && num("remaining_percent") < 100.0);
    assert!(num("gouge_depth_mm") <= 1.0);
    // Removal rate times time is the removed volume; the %/s rate is (100 - V_r) / t.
    let t = num("machining_time_s");
    assert!((num("removal_rate_mm3_s") * t - num("removed_volume_mm3")).abs() <= 1e-6 * num("removed_volume_mm3"));
    assert!((num("removal_rate_percent_s") * t - (100.0 - num("remaining_percent"))).abs() < 1e-9);
    let nc = std::fs::read_to_string(dir.join("program.nc")).expect("program");
    assert!(nc.contains("TRAORI"));
    assert!(report["post_error"].is_null());
}

#[test]
fn rough5_refuses_bad_settings() {
    let dir = scratch("rough5-bad");
    let out = scallop().args(["rough5", "--step", "0", "-o"]).arg(&dir).output().expect("run");
    assert!(rejected(&out).contains("--step"));
    let out = scallop().args(["rough5", "--flutes", "50", "-o"]).arg(&dir).output().expect("run");
    assert!(rejected(&out).contains("--stick-out"));
}
