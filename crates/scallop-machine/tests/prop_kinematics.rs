//! Property tests: FK(IK(pose)) = pose on both branches, IK(FK(q)) recovers q modulo
//! branch and 2 pi, the analytic Jacobian equals central differences, unwrapping never
//! jumps more than pi; on every shipped machine and on random machines of every family
//! (random pivots within +-100 mm, random signs, setups and linear-axis distribution).

mod common;

use common::{machine, same_joints_mod_turn};
use proptest::prelude::*;
use scallop_geom::nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use scallop_geom::{Point3, Vec3};
use scallop_machine::plan::unwrap_angle;
use scallop_machine::{Joints, Kinematics, Machine, Solver};

const FK_IK_TOL: f64 = 1e-9;

/// Random joints inside the strokes (rotaries in (-pi, pi] for continuous axes).
fn joints_in_strokes(m: &Machine, u: &[f64; 5]) -> Joints {
    let mut q = Joints::zeros();
    for (i, a) in m.axes().iter().enumerate() {
        let (lo, hi) = a.joint_limits().unwrap_or((-std::f64::consts::PI, std::f64::consts::PI));
        let (lo, hi) = (lo.max(-1000.0), hi.min(1000.0));
        q[i] = lo + (hi - lo) * u[i];
    }
    q
}

fn assert_fk_ik(k: &Kinematics, q: &Joints, hold: &Joints) -> Result<(), TestCaseError> {
    let pose = k.fk(q);
    let sols = k.ik(&pose, hold).map_err(|e| TestCaseError::fail(e.to_string()))?;
    prop_assert_eq!(sols.as_slice().len(), 2);
    for s in sols.as_slice() {
        let back = k.fk(&s.joints);
        prop_assert!((back.tip - pose.tip).norm() < FK_IK_TOL, "tip {:?} vs {:?}", back.tip, pose.tip);
        let axis_tol = if s.at_pole { k.machine().pole_eps() } else { FK_IK_TOL };
        prop_assert!((back.axis - pose.axis).norm() < axis_tol, "axis {:?} vs {:?}", back.axis, pose.axis);
    }
    let v = k.part_frame().rotation * pose.axis;
    let rho = k.machine().axes()[k.pole_axis()].direction.cross(&v).norm();
    if rho >= 1e-3 {
        prop_assert!(
            sols.as_slice().iter().any(|s| same_joints_mod_turn(&s.joints, q, FK_IK_TOL)),
            "{:?} not among {:?}",
            q,
            sols
        );
    }
    Ok(())
}

fn assert_jacobian(k: &Kinematics, q: &Joints) -> Result<(), TestCaseError> {
    let j = k.jacobian(q);
    let h = 1e-6;
    let o = k.fk(q).axis;
    for c in 0..5 {
        let mut qp = *q;
        let mut qm = *q;
        qp[c] += h;
        qm[c] -= h;
        let (pp, pm) = (k.fk(&qp), k.fk(&qm));
        let dp = (pp.tip - pm.tip) / (2.0 * h);
        let dor = (pp.axis - pm.axis) / (2.0 * h);
        let jp = Vec3::new(j[(3, c)], j[(4, c)], j[(5, c)]);
        let jo = Vec3::new(j[(0, c)], j[(1, c)], j[(2, c)]).cross(&o);
        prop_assert!((jp - dp).norm() <= 1e-6 * (1.0 + dp.norm()), "dP/dq{c}: {jp:?} vs {dp:?}");
        prop_assert!((jo - dor).norm() <= 1e-6 * (1.0 + dor.norm()), "dO/dq{c}: {jo:?} vs {dor:?}");
    }
    Ok(())
}

