//! Smoke tests of `scallop pocket`: a rectangle with an island cleared to
//! G-code (with arcs) and CL, the summary, and bad input (exit code 1).

#[allow(dead_code, reason = "the helpers other test files use")]
mod common;

use common::{scallop, scratch};

const REGION: &str =
    r#"{"units": "mm", "rings": [[[0, 0], [40, 0], [40, 30], [0, 30]], [[17, 12], [23, 12], [23, 18], [17, 18]]]}"#;

#[test]
fn pocket_writes_gcode_and_cl() {
    let dir = scratch("pocket");
    let region = dir.join("pocket.json");
    std::fs::write(&region, REGION).expect("region");
    let out_dir = dir.join("out");
    let out = scallop()
        .args(["pocket", "--region"])
        .arg(&region)
        .args(["--tool-diameter", "6", "--stepover", "0.2", "--json", "-o"])
        .arg(&out_dir)
        .output()
        .expect("run");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json summary");
    assert!(summary["passes"].as_u64().is_some_and(|p| p > 3), "{summary}");
    assert!(summary["arcs"].as_u64().is_some_and(|a| a > 0), "{summary}");
    let program = std::fs::read_to_string(out_dir.join("program.nc")).expect("program");
    assert!(program.contains("G2") || program.contains("G3"));
    let cl = std::fs::read_to_string(out_dir.join("toolpath.csv")).expect("cl");
    // Every cutting location keeps the tool centre 3 mm inside the wall and outside the island.
    for line in cl.lines().skip(1) {
        let v: Vec<&str> = line.split(',').collect();
        let (x, y, z): (f64, f64, f64) = (v[1].parse().unwrap(), v[2].parse().unwrap(), v[3].parse().unwrap());
        if z < 0.0 {
            assert!((3.0 - 1e-6..=37.0 + 1e-6).contains(&x) && (3.0 - 1e-6..=27.0 + 1e-6).contains(&y), "{line}");
            let dx = (x - 20.0).abs() - 3.0;
            let dy = (y - 15.0).abs() - 3.0;
            let outside = dx.max(0.0).hypot(dy.max(0.0));
            assert!(outside >= 3.0 - 1e-3, "{line}: {outside}");
        }
    }
}

#[test]
fn pocket_rejects_bad_input_with_exit_code_1() {
    let dir = scratch("pocket-bad");
    let region = dir.join("pocket.json");
    std::fs::write(&region, REGION).expect("region");
    for args in [
        vec!["--tool-diameter", "0"],
        vec!["--tool-diameter", "6", "--stepover", "0.9"],
        vec!["--tool-diameter", "6", "--pattern", "spiral"],
        vec!["--tool-diameter", "50"],
    ] {
        let out = scallop()
            .args(["pocket", "--region"])
            .arg(&region)
            .args(&args)
            .args(["-o"])
            .arg(dir.join("o"))
            .output()
            .expect("run");
        assert_eq!(out.status.code(), Some(1), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    }
    std::fs::write(&region, r#"{"units": "mm", "rings": []}"#).expect("region");
    let out = scallop()
        .args(["pocket", "--region"])
        .arg(&region)
        .args(["--tool-diameter", "6", "-o"])
        .arg(dir.join("o"))
        .output()
        .expect("run");
    assert_eq!(out.status.code(), Some(1));
    assert!(!dir.join("o").join("program.nc").exists());
}
