//! Helpers shared by the integration tests.
#![allow(dead_code, reason = "each test binary uses a subset")]

use scallop_machine::{Joints, Kinematics, Machine};

/// Degrees to radians.
pub fn deg(d: f64) -> f64 {
    d.to_radians()
}

/// `assert!((a - b).abs() <= eps)` with a message.
#[macro_export]
macro_rules! assert_near {
    ($a:expr, $b:expr, $eps:expr) => {{
        let (a, b, eps): (f64, f64, f64) = ($a, $b, $eps);
        assert!(
            (a - b).abs() <= eps,
            "{} = {a} differs from {} = {b} by more than {eps}",
            stringify!($a),
            stringify!($b)
        );
    }};
}

/// Parses a test machine.
pub fn machine(text: &str) -> Machine {
    match Machine::from_toml_str(text) {
        Ok(m) => m,
        Err(e) => panic!("test machine does not load: {e}"),
    }
}

/// MX330 with d = 50, l = 100 (spec 7.2).
pub fn mx330() -> Kinematics {
    Kinematics::new(&Machine::builtin("mx330").expect("shipped"), 100.0)
}

/// MX330 joints from the spec's (C, A, X, Y, Z) in degrees and mm.
pub fn mx_q(c: f64, a: f64, x: f64, y: f64, z: f64) -> Joints {
    Joints::new(x, y, z, deg(a), deg(c))
}

/// `a == b` modulo 2 pi on the rotaries (indices 3, 4) and exactly on the rest, within eps.
pub fn same_joints_mod_turn(a: &Joints, b: &Joints, eps: f64) -> bool {
    (0..5).all(|i| {
        let d = a[i] - b[i];
        if i >= 3 {
            let r = d.rem_euclid(std::f64::consts::TAU);
            r.min(std::f64::consts::TAU - r) <= eps
        } else {
            d.abs() <= eps
        }
    })
}

/// A synthetic machine (spec 2.6): X, Y, Z tool-side +e, W = M, a0 = e_z, g0 = 0.
/// `rotaries` are `(name, direction, point)`, `part`/`tool` the rotary chains after XYZ.
pub fn synthetic(rotaries: &[(&str, [f64; 3], [f64; 3])], part: &[&str], tool_rot: &[&str]) -> Machine {
    let mut s = String::from(
        "schema = \"scallop.machine/1\"\nname = \"synthetic\"\nspindle = { gauge_point = [0, 0, 0], tool_axis = [0, 0, 1] }\n",
    );
    let list = |v: &[&str]| v.iter().map(|n| format!("\"{n}\"")).collect::<Vec<_>>().join(", ");
    let mut tool = vec!["X", "Y", "Z"];
    tool.extend_from_slice(tool_rot);
    s += &format!("[chains]\npart = [{}]\ntool = [{}]\n[axes]\n", list(part), list(&tool));
    s += "X = { kind = \"linear\", direction = [1, 0, 0], limits = [-1000, 1000] }\n";
    s += "Y = { kind = \"linear\", direction = [0, 1, 0], limits = [-1000, 1000] }\n";
    s += "Z = { kind = \"linear\", direction = [0, 0, 1], limits = [-1000, 1000] }\n";
    for (n, d, p) in rotaries {
        s += &format!(
            "{n} = {{ kind = \"rotary\", direction = [{:?}, {:?}, {:?}], point = [{:?}, {:?}, {:?}], continuous = true }}\n",
            d[0], d[1], d[2], p[0], p[1], p[2]
        );
    }
    s += "[dynamics]\nX = [100, 1000, 10000]\nY = [100, 1000, 10000]\nZ = [100, 1000, 10000]\n";
    for (n, _, _) in rotaries {
        s += &format!("{n} = [90, 360, 3600]\n");
    }
    machine(&s)
}