/// A random machine of one family (0 TT-AC, 1 TT-BC, 2 HH-CA, 3 HH-CB, 4 HT-BC, 5 HT-AC,
/// 6 generic nutating head), pivots in +-100 mm, signs from `signs`, linear axes moved to
/// the part chain by the bits of `linear_on_part`.
fn random_machine(family: usize, pivots: &[f64; 6], signs: [bool; 2], linear_on_part: u8) -> Machine {
    let s = |b: bool| if b { 1.0 } else { -1.0 };
    let (s1, s2) = (s(signs[0]), s(signs[1]));
    let h = std::f64::consts::FRAC_1_SQRT_2;
    // (primary name, dir, secondary name, dir, primary on part, secondary on part)
    let (n1, d1, n2, d2, p1, p2) = match family {
        0 => ("A", [s1, 0.0, 0.0], "C", [0.0, 0.0, s2], true, true),
        1 => ("B", [0.0, s1, 0.0], "C", [0.0, 0.0, s2], true, true),
        2 => ("C", [0.0, 0.0, s1], "A", [s2, 0.0, 0.0], false, false),
        3 => ("C", [0.0, 0.0, s1], "B", [0.0, s2, 0.0], false, false),
        4 => ("C", [0.0, 0.0, s1], "B", [0.0, s2, 0.0], true, false),
        5 => ("C", [0.0, 0.0, s1], "A", [s2, 0.0, 0.0], true, false),
        _ => ("C", [0.0, 0.0, s1], "B", [0.0, -h * s2, h], false, false),
    };
    let lin = ["X", "Y", "Z"];
    let mut part: Vec<&str> =
        lin.iter().enumerate().filter(|(i, _)| linear_on_part & (1 << i) != 0).map(|(_, n)| *n).collect();
    let mut tool: Vec<&str> =
        lin.iter().enumerate().filter(|(i, _)| linear_on_part & (1 << i) == 0).map(|(_, n)| *n).collect();
    for (n, on_part) in [(n1, p1), (n2, p2)] {
        if on_part { part.push(n) } else { tool.push(n) }
    }
    let list = |v: &[&str]| v.iter().map(|n| format!("\"{n}\"")).collect::<Vec<_>>().join(", ");
    let mut t = format!(
        "schema = \"scallop.machine/1\"\nname = \"random\"\nspindle = {{ gauge_point = [0, 0, 0], tool_axis = [0, 0, 1] }}\n[chains]\npart = [{}]\ntool = [{}]\n[axes]\n",
        list(&part),
        list(&tool)
    );
    for (n, d) in [("X", [1, 0, 0]), ("Y", [0, 1, 0]), ("Z", [0, 0, 1])] {
        t += &format!(
            "{n} = {{ kind = \"linear\", direction = [{}, {}, {}], limits = [-5000, 5000] }}\n",
            d[0], d[1], d[2]
        );
    }
    for (n, d, p) in [(n1, d1, &pivots[0..3]), (n2, d2, &pivots[3..6])] {
        t += &format!(
            "{n} = {{ kind = \"rotary\", direction = [{:?}, {:?}, {:?}], point = [{:?}, {:?}, {:?}], continuous = true }}\n",
            d[0], d[1], d[2], p[0], p[1], p[2]
        );
    }
    t += &format!("[dynamics]\nX = [1, 1, 1]\nY = [1, 1, 1]\nZ = [1, 1, 1]\n{n1} = [1, 1, 1]\n{n2} = [1, 1, 1]\n");
    machine(&t)
}

