//! 3-axis mills and machines as a job names them (`Described`): the shipped files load,
//! a 3-axis file is refused where 5-axis kinematics are needed, the travel check agrees
//! with the forward kinematics of the 5-axis machines and with a brute-force box test.

use proptest::prelude::*;
use scallop_geom::Point3;
use scallop_machine::{Described, Dialect, Joints, Kinematics, Machine, MachineError};

fn file(name: &str) -> String {
    std::fs::read_to_string(format!("{}/../../machines/{name}.toml", env!("CARGO_MANIFEST_DIR"))).expect("file")
}

#[test]
fn the_shipped_mills_load_with_their_controllers() {
    for (name, dialect, changer) in [
        ("generic-3axis", Dialect::Linuxcnc, true),
        ("linuxcnc-3axis", Dialect::Linuxcnc, true),
        ("fanuc-3axis", Dialect::Fanuc, true),
        ("grbl-3axis", Dialect::Grbl, false),
    ] {
        let m = Described::builtin(name).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(matches!(m, Described::ThreeAxis(_)), "{name}");
        assert_eq!(Described::from_toml_str(&file(name)).expect("file"), m);
        assert_eq!((m.nc().dialect, m.nc().tool_changer), (dialect, changer), "{name}");
        assert!(m.max_spindle_speed().is_some_and(|n| n > 0.0), "{name}");
        assert_eq!(m.linear_axes().iter().map(|a| a.name.as_str()).collect::<Vec<_>>(), ["X", "Y", "Z"]);
        // The part zero (the program's origin) and a point 5 mm above it are inside the travel.
        assert!(m.check_travel([Point3::origin(), Point3::new(0.0, 0.0, 5.0)]).is_ok(), "{name}");
    }
    for name in Machine::builtin_names() {
        assert!(matches!(Described::builtin(name), Ok(Described::FiveAxis(_))), "{name}");
    }
}

#[test]
fn a_mill_is_refused_where_five_axes_are_needed_and_unknown_names_list_the_shipped_ones() {
    match Machine::from_toml_str(&file("grbl-3axis")) {
        Err(e @ MachineError::Unsupported { .. }) => assert!(e.to_string().contains("`machine` key"), "{e}"),
        other => panic!("{other:?}"),
    }
    let e = Described::builtin("haas").unwrap_err().to_string();
    assert!(e.contains("grbl-3axis") && e.contains("mx330"), "{e}");
}

#[test]
fn bad_mill_values_name_their_field() {
    let grbl = file("grbl-3axis");
    for (from, to, place) in [
        ("max_speed = 24000", "max_speed = -1", "spindle.max_speed"),
        ("limits = [-80, 0]", "limits = [0, -80]", "axes.Z.limits"),
        ("Z = [33.3, 300, 3000]", "Z = [33.3, 0, 3000]", "dynamics.Z"),
    ] {
        let text = grbl.replace(from, to);
        assert_ne!(text, grbl, "{from}");
        match Described::from_toml_str(&text) {
            Err(MachineError::Invalid { place: p, .. }) => assert_eq!(p, place),
            other => panic!("{from}: {other:?}"),
        }
    }
    // Two linear axes: not a machine this version knows.
    let two = grbl.replace("Z = { kind = \"linear\", direction = [0, 0, 1], limits = [-80, 0] }\n", "");
    let two = two.replace("Z = [33.3, 300, 3000]\n", "");
    assert!(matches!(Described::from_toml_str(&two), Err(MachineError::Unsupported { .. })));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// With the rotaries at zero, the forward kinematics of the joint vector made of the
    /// linear words (over `nc_sign`) puts the tool tip at the point, on every 5-axis machine.
    #[test]
    fn linear_words_agree_with_the_forward_kinematics(x in -50.0..50.0f64, y in -50.0..50.0f64, z in -50.0..50.0f64) {
        for name in Machine::builtin_names() {
            let machine = Machine::builtin(name).expect("shipped");
            let d = Described::FiveAxis(machine.clone());
            let p = Point3::new(x, y, z);
            let w = d.linear_words(p);
            let axes = machine.axes();
            let q = Joints::from_fn(|i, _| if i < 3 { w[i] / axes[i].nc_sign } else { 0.0 });
            let pose = Kinematics::new(&machine, 0.0).fk(&q);
            prop_assert!((pose.tip - p).norm() < 1e-9, "{}: {:?} vs {:?}", name, pose.tip, p);
        }
    }

    /// The travel check accepts a program exactly when every point's words lie in every
    /// stroke (the brute-force box test), and its error names an axis that leaves it.
    #[test]
    fn the_travel_check_is_the_box_test(points in prop::collection::vec((-400.0..400.0f64, -400.0..400.0f64, -200.0..200.0f64), 1..6)) {
        let m = Described::builtin("linuxcnc-3axis").expect("shipped");
        let points: Vec<Point3> = points.into_iter().map(|(x, y, z)| Point3::new(x, y, z)).collect();
        let outside: Vec<&str> = m
            .linear_axes()
            .iter()
            .enumerate()
            .filter(|(i, a)| {
                let (lo, hi) = a.limits.expect("linear strokes");
                points.iter().any(|p| !(lo..=hi).contains(&m.linear_words(*p)[*i]))
            })
            .map(|(_, a)| a.name.as_str())
            .collect();
        match m.check_travel(points.iter().copied()) {
            Ok(()) => prop_assert!(outside.is_empty(), "{:?}", outside),
            Err(MachineError::OutOfTravel { axis, fix, .. }) => {
                prop_assert!(outside.contains(&axis.as_str()), "{} not in {:?}", axis, outside);
                prop_assert!(fix.contains(&axis));
            }
            Err(e) => prop_assert!(false, "{}", e),
        }
    }
}
