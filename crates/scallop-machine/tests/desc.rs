//! Machine descriptions: every shipped file loads; validation errors name the field and the fix.

use scallop_machine::{Machine, MachineError};

fn ucp_text() -> String {
    std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../machines/mikron-ucp710.toml")).expect("file")
}

fn invalid_place(text: &str) -> String {
    match Machine::from_toml_str(text) {
        Err(MachineError::Invalid { place, fix, .. }) => {
            assert!(!fix.is_empty());
            place
        }
        other => panic!("expected Invalid, got {other:?}"),
    }
}

/// The place [`invalid_place`] names in the UCP 710 file with `from` replaced by `to`.
fn place_after(from: &str, to: &str) -> String {
    invalid_place(&ucp_text().replace(from, to))
}

#[test]
fn every_shipped_machine_loads_and_validates() {
    for name in Machine::builtin_names() {
        let m = Machine::builtin(name).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(m.axes().len(), 5);
        for a in m.axes() {
            assert!((a.direction.norm() - 1.0).abs() < 1e-15);
            if let Some((lo, hi)) = a.limits {
                assert!(lo < hi);
            }
            assert!(a.dynamics.vmax > 0.0 && a.dynamics.amax > 0.0 && a.dynamics.jmax > 0.0);
        }
    }
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../machines");
    let files = std::fs::read_dir(dir).expect("machines/").count();
    // The 5-axis machines and the 3-axis mills (`Described::builtin`, tests/mill.rs).
    assert_eq!(
        files,
        scallop_machine::Described::builtin_names().len(),
        "every file in machines/ is shipped as a builtin"
    );
}

#[test]
fn stroke_min_not_below_max() {
    assert_eq!(place_after("limits = [-30, 120]", "limits = [120, -30]"), "axes.A.limits");
}

#[test]
fn direction_must_be_unit() {
    assert_eq!(place_after("direction = [-1, 0, 0]", "direction = [-1, 0.1, 0]"), "axes.A.direction");
}

#[test]
fn dynamics_must_exist_and_be_positive() {
    assert_eq!(place_after("A = [90.0, 298.8, 1800]", "A = [90.0, -298.8, 1800]"), "dynamics.A");
    assert_eq!(place_after("A = [90.0, 298.8, 1800]\n", ""), "dynamics.A");
}

#[test]
fn chains_must_cover_every_axis_once() {
    assert_eq!(place_after("part = [\"A\", \"C\"]", "part = [\"A\"]"), "chains");
    assert_eq!(place_after("part = [\"A\", \"C\"]", "part = [\"A\", \"C\", \"Q\"]"), "chains.part");
}

#[test]
fn rotary_axes_need_a_pivot_and_must_not_be_parallel() {
    assert_eq!(place_after(", point = [0, 0, -100]", ""), "axes.A.point");
    assert_eq!(place_after("direction = [-1, 0, 0], point", "direction = [0, 0, 1], point"), "axes.C.direction");
}

#[test]
fn schema_and_unknown_fields() {
    assert_eq!(place_after("scallop.machine/1", "scallop.machine/9"), "schema");
    let t = ucp_text().replace("controlled_point = \"tip\"", "controlled_point = \"tip\"\nspeed = 3");
    match Machine::from_toml_str(&t) {
        Err(MachineError::Parse { line, message, .. }) => {
            let expected = t.lines().position(|l| l.starts_with("speed")).expect("inserted") + 1;
            assert_eq!(line, expected, "{message}");
            assert!(message.contains("speed"), "{message}");
        }
        other => panic!("{other:?}"),
    }
    let t = ucp_text().replace("nc_sign = 1, limits = [-30, 120]", "nc_sign = 1, limts = [-30, 120]");
    match Machine::from_toml_str(&t) {
        Err(e @ MachineError::Parse { .. }) => {
            let s = e.to_string();
            let line = t.lines().position(|l| l.contains("limts")).expect("typo") + 1;
            assert!(s.contains("limts") && s.contains(&format!("line {line} ")), "{s}");
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn four_axis_machines_are_unsupported_for_now() {
    let t = ucp_text().replace("part = [\"A\", \"C\"]", "part = [\"C\"]").replace(
        "A = { kind = \"rotary\", direction = [-1, 0, 0], point = [0, 0, -100], nc_sign = 1, limits = [-30, 120] }\n",
        "",
    );
    let t = t.replace("A = [90.0, 298.8, 1800]\n", "").replace("preferred_branch = { axis = \"A\", sign = 1 }\n", "");
    assert!(matches!(Machine::from_toml_str(&t), Err(MachineError::Unsupported { .. })));
}

#[test]
fn nan_inf_and_huge_frames_and_points_are_refused_with_their_key() {
    // Issue 21: these passed validation and reached the kinematics (a panic, or a program
    // "deviating inf" with no key named).
    let text = ucp_text();
    let frame = "part_frame = { origin = [0, 0, 0], rotation = [[1, 0, 0], [0, 1, 0], [0, 0, 1]] }";
    let cases = [
        (
            frame,
            "part_frame = { origin = [0, 0, 0], rotation = [[1, 0, 0], [0, nan, 0], [0, 0, 1]] }",
            "part_frame.rotation",
        ),
        (
            frame,
            "part_frame = { origin = [0, 0, 0], rotation = [[1, 0, 0], [0, 1, 0], [0, 0, inf]] }",
            "part_frame.rotation",
        ),
        (
            frame,
            "part_frame = { origin = [nan, 0, 0], rotation = [[1, 0, 0], [0, 1, 0], [0, 0, 1]] }",
            "part_frame.origin",
        ),
        (
            frame,
            "part_frame = { origin = [0, 2e5, 0], rotation = [[1, 0, 0], [0, 1, 0], [0, 0, 1]] }",
            "part_frame.origin",
        ),
        ("gauge_point = [0, 0, 0]", "gauge_point = [nan, 0, 0]", "spindle.gauge_point"),
        ("point = [0, 0, -100]", "point = [0, 0, nan]", "axes.A.point"),
        ("point = [0, 0, -100]", "point = [0, 0, 1e308]", "axes.A.point"),
    ];
    for (from, to, key) in cases {
        assert!(text.contains(from), "{from}");
        assert_eq!(invalid_place(&text.replacen(from, to, 1)), key, "{to}");
    }
    // At the bound itself a point is accepted.
    let edge = text.replacen("point = [0, 0, -100]", "point = [0, 0, -100000]", 1);
    assert!(Machine::from_toml_str(&edge).is_ok());
}
