//! Acceptance tests of spec kinematics.md section 7 that concern kinematics, named
//! after the spec's ids, with the spec's tolerances.
#![allow(clippy::approx_constant, reason = "the spec's values as printed (6 decimals)")]
#![allow(clippy::type_complexity, reason = "test tables written as the spec prints them")]

mod common;

use common::{deg, mx_q, mx330, same_joints_mod_turn, synthetic};
use scallop_geom::{Point3, Vec3};
use scallop_machine::plan::{Event, select, solve_path, unwrap_angle};
use scallop_machine::{Branch, Iso841, Joints, Kinematics, Machine, MachineError, Pose, Solver};

fn check_pose(k: &Kinematics, q: &Joints, p: [f64; 3], o: [f64; 3], tol_p: f64, tol_o: f64) {
    let pose = k.fk(q);
    for i in 0..3 {
        assert_near!(pose.tip[i], p[i], tol_p);
        assert_near!(pose.axis[i], o[i], tol_o);
    }
}

/// The IK solutions of `fk(q)` contain `expected` (mod 2 pi) within 1e-9; returns the other one.
fn ik_contains(k: &Kinematics, q: &Joints, expected: &Joints) -> Joints {
    let sols = k.ik(&k.fk(q), q).expect("reachable");
    let s = sols.as_slice();
    let hit = s.iter().position(|x| same_joints_mod_turn(&x.joints, expected, 1e-9));
    let Some(i) = hit else { panic!("{expected:?} not among {s:?}") };
    s[1 - i.min(1)].joints
}

// ---------------------------------------------------------------- 7.2 test vectors

#[test]
fn vectors_mx330_forward_and_both_branches() {
    let k = mx330();
    // (C, A, X, Y, Z) -> P, O; branch (-), branch (+), (+) within strokes?
    let rows: [((f64, f64, f64, f64, f64), [f64; 3], [f64; 3], (f64, f64, f64, f64, f64), bool); 4] = [
        (
            (30.0, -45.0, 10.0, 20.0, 150.0),
            [-51.0867, -68.4847, 6.5685],
            [-0.353553, -0.612372, 0.707107],
            (-150.0, 45.0, -10.0, -20.0, 150.0),
            false,
        ),
        (
            (-120.0, -90.0, -25.0, 40.0, 200.0),
            [117.4038, 96.6506, -90.0],
            [0.866025, 0.5, 0.0],
            (60.0, 90.0, 25.0, -40.0, 200.0),
            false,
        ),
        (
            (200.0, 5.0, 5.0, -5.0, 120.0),
            [0.9082, -12.1237, 19.2979],
            [-0.029809, -0.0819, 0.996195],
            (20.0, -5.0, -5.0, 5.0, 120.0),
            true,
        ),
        (
            (90.0, -125.0, 0.0, 0.0, 100.0),
            [-40.9576, 0.0, -78.6788],
            [-0.819152, 0.0, -0.573576],
            (-90.0, 125.0, 0.0, 0.0, 100.0),
            false,
        ),
    ];
    for ((c, a, x, y, z), p, o, other, other_ok) in rows {
        let q = mx_q(c, a, x, y, z);
        check_pose(&k, &q, p, o, 1e-4, 1e-6);
        let (oc, oa, ox, oy, oz) = other;
        let got_other = ik_contains(&k, &q, &q);
        assert!(same_joints_mod_turn(&got_other, &mx_q(oc, oa, ox, oy, oz), 1e-9), "{got_other:?}");
        let in_range = scallop_machine::plan::check_limits(k.machine(), &got_other, None).is_ok();
        assert_eq!(in_range, other_ok, "row C {c} A {a}");
    }
}

#[test]
fn vectors_mx330_pole_row() {
    let k = mx330();
    let q = mx_q(0.0, 0.0, 0.0, 0.0, 100.0);
    check_pose(&k, &q, [0.0, 0.0, 0.0], [0.0, 0.0, 1.0], 1e-12, 1e-15);
    let hold = mx_q(37.0, 0.0, 0.0, 0.0, 0.0);
    let sols = k.ik(&k.fk(&q), &hold).expect("pole is reachable");
    for s in sols.as_slice() {
        assert!(s.at_pole);
        assert_near!(s.joints[4], deg(37.0), 1e-15);
        assert_near!(s.joints[2], 100.0, 1e-12);
        assert_near!(s.joints[3], 0.0, 1e-15);
    }
}

#[test]
fn vectors_mx330_printed_v8_z_is_wrong_unless_a_is_zero() {
    // E17: printed Z = Px sA sC + Py sA cC + (Pz + d) - (d - l); correct has cA (Pz + d) - d + l.
    let k = mx330();
    for ((c, a, x, y, z), printed) in [
        ((30.0, -45.0, 10.0, 20.0, 150.0), 166.5685),
        ((-120.0, -90.0, -25.0, 40.0, 200.0), 160.0),
        ((200.0, 5.0, 5.0, -5.0, 120.0), 120.2637),
        ((90.0, -125.0, 0.0, 0.0, 100.0), 54.8717),
    ] {
        let q = mx_q(c, a, x, y, z);
        let p = k.fk(&q).tip;
        let (sa, sc, cc) = (deg(a).sin(), deg(c).sin(), deg(c).cos());
        let v8 = p.x * sa * sc + p.y * sa * cc + (p.z + 50.0) - (50.0 - 100.0);
        assert_near!(v8, printed, 1e-4);
    }
}