fn setup(r: &[f64; 6]) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(r[0], r[1], r[2]),
        UnitQuaternion::from_scaled_axis(Vector3::new(r[3], r[4], r[5])),
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1000, ..ProptestConfig::default() })]

    #[test]
    fn fk_ik_on_every_shipped_machine(which in 0usize..7, u in prop::array::uniform5(0.0..1.0f64), l in 0.0..150.0f64) {
        let m = Machine::builtin(Machine::builtin_names()[which]).expect("shipped");
        let k = Kinematics::new(&m, l);
        let q = joints_in_strokes(&m, &u);
        assert_fk_ik(&k, &q, &q)?;
        assert_fk_ik(&k.clone().with_solver(Solver::Generic), &q, &q)?;
        assert_jacobian(&k, &q)?;
        // The numeric fallback from a nearby seed.
        let seed = q + Joints::new(0.5, -0.5, 0.5, 0.02, -0.02);
        let pose = k.fk(&q);
        let sol = k.ik_numeric(&pose, &seed).map_err(|e| TestCaseError::fail(e.to_string()))?;
        let back = k.fk(&sol);
        prop_assert!((back.tip - pose.tip).norm() < FK_IK_TOL && (back.axis - pose.axis).norm() < FK_IK_TOL);
    }

    #[test]
    fn k2_fk_ik_random_families(
        family in 0usize..7,
        pivots in prop::array::uniform6(-100.0..100.0f64),
        signs in prop::array::uniform2(any::<bool>()),
        linear_on_part in 0u8..8,
        frame in prop::array::uniform6(-1.5..1.5f64),
        q in prop::array::uniform5(-3.0..3.0f64),
        l in 0.0..120.0f64,
    ) {
        let m = random_machine(family, &pivots, signs, linear_on_part);
        let mut f = frame;
        for v in &mut f[0..3] { *v *= 60.0; }
        let k = Kinematics::new(&m, l).with_part_frame(setup(&f));
        if family < 6 {
            prop_assert!(matches!(k.solver(), Solver::Closed(_)), "family {} -> {:?}", family, k.solver());
        }
        let mut q = Joints::new(q[0] * 50.0, q[1] * 50.0, q[2] * 50.0, q[3], q[4]);
        if family == 6 {
            q[4] = q[4].abs().min(3.0); // nutating tilt: any value, both signs reach the cone
        }
        assert_fk_ik(&k, &q, &q)?;
        assert_jacobian(&k, &q)?;
    }

    #[test]
    fn linear_axis_carried_by_a_rotary_generic_and_numeric(
        q in prop::array::uniform5(-1.0..1.0f64),
        kick in prop::array::uniform5(-0.05..0.05f64),
    ) {
        // Head-head whose C head carries the Z ram: no closed position step.
        let m = machine(concat!(
            "schema = \"scallop.machine/1\"\nname = \"z-on-c\"\n",
            "spindle = { gauge_point = [0, 0, 0], tool_axis = [0, 0, 1] }\n",
            "[chains]\npart = []\ntool = [\"X\", \"Y\", \"C\", \"Z\", \"A\"]\n[axes]\n",
            "X = { kind = \"linear\", direction = [1, 0, 0], limits = [-500, 500] }\n",
            "Y = { kind = \"linear\", direction = [0, 1, 0], limits = [-500, 500] }\n",
            "Z = { kind = \"linear\", direction = [0, 0, 1], limits = [-500, 500] }\n",
            "A = { kind = \"rotary\", direction = [1, 0, 0], point = [0, 20, 150], limits = [-100, 100] }\n",
            "C = { kind = \"rotary\", direction = [0, 0, 1], point = [5, -3, 0], continuous = true }\n",
            "[dynamics]\nX = [1, 1, 1]\nY = [1, 1, 1]\nZ = [1, 1, 1]\nA = [1, 1, 1]\nC = [1, 1, 1]\n",
        ));
        let k = Kinematics::new(&m, 20.0);
        prop_assert_eq!(k.solver(), scallop_machine::Solver::Closed(scallop_machine::Family::HhCa));
        let q = Joints::new(q[0] * 100.0, q[1] * 100.0, q[2] * 100.0, q[3] + 0.2, q[4] * 3.0);
        let pose = k.fk(&q);
        assert_fk_ik(&k, &q, &q)?;
        assert_fk_ik(&k.clone().with_solver(Solver::Generic), &q, &q)?;
        let k = k.with_solver(Solver::Numeric);
        let seed = q + Joints::new(kick[0] * 100.0, kick[1] * 100.0, kick[2] * 100.0, kick[3], kick[4]);
        let sol = k.ik_numeric(&pose, &seed).map_err(|e| TestCaseError::fail(e.to_string()))?;
        let back = k.fk(&sol);
        prop_assert!((back.tip - pose.tip).norm() < FK_IK_TOL && (back.axis - pose.axis).norm() < FK_IK_TOL);
        // Through `ik`, seeded with the previous joints.
        for s in k.ik(&pose, &seed).map_err(|e| TestCaseError::fail(e.to_string()))?.as_slice() {
            let back = k.fk(&s.joints);
            prop_assert!((back.tip - pose.tip).norm() < FK_IK_TOL && (back.axis - pose.axis).norm() < FK_IK_TOL);
        }
        assert_jacobian(&k, &q)?;
    }

    #[test]
    fn unwrapping_never_jumps_more_than_pi(raw in -3.2..3.2f64, previous in -100.0..100.0f64) {
        let (v, unwound) = unwrap_angle(raw, previous, None).expect("no limits");
        prop_assert!(!unwound);
        prop_assert!((v - previous).abs() <= std::f64::consts::PI + 1e-12);
        let turns = (v - raw) / std::f64::consts::TAU;
        prop_assert!((turns - turns.round()).abs() < 1e-9);
    }

    #[test]
    fn unwrapping_with_limits_stays_inside(raw in -3.2..3.2f64, previous in -6.0..6.0f64, lo in -7.0..0.0f64, width in 0.5..14.0f64) {
        let limits = (lo, lo + width);
        if let Some((v, _)) = unwrap_angle(raw, previous, Some(limits)) {
            prop_assert!(v >= limits.0 - 1e-9 && v <= limits.1 + 1e-9);
        } else {
            prop_assert!(width < std::f64::consts::TAU);
        }
    }
}

#[test]
fn poses_sampled_in_pose_space_mx330() {
    // Reachable poses drawn directly (tip anywhere near the table, tilt <= 120 deg).
    let k = Kinematics::new(&Machine::builtin("mx330").expect("shipped"), 100.0);
    let mut rng = scallop_geom::rng::SplitMix64::new(0x9e37_79b9_7f4a_7c15);
    let mut rnd = || rng.unit();
    for _ in 0..2000 {
        let tilt = 120f64.to_radians() * rnd();
        let az = std::f64::consts::TAU * rnd();
        let axis = Vec3::new(tilt.sin() * az.cos(), tilt.sin() * az.sin(), tilt.cos());
        let tip = Point3::new(100.0 * rnd() - 50.0, 100.0 * rnd() - 50.0, 60.0 * rnd());
        let pose = scallop_machine::Pose::new(tip, axis);
        for s in k.ik(&pose, &Joints::zeros()).expect("reachable").as_slice() {
            let back = k.fk(&s.joints);
            assert!((back.tip - tip).norm() < FK_IK_TOL && (back.axis - pose.axis).norm() < FK_IK_TOL);
        }
    }
}