#[test]
fn vectors_ucp710() {
    let k = Kinematics::new(&Machine::builtin("ucp710").expect("shipped"), 0.0);
    // (A, C) printed, xyz, O, P, branch A > 0 (A, C mod 360), other (A, C; x, y), other in range
    type Row = ((f64, f64), [f64; 3], [f64; 3], [f64; 3], (f64, f64), (f64, f64, f64, f64), bool);
    let rows: [Row; 5] = [
        (
            (30.2, -71.5),
            [0.0; 3],
            [-0.477026, -0.159611, 0.864275],
            [-47.7026, -15.9611, -13.5725],
            (30.2, 288.5),
            (-30.2, 108.5, 0.0, 0.0),
            false,
        ),
        (
            (17.2, -148.2),
            [0.0; 3],
            [-0.155825, 0.251320, 0.955278],
            [-15.5825, 25.1320, -4.4722],
            (17.2, 211.8),
            (-17.2, 31.8, 0.0, 0.0),
            true,
        ),
        (
            (38.8, -112.5),
            [0.0; 3],
            [-0.578906, 0.239791, 0.779338],
            [-57.8906, 23.9791, -22.0662],
            (38.8, 247.5),
            (-38.8, 67.5, 0.0, 0.0),
            false,
        ),
        (
            (18.5, -32.2),
            [0.0; 3],
            [-0.169084, -0.268501, 0.948324],
            [-16.9084, -26.8501, -5.1676],
            (18.5, 327.8),
            (-18.5, 147.8, 0.0, 0.0),
            true,
        ),
        (
            (30.2, -71.5),
            [10.0, 20.0, 30.0],
            [-0.477026, -0.159611, 0.864275],
            [-42.4481, -24.7478, 22.4161],
            (30.2, 288.5),
            (-30.2, 108.5, -10.0, -20.0),
            false,
        ),
    ];
    for ((a, c), xyz, o, p, (pa, pc), (oa, oc, ox, oy), other_ok) in rows {
        let q = Joints::new(xyz[0], xyz[1], xyz[2], deg(a), deg(c));
        check_pose(&k, &q, p, o, 1e-4, 1e-6);
        let positive = Joints::new(xyz[0], xyz[1], xyz[2], deg(pa), deg(pc));
        let other = ik_contains(&k, &q, &positive);
        let expected_other = Joints::new(ox, oy, xyz[2], deg(oa), deg(oc));
        assert!(same_joints_mod_turn(&other, &expected_other, 1e-9), "{other:?} vs {expected_other:?}");
        assert_eq!(scallop_machine::plan::check_limits(k.machine(), &other, None).is_ok(), other_ok);
    }
}

#[test]
fn vectors_synthetic_s1_to_s6() {
    let (ex, ey, ez) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
    let (mey, mez) = ([0.0, -1.0, 0.0], [0.0, 0.0, -1.0]);
    let pivot = [0.0, 0.0, 150.0];
    let o = [0.0; 3];
    // (machine, tool length, rotaries (name, deg), P, O, other rotaries (deg), other xyz)
    type Case = (Machine, f64, [(&'static str, f64); 2], [f64; 3], [f64; 3], [f64; 2], [f64; 3]);
    let cases: Vec<Case> = vec![
        (
            synthetic(&[("B", mey, [5.0, 0.0, -80.0]), ("C", mez, o)], &["B", "C"], &[]),
            0.0,
            [("B", 30.0), ("C", 90.0)],
            [-20.0, 64.3301, 12.7628],
            [0.0, 0.5, 0.866025],
            [-30.0, -90.0],
            [-8.6603, -20.0, 35.0],
        ),
        (
            synthetic(&[("C", ez, pivot), ("A", ex, pivot)], &[], &["C", "A"]),
            0.0,
            [("C", 90.0), ("A", 30.0)],
            [-65.0, 20.0, 50.0962],
            [0.5, 0.0, 0.866025],
            [-90.0, -30.0],
            [10.0, 20.0, 30.0],
        ),
        (
            synthetic(&[("C", ez, pivot), ("B", ey, pivot)], &[], &["C", "B"]),
            0.0,
            [("C", 90.0), ("B", 30.0)],
            [10.0, -55.0, 50.0962],
            [0.0, 0.5, 0.866025],
            [-90.0, -30.0],
            [10.0, 20.0, 30.0],
        ),
        (
            synthetic(&[("C", mez, o), ("B", ey, pivot)], &["C"], &["B"]),
            0.0,
            [("C", 90.0), ("B", 30.0)],
            [-20.0, -65.0, 50.0962],
            [0.0, 0.5, 0.866025],
            [-90.0, -30.0],
            [-10.0, -20.0, 30.0],
        ),
        (
            synthetic(&[("C", mez, o), ("A", ex, pivot)], &["C"], &["A"]),
            0.0,
            [("C", 90.0), ("A", 30.0)],
            [-95.0, 10.0, 50.0962],
            [0.5, 0.0, 0.866025],
            [-90.0, -30.0],
            [-10.0, -20.0, 30.0],
        ),
        (
            synthetic(&[("C", ez, o), ("A", ex, [0.0, 20.0, 50.0])], &[], &["C", "A"]),
            100.0,
            [("C", 90.0), ("A", 30.0)],
            [-67.6795, 20.0, -59.9038],
            [0.5, 0.0, 0.866025],
            [-90.0, -30.0],
            [4.641, 20.0, 10.0],
        ),
    ];
    for (i, (m, l, rot, p, o, other_rot, other_xyz)) in cases.into_iter().enumerate() {
        let k = Kinematics::new(&m, l);
        assert!(matches!(k.solver(), Solver::Closed(_)), "S{}: {:?}", i + 1, k.solver());
        let mut q = Joints::new(10.0, 20.0, 30.0, 0.0, 0.0);
        let mut other = Joints::new(other_xyz[0], other_xyz[1], other_xyz[2], 0.0, 0.0);
        for (j, (name, value)) in rot.iter().enumerate() {
            let idx = m.axis_by_name(name).expect("axis");
            q[idx] = deg(*value);
            other[idx] = deg(other_rot[j]);
        }
        check_pose(&k, &q, p, o, 1e-4, 1e-6);
        let got = ik_contains(&k, &q, &q);
        assert!(same_joints_mod_turn(&got, &other, 1e-3), "S{}: {got:?} vs {other:?}", i + 1);
    }
}

fn trt(ac: bool, conventional: bool) -> Kinematics {
    // x-rot-point 10, y-rot-point -5, z-rot-point 20, y-offset (AC) / x-offset (BC) 15,
    // z-offset -30, tool-offset 40: C through (10, -5); tilt through the offsets.
    let s = if conventional { -1.0 } else { 1.0 };
    let zt = 20.0 - 30.0 + 40.0;
    let c = ("C", [0.0, 0.0, s], [10.0, -5.0, 0.0]);
    let m = if ac {
        synthetic(&[("A", [s, 0.0, 0.0], [0.0, -5.0 + 15.0, zt]), c], &["A", "C"], &[])
    } else {
        synthetic(&[("B", [0.0, s, 0.0], [10.0 + 15.0, 0.0, zt]), c], &["B", "C"], &[])
    };
    Kinematics::new(&m, 0.0)
}

#[test]
fn vectors_linuxcnc_forward_oracle() {
    let rows: [(bool, bool, [f64; 3], [f64; 3]); 4] = [
        (true, true, [-6.7303, 11.7303, 25.0], [50.3874, 40.9643, 82.1149]),
        (true, false, [26.7303, 11.7303, 35.0], [-0.0073, -80.0597, 71.8543]),
        (false, true, [-6.2567, 14.0987, 22.5], [55.1687, 13.2345, 102.6361]),
        (false, false, [29.0987, 11.2567, 37.5], [20.3082, -82.8544, 51.3331]),
    ];
    for (ac, conventional, w1, w2) in rows {
        let k = trt(ac, conventional);
        for (j, w) in [([10.0, 20.0, 30.0, -30.0, 45.0], w1), ([-50.0, 25.0, 80.0, 20.0, -120.0], w2)] {
            let q = Joints::new(j[0], j[1], j[2], deg(j[3]), deg(j[4]));
            let p = k.fk(&q).tip;
            for i in 0..3 {
                assert_near!(p[i], w[i], 1e-4);
            }
        }
    }
}

#[test]
fn vectors_linuxcnc_forward_random_against_rederivation() {
    // Independent forms: the published xyzac forward map (conventional-directions = false),
    // and P = Rz(-g)(R_t(-t)(j - p_t) + p_t - p_c) + p_c for both modules.
    let (xr, yr, zr, off, zo, to) = (10.0, -5.0, 20.0, 15.0, -30.0, 40.0);
    let mut rng = scallop_geom::rng::SplitMix64::new(0x2545_f491_4f6c_dd1d);
    let mut rnd = |lo: f64, hi: f64| rng.uniform(lo, hi);
    for ac in [true, false] {
        for conventional in [true, false] {
            let k = trt(ac, conventional);
            let s = if conventional { -1.0 } else { 1.0 };
            for _ in 0..1000 {
                let j = [rnd(-200.0, 200.0), rnd(-200.0, 200.0), rnd(-200.0, 200.0), rnd(-3.0, 3.0), rnd(-7.0, 7.0)];
                let q = Joints::new(j[0], j[1], j[2], j[3], j[4]);
                let p = k.fk(&q).tip;
                let (t, g) = (s * j[3], s * j[4]);
                let (ct, st, cg, sg) = (t.cos(), t.sin(), g.cos(), g.sin());
                let dz = zo + to;
                let expected = if ac {
                    let (yt, zt) = (yr + off, zr + dz);
                    let y1 = ct * (j[1] - yt) + st * (j[2] - zt) + yt - yr;
                    let z1 = -st * (j[1] - yt) + ct * (j[2] - zt) + zt;
                    let x1 = j[0] - xr;
                    Vec3::new(cg * x1 + sg * y1 + xr, -sg * x1 + cg * y1 + yr, z1)
                } else {
                    let (xt, zt) = (xr + off, zr + dz);
                    let x1 = ct * (j[0] - xt) - st * (j[2] - zt) + xt - xr;
                    let z1 = st * (j[0] - xt) + ct * (j[2] - zt) + zt;
                    let y1 = j[1] - yr;
                    Vec3::new(cg * x1 + sg * y1 + xr, -sg * x1 + cg * y1 + yr, z1)
                };
                assert!((p.coords - expected).norm() < 1e-9, "{p:?} vs {expected:?}");
                if ac && !conventional {
                    // The published map, term by term.
                    let (ca, sa, cc, sc) = (j[3].cos(), j[3].sin(), j[4].cos(), j[4].sin());
                    let px =
                        cc * (j[0] - xr) + sc * ca * (j[1] - off - yr) + sc * sa * (j[2] - dz - zr) + sc * off + xr;
                    let py =
                        -sc * (j[0] - xr) + cc * ca * (j[1] - off - yr) + cc * sa * (j[2] - dz - zr) + cc * off + yr;
                    let pz = -sa * (j[1] - off - yr) + ca * (j[2] - dz - zr) + dz + zr;
                    assert!((p.coords - Vec3::new(px, py, pz)).norm() < 1e-9);
                }
            }
        }
    }
}

// ---------------------------------------------------------------- 7.1 kinematic core

#[test]
fn k3_ik_of_fk_recovers_joints_on_the_shipped_machines() {
    for name in Machine::builtin_names() {
        let m = Machine::builtin(name).expect("shipped");
        let k = Kinematics::new(&m, 25.0);
        for i in 0..200 {
            let t = f64::from(i);
            let mut q =
                Joints::new(30.0 * (t * 0.37).sin(), 20.0 * (t * 0.53).cos(), 40.0 + 10.0 * (t * 0.21).sin(), 0.0, 0.0);
            q[3] = 1.2 * (t * 0.71).sin();
            q[4] = 3.0 * (t * 0.13).cos();
            let pose = k.fk(&q);
            let rho =
                (k.machine().axes()[k.pole_axis()].direction.cross(&(k.part_frame().rotation * pose.axis))).norm();
            if rho < 1e-3 {
                continue;
            }
            let sols = k.ik(&pose, &q).expect("reachable");
            assert!(
                sols.as_slice().iter().any(|s| same_joints_mod_turn(&s.joints, &q, 1e-9)),
                "{name}: {q:?} not in {sols:?}"
            );
        }
    }
}

#[test]
fn k4_closed_forms_equal_the_generic_solver() {
    for name in Machine::builtin_names() {
        let m = Machine::builtin(name).expect("shipped");
        let closed = Kinematics::new(&m, 10.0);
        assert!(matches!(closed.solver(), Solver::Closed(_)), "{name} has no closed form");
        let generic = closed.clone().with_solver(Solver::Generic);
        for i in 0..100 {
            let t = f64::from(i);
            let q =
                Joints::new(5.0 * t.sin(), 7.0 * t.cos(), 3.0 * t, 1.1 * (0.3 * t).sin() + 0.01, 2.9 * (0.7 * t).cos());
            let pose = closed.fk(&q);
            let a = closed.ik(&pose, &q).expect("closed");
            let b = generic.ik(&pose, &q).expect("generic");
            for s in a.as_slice() {
                assert!(
                    b.as_slice().iter().any(|r| same_joints_mod_turn(&r.joints, &s.joints, 1e-9)),
                    "{name}: {s:?} vs {b:?}"
                );
            }
        }
    }
}

#[test]
fn k5_mx330_jacobian_check_point() {
    let k = mx330();
    let q = mx_q(30.0, -45.0, 10.0, 20.0, 150.0);
    let j = k.jacobian(&q);
    // Our columns are X, Y, Z, A, C; the spec's are C, A, X, Y, Z.
    let col = [4, 3, 0, 1, 2];
    let p_dot = [
        [-68.484692, 28.284271, -0.866025, -0.353553, -0.353553],
        [51.086661, 48.989795, 0.5, -0.612372, -0.612372],
        [0.0, 84.852814, 0.0, -0.707107, 0.707107],
    ];
    let o_dot =
        [[-0.612372, 0.353553, 0.0, 0.0, 0.0], [0.353553, 0.612372, 0.0, 0.0, 0.0], [0.0, 0.707107, 0.0, 0.0, 0.0]];
    let o = k.fk(&q).axis;
    for (c, &jc) in col.iter().enumerate() {
        let omega = Vec3::new(j[(0, jc)], j[(1, jc)], j[(2, jc)]);
        let od = omega.cross(&o);
        for r in 0..3 {
            assert_near!(j[(3 + r, jc)], p_dot[r][c], 1e-6);
            assert_near!(od[r], o_dot[r][c], 1e-6);
        }
    }
    let (j5, _, _) = k.task_jacobian(&q);
    assert_near!(j5.determinant().abs(), 0.707107, 1e-6);
}

#[test]
fn k5_mx330_analytic_form_equals_generic() {
    let k = mx330();
    for i in 0..50 {
        let t = f64::from(i);
        let (c, a) = (2.0 * t.sin(), -(0.3 * t).cos());
        let q = Joints::new(10.0 * t.cos(), 5.0, 120.0 + t, a, c);
        let p = k.fk(&q).tip;
        let (sa, ca, sc, cc) = (a.sin(), a.cos(), c.sin(), c.cos());
        let d = 50.0;
        // Rows over (C, A, X, Y, Z), spec 3.8 [CORR].
        let rows = [
            [p.y, sc * (p.z + d), -cc, -ca * sc, sa * sc],
            [-p.x, cc * (p.z + d), sc, -ca * cc, sa * cc],
            [0.0, -(sc * p.x + cc * p.y), 0.0, sa, ca],
        ];
        let omega = [[0.0, -cc, 0.0, 0.0, 0.0], [0.0, sc, 0.0, 0.0, 0.0], [-1.0, 0.0, 0.0, 0.0, 0.0]];
        let j = k.jacobian(&q);
        for (c_spec, jc) in [4usize, 3, 0, 1, 2].into_iter().enumerate() {
            for r in 0..3 {
                assert_near!(j[(3 + r, jc)], rows[r][c_spec], 1e-9);
                assert_near!(j[(r, jc)], omega[r][c_spec], 1e-12);
            }
        }
    }
}

fn nutating(tilt_axis: [f64; 3]) -> Kinematics {
    Kinematics::new(
        &synthetic(&[("C", [0.0, 0.0, 1.0], [0.0, 0.0, 150.0]), ("B", tilt_axis, [0.0, 0.0, 150.0])], &[], &["C", "B"]),
        0.0,
    )
}

#[test]
fn k6_nutating_head_reach() {
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let k = nutating([0.0, -h, h]);
    assert_eq!(k.solver(), Solver::Generic);
    let at = |tilt: f64| {
        Pose::new(Point3::new(1.0, 2.0, 3.0), Vec3::new(deg(tilt).sin() * 0.6, deg(tilt).sin() * 0.8, deg(tilt).cos()))
    };
    let sols = k.ik(&at(89.0), &Joints::zeros()).expect("89 deg is reachable");
    let s = sols.as_slice();
    assert_eq!(s.len(), 2);
    assert!(!same_joints_mod_turn(&s[0].joints, &s[1].joints, 1e-6));
    for x in s {
        let back = k.fk(&x.joints);
        assert!((back.tip - at(89.0).tip).norm() < 1e-9 && (back.axis - at(89.0).axis).norm() < 1e-9);
    }
    assert!(matches!(k.ik(&at(91.0), &Joints::zeros()), Err(MachineError::Unreachable { .. })));
}

// ---------------------------------------------------------------- 7.3 planning

#[test]
fn k7_iso841_report() {
    let mx = Machine::builtin("mx330").expect("shipped").iso841_report();
    for (name, sense) in mx {
        let expected = if name == "Z" { Iso841::Iso } else { Iso841::TableMotionSense };
        assert_eq!(sense, expected, "MX330 {name}");
    }
    assert!(Machine::builtin("ucp710").expect("shipped").iso841_report().iter().all(|(_, s)| *s == Iso841::Iso));
}

#[test]
fn k8_branch_policy_mx330() {
    let k = mx330();
    let q = mx_q(30.0, -45.0, 10.0, 20.0, 150.0);
    let pose = k.fk(&q);
    let sols = k.ik(&pose, &Joints::zeros()).expect("reachable");
    let s = select(&k, sols.as_slice(), None, Some(0)).expect("branch (-) fits");
    assert_eq!(s.branch, Branch::Negative);
    assert!(same_joints_mod_turn(&s.joints, &q, 1e-9));
    // Tilt 5 deg: both branches fit; continuity keeps the previous one.
    let small = mx_q(20.0, 5.0, 5.0, -5.0, 120.0);
    let pose = k.fk(&small);
    let sols = k.ik(&pose, &small).expect("reachable");
    assert!(sols.as_slice().iter().all(|x| scallop_machine::plan::check_limits(k.machine(), &x.joints, None).is_ok()));
    let keep_pos = select(&k, sols.as_slice(), Some(&mx_q(21.0, 5.5, 5.0, -5.0, 120.0)), Some(1)).expect("fits");
    assert_eq!(keep_pos.branch, Branch::Positive);
    let keep_neg = select(&k, sols.as_slice(), Some(&mx_q(-159.0, -5.5, -5.0, 5.0, 120.0)), Some(1)).expect("fits");
    assert_eq!(keep_neg.branch, Branch::Negative);
    // Without a previous state the preference (A < 0) decides.
    assert_eq!(select(&k, sols.as_slice(), None, Some(0)).expect("fits").branch, Branch::Negative);
}

#[test]
fn k9_pole_on_mx330_holds_c() {
    let k = mx330();
    for c_prev in [0.0, 33.0, -120.0, 400.0] {
        let p = Point3::new(12.0, -7.0, 3.0);
        let pose = Pose::new(p, Vec3::z());
        let prev = mx_q(c_prev, -10.0, 0.0, 0.0, 100.0);
        let path = solve_path(&k, &[pose], Some(prev)).expect("pole is reachable");
        let q = path.joints[0];
        assert!(q.iter().all(|v| v.is_finite()));
        let (sc, cc) = (deg(c_prev).sin(), deg(c_prev).cos());
        assert_near!(q[4], deg(c_prev), 1e-12);
        assert_near!(q[3], 0.0, 1e-12);
        assert_near!(q[2], p.z + 100.0, 1e-9);
        assert_near!(q[0], -p.x * cc + p.y * sc, 1e-9);
        assert_near!(q[1], -p.x * sc - p.y * cc, 1e-9);
        assert!(path.events.contains(&Event::PoleHold { block: 0 }));
    }
}

#[test]
fn k10_pole_crossing_with_symmetric_tilt_range_keeps_c() {
    // Second half of K10: A in [-125, 125]: A = phi, C = 0 constant, no flip event.
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../machines/matsuura-mx330.toml"))
        .expect("file");
    let m = Machine::from_toml_str(&text.replace("limits = [-125, 10]", "limits = [-125, 125]")).expect("valid");
    let k = Kinematics::new(&m, 100.0);
    let poses: Vec<Pose> = (-30..=30)
        .map(|i| Pose::new(Point3::origin(), Vec3::new(0.0, deg(f64::from(i)).sin(), deg(f64::from(i)).cos())))
        .collect();
    let path = solve_path(&k, &poses, None).expect("reachable");
    for (i, q) in (-30..=30).zip(&path.joints) {
        // O = (sA sC, sA cC, cA) with C = 0: A = phi (Oj = sin phi).
        assert_near!(q[3], deg(f64::from(i)), 1e-9);
        assert_near!(q[4], 0.0, 1e-9);
    }
    assert!(path.events.iter().all(|e| matches!(e, Event::PoleHold { .. })), "{:?}", path.events);
}

#[test]
fn k11_near_pole_rate() {
    // Great circle passing delta = 1 deg from the pole at Omega = 10 deg/s, closest approach.
    let k = mx330();
    let delta = deg(1.0);
    let omega = deg(10.0);
    let o = Vec3::new(0.0, delta.sin(), delta.cos());
    let o_dot = Vec3::new(omega, 0.0, 0.0); // perpendicular to the meridian
    let pose = Pose::new(Point3::new(0.0, 0.0, 0.0), o);
    let sols = k.ik(&pose, &Joints::zeros()).expect("reachable");
    let q = select(&k, sols.as_slice(), None, None).expect("fits").joints;
    let rates = k.joint_rates(&q, &Vec3::zeros(), &o_dot).expect("off the pole");
    assert_near!(rates[4].abs().to_degrees(), 572.99, 0.01);
    let scale = k.feed_scale(&q, &Vec3::zeros(), &o_dot).expect("off the pole");
    assert_near!(scale, 0.34556, 1e-5);
}

#[test]
fn k12_unwrapping() {
    let raw = [170.0, -170.0, -150.0].map(deg);
    let mut prev = 0.0;
    let mut out = Vec::new();
    for r in raw {
        let (v, unwound) = unwrap_angle(r, prev, None).expect("continuous");
        assert!(!unwound);
        out.push(v.to_degrees());
        prev = v;
    }
    for (a, b) in out.iter().zip([170.0, 190.0, 210.0]) {
        assert_near!(*a, b, 1e-9);
    }
    let lim = Some((deg(-180.0), deg(180.0)));
    let (first, u0) = unwrap_angle(raw[0], 0.0, lim).expect("fits");
    assert!(!u0);
    let (second, u1) = unwrap_angle(raw[1], first, lim).expect("fits");
    assert!(u1, "the second point forces an unwind");
    assert_near!((second - first).to_degrees(), -340.0, 1e-9);
}

#[test]
fn k12_unwind_event_in_a_path() {
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../machines/matsuura-mx330.toml"))
        .expect("file");
    let m = Machine::from_toml_str(&text.replace("continuous = true, wrap = \"absolute\"", "limits = [-180, 180]"))
        .expect("valid");
    let k = Kinematics::new(&m, 100.0);
    let poses: Vec<Pose> = [170.0, -170.0, -150.0].iter().map(|c| k.fk(&mx_q(*c, -30.0, 0.0, 0.0, 100.0))).collect();
    let path = solve_path(&k, &poses, None).expect("reachable");
    assert!(path.events.iter().any(|e| matches!(e, Event::Unwind { block: 1, axis, delta_deg } if axis == "C" && (delta_deg + 340.0).abs() < 1e-6)), "{:?}", path.events);
}

// ---------------------------------------------------------------- errors name the axis

#[test]
fn stroke_violation_names_block_and_axis() {
    let k = mx330();
    let ok = k.fk(&mx_q(0.0, -30.0, 0.0, 0.0, 150.0));
    // Tilt 130 deg: branch (-) needs A = -130 < -125, branch (+) A = 130 > 10.
    let bad = k.fk(&mx_q(0.0, -130.0, 0.0, 0.0, 150.0));
    let err = solve_path(&k, &[ok, ok, bad], None).expect_err("A leaves its stroke");
    match &err {
        MachineError::LimitViolation { block, axis, .. } => {
            assert_eq!(*block, Some(2));
            assert_eq!(axis, "A");
        }
        other => panic!("unexpected {other:?}"),
    }
    assert!(err.to_string().contains("block 2: axis A"));
    // A linear stroke.
    let far = Pose::new(Point3::new(0.0, 0.0, 600.0), Vec3::z());
    let err = solve_path(&k, &[far], None).expect_err("Z leaves its stroke");
    assert!(matches!(&err, MachineError::LimitViolation { axis, .. } if axis == "Z"), "{err}");
}

#[test]
fn unreachable_orientation_is_an_error() {
    // Head-table with B in a half plane cannot reach... use the nutating head at 120 deg.
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let k = nutating([0.0, -h, h]);
    let pose = Pose::new(Point3::origin(), Vec3::new(0.0, 0.0, -1.0));
    let err = solve_path(&k, &[pose, pose], None).expect_err("unreachable");
    assert!(matches!(err, MachineError::Unreachable { block: Some(0), .. }), "{err}");
}

// ---------------------------------------------------------------- K10 with the dynamic programme

fn sweep(tip: Point3) -> Vec<Pose> {
    (-30..=30).map(|i| Pose::new(tip, Vec3::new(0.0, deg(f64::from(i)).sin(), deg(f64::from(i)).cos()))).collect()
}

#[test]
fn k10_pole_crossing_while_cutting_flips_at_the_pole() {
    use scallop_machine::plan::{PlanOptions, plan_path};
    let k = mx330();
    let poses = sweep(Point3::origin());
    let path = plan_path(&k, &poses, &vec![true; poses.len()], None, &PlanOptions::default())
        .expect("a pole flip path exists");
    let flips: Vec<&Event> = path.events.iter().filter(|e| matches!(e, Event::PoleFlip { .. })).collect();
    assert_eq!(flips.len(), 1, "{:?}", path.events);
    match flips[0] {
        Event::PoleFlip { axis, delta_deg, seconds, block } => {
            assert_eq!(axis, "C");
            assert_near!(delta_deg.abs(), 180.0, 1e-9);
            assert_near!(*seconds, 0.909, 1e-3);
            assert_eq!(*block, 31); // the move out of the pole pose (phi = 0 is pose 30)
        }
        _ => unreachable!(),
    }
    // A = -|phi| everywhere; C = 0 before the pole, +-180 after; one extra in-place vector.
    assert_eq!(path.joints.len(), poses.len() + 1);
    for (q, &i) in path.joints.iter().zip(&path.pose_index) {
        let phi = f64::from(i32::try_from(i).expect("small") - 30);
        assert_near!(q[3], -deg(phi.abs()), 1e-9);
        let back = k.fk(q);
        assert!((back.tip - poses[i].tip).norm() < 1e-9 && (back.axis - poses[i].axis).norm() < 1e-9);
        if phi < 0.0 {
            assert_near!(q[4], 0.0, 1e-9);
        } else if phi > 0.0 {
            assert_near!(q[4].abs(), deg(180.0), 1e-9);
        }
    }
    for q in &path.joints {
        assert!(scallop_machine::plan::check_limits(k.machine(), q, None).is_ok());
    }
}

#[test]
fn k10_symmetric_tilt_range_keeps_c_constant_with_the_programme() {
    use scallop_machine::plan::{PlanOptions, plan_path};
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../machines/matsuura-mx330.toml"))
        .expect("file");
    let m = Machine::from_toml_str(&text.replace("limits = [-125, 10]", "limits = [-125, 125]")).expect("valid");
    let k = Kinematics::new(&m, 100.0);
    let poses = sweep(Point3::origin());
    let path = plan_path(&k, &poses, &vec![true; poses.len()], None, &PlanOptions::default()).expect("continuous");
    assert_eq!(path.joints.len(), poses.len());
    for (q, i) in path.joints.iter().zip(-30..=30) {
        assert_near!(q[3], deg(f64::from(i)), 1e-9);
        assert_near!(q[4], 0.0, 1e-9);
    }
    assert!(path.events.iter().all(|e| matches!(e, Event::PoleHold { .. })), "{:?}", path.events);
}

#[test]
fn k10_pole_crossing_between_samples_is_a_pole_flip() {
    use scallop_machine::plan::{PlanOptions, plan_path};
    let k = mx330();
    // phi = -29.5 ... 29.5: the pole is crossed inside a block, never sampled.
    let poses: Vec<Pose> = (-30..30)
        .map(|i| {
            let p = deg(f64::from(i) + 0.5);
            Pose::new(Point3::origin(), Vec3::new(0.0, p.sin(), p.cos()))
        })
        .collect();
    let path =
        plan_path(&k, &poses, &vec![true; poses.len()], None, &PlanOptions::default()).expect("flip in the block");
    assert_eq!(path.events.iter().filter(|e| matches!(e, Event::PoleFlip { .. })).count(), 1, "{:?}", path.events);
}

#[test]
fn flip_while_cutting_is_an_error_and_a_reorient_when_not_cutting() {
    use scallop_machine::plan::{PlanOptions, plan_path};
    let k = mx330();
    // Tilt 5 deg on branch (+) then tilt 40 deg at the same azimuth: (+) leaves A <= 10,
    // (-) needs C + 180 away from the pole.
    let a = k.fk(&mx_q(20.0, 5.0, 0.0, 0.0, 120.0));
    let b = k.fk(&mx_q(20.0, 40.0, 0.0, 0.0, 120.0));
    let start = Some(mx_q(20.0, 5.0, 0.0, 0.0, 120.0));
    let err = plan_path(&k, &[a, b], &[true, true], start, &PlanOptions::default()).expect_err("needs a flip");
    assert!(matches!(&err, MachineError::FlipWhileCutting { block: 1, axis, .. } if axis == "C"), "{err}");
    let ok = plan_path(&k, &[a, b], &[true, false], start, &PlanOptions::default()).expect("link move");
    assert!(ok.events.iter().any(|e| matches!(e, Event::Reorient { block: 1, .. })), "{:?}", ok.events);
}

#[test]
fn plan_path_matches_greedy_on_smooth_paths() {
    use scallop_machine::plan::{PlanOptions, plan_path};
    for name in Machine::builtin_names() {
        let k = Kinematics::new(&Machine::builtin(name).expect("shipped"), 0.0);
        let poses: Vec<Pose> = (0..50)
            .map(|i| {
                let t = f64::from(i) * 0.02;
                Pose::new(Point3::new(10.0 * t, 5.0 - t, 40.0), Vec3::new(0.3 * t.sin(), 0.2 + 0.1 * t, 1.0))
            })
            .collect();
        let greedy = solve_path(&k, &poses, None).expect("reachable");
        let dp = plan_path(&k, &poses, &vec![true; poses.len()], None, &PlanOptions::default()).expect("reachable");
        assert_eq!(greedy.joints.len(), dp.joints.len(), "{name}");
        for (a, b) in greedy.joints.iter().zip(&dp.joints) {
            assert!((a - b).amax() < 1e-9, "{name}: {a:?} vs {b:?}");
        }
    }
}

// ---------------------------------------------------------------- K13, K14: subdivision and G93

fn k13_block() -> (Kinematics, Pose, Pose, Joints, Joints) {
    use scallop_geom::nalgebra::Rotation3;
    let k = mx330();
    let rz = Rotation3::from_axis_angle(&Vec3::z_axis(), deg(10.0));
    let ry = Rotation3::from_axis_angle(&Vec3::y_axis(), deg(30.0));
    let pa = Pose::new(Point3::new(100.0, 0.0, 0.0), ry * Vec3::z());
    let pb = Pose::new(rz * Point3::new(100.0, 0.0, 0.0), rz * ry * Vec3::z());
    let qa =
        select(&k, k.ik(&pa, &Joints::zeros()).expect("reachable").as_slice(), None, Some(0)).expect("fits").joints;
    let qb = select(&k, k.ik(&pb, &qa).expect("reachable").as_slice(), Some(&qa), Some(1)).expect("fits").joints;
    (k, pa, pb, qa, qb)
}

#[test]
fn k13_subdivision_position_criterion() {
    use scallop_machine::feed::{deviation, subdivide};
    let (k, pa, pb, qa, qb) = k13_block();
    assert!(same_joints_mod_turn(&qa, &mx_q(-90.0, -30.0, 0.0, 61.6025, 143.3013), 1e-4), "{qa:?}");
    assert!(same_joints_mod_turn(&qb, &mx_q(-100.0, -30.0, 0.0, 61.6025, 143.3013), 1e-4), "{qb:?}");
    assert_near!((qb - qa).amax(), deg(10.0), 1e-9); // a pure C move
    let (e_pos, e_ang) = deviation(&k, &pa, &pb, &qa, &qb);
    assert_near!(e_pos, 0.380530, 1e-6);
    assert_near!(e_pos, 100.0 * (1.0 - deg(5.0).cos()), 1e-6);
    assert_near!(e_ang.to_degrees(), 0.0945, 1e-4);
    let max_dev = |ends: &[scallop_machine::feed::BlockEnd]| {
        let mut prev = (pa, qa);
        let mut worst: f64 = 0.0;
        for e in ends {
            worst = worst.max(deviation(&k, &prev.0, &e.pose, &prev.1, &e.joints).0);
            prev = (e.pose, e.joints);
        }
        worst
    };
    let ends = subdivide(&k, &pa, &pb, &qa, &qb, 0.01, f64::INFINITY, 0).expect("converges");
    assert_eq!(ends.len(), 8);
    assert_near!(max_dev(&ends), 0.005957, 1e-6);
    let ends = subdivide(&k, &pa, &pb, &qa, &qb, 0.001, f64::INFINITY, 0).expect("converges");
    assert_eq!(ends.len(), 32);
    // Uniform split: 7 blocks pass (0.007780), 6 fail (0.010589).
    for (n, expected) in [(7u32, 0.007780), (6, 0.010589)] {
        let mut ends = Vec::new();
        let mut prev = qa;
        for i in 1..=n {
            let s = f64::from(i) / f64::from(n);
            let pose = Pose::new(Point3::from(pa.tip.coords * (1.0 - s) + pb.tip.coords * s), {
                let r =
                    scallop_geom::nalgebra::UnitQuaternion::rotation_between(&pa.axis, &pb.axis).expect("not opposite");
                scallop_geom::nalgebra::UnitQuaternion::identity().slerp(&r, s) * pa.axis
            });
            let q =
                select(&k, k.ik(&pose, &prev).expect("reachable").as_slice(), Some(&prev), None).expect("fits").joints;
            ends.push(scallop_machine::feed::BlockEnd { pose, joints: q });
            prev = q;
        }
        assert_near!(max_dev(&ends), expected, 1e-6);
    }
}

#[test]
fn k14_inverse_time_feed() {
    use scallop_machine::feed::inverse_time_feed;
    let (k, pa, pb, qa, qb) = k13_block();
    assert_near!((pb.tip - pa.tip).norm(), 17.431149, 1e-6);
    let f1 = inverse_time_feed(&k, &pa, &pb, &qa, &qb, 1000.0);
    assert_near!(f1, 57.368, 1e-12);
    let f2 = inverse_time_feed(&k, &pa, &pb, &qa, &qb, 30000.0);
    assert_near!(f2, 1188.0, 1e-12);
    assert_near!(60.0 / 0.050505, 1188.0, 0.01);
    // Every block keeps every axis within vmax: |dq_j| F_inv / 60 <= vmax_j.
    for f in [f1, f2] {
        for (j, a) in k.machine().axes().iter().enumerate() {
            assert!((qb[j] - qa[j]).abs() * f / 60.0 <= a.dynamics.vmax * (1.0 + 1e-12), "axis {}", a.name);
        }
    }
    // Translation-only block: F_inv = F / L exactly.
    let q0 = mx_q(0.0, -20.0, 0.0, 0.0, 150.0);
    let q1 = mx_q(0.0, -20.0, 25.0, 0.0, 150.0);
    let f = inverse_time_feed(&k, &k.fk(&q0), &k.fk(&q1), &q0, &q1, 1000.0);
    assert_near!(f, 40.0, 0.0);
}
