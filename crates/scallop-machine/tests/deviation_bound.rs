//! `feed::deviation_bound` is an upper bound of the sampled deviation of joint-linear
//! motion, on every shipped machine, for random blocks of every size the bound accepts;
//! `feed::deviation_bound_relaxed` (the subdivision's trigonometry-free pretest) is never
//! below it.

use proptest::prelude::*;
use scallop_machine::feed::{deviation, deviation_bound, deviation_bound_relaxed};
use scallop_machine::{AxisKind, Joints, Kinematics, Machine};

fn joints_in_strokes(m: &Machine, unit: &[f64; 5]) -> Joints {
    let mut q = Joints::zeros();
    for (i, a) in m.axes().iter().enumerate().take(5) {
        let (lo, hi) = a.joint_limits().unwrap_or((-std::f64::consts::PI, std::f64::consts::PI));
        q[i] = lo + (hi - lo) * unit[i];
    }
    q
}

prop_compose! {
    /// A block on a random shipped machine with a random tool length: from a start
    /// in `starts` (shares of the strokes) by a step of random direction scaled by
    /// one of `scales` (rad on rotary axes, 100 mm per unit on linear ones).
    fn random_block(starts: std::ops::Range<f64>, scales: Vec<f64>)(
        machine in 0usize..16,
        start in prop::array::uniform5(starts),
        step in prop::array::uniform5(-1.0f64..1.0),
        scale in prop::sample::select(scales),
        tool_length in 0.0f64..150.0,
    ) -> (Kinematics, Joints, Joints) {
        let names = Machine::builtin_names();
        let m = Machine::builtin(names[machine % names.len()]).expect("shipped");
        let kin = Kinematics::new(&m, tool_length);
        let qa = joints_in_strokes(&m, &start);
        let mut qb = qa;
        for (i, a) in m.axes().iter().enumerate().take(5) {
            qb[i] += step[i] * scale * if a.kind == AxisKind::Rotary { 1.0 } else { 100.0 };
        }
        (kin, qa, qb)
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]
    #[test]
    fn the_bound_is_never_below_the_sampled_deviation(
        (kin, qa, qb) in random_block(0.05..0.95, vec![1e-3, 1e-2, 0.05, 0.1]),
    ) {
        if let Some((bp, ba)) = deviation_bound(&kin, &qa, &qb) {
            let (pos, ang) = deviation(&kin, &kin.fk(&qa), &kin.fk(&qb), &qa, &qb);
            prop_assert!(pos <= bp * (1.0 + 1e-9) + 1e-12, "tip {pos} > bound {bp}");
            prop_assert!(ang <= ba * (1.0 + 1e-9) + 1e-12, "axis {ang} > bound {ba}");
        }
    }

    #[test]
    fn the_relaxed_bound_is_never_below_the_exact_bound(
        (kin, qa, qb) in random_block(0.0..1.0, vec![1e-4, 1e-3, 1e-2, 0.05, 0.1]),
    ) {
        match (deviation_bound(&kin, &qa, &qb), deviation_bound_relaxed(&kin, &qa, &qb)) {
            (Some((bp, ba)), Some((rp, ra))) => {
                prop_assert!(rp >= bp, "relaxed tip bound {rp} < exact {bp}");
                prop_assert!(ra >= ba, "relaxed axis bound {ra} < exact {ba}");
            }
            (None, None) => {}
            (exact, relaxed) => prop_assert!(false, "exact {exact:?} but relaxed {relaxed:?}"),
        }
    }
}

#[test]
fn the_bound_is_tight_enough_to_decide_dense_paths() {
    // A milliradian block with a millimetre of travel, 100 mm from the rotary axes: the
    // bound is far below a 0.01 mm tolerance, so such blocks need no sampling.
    let m = Machine::builtin("ucp710").expect("shipped");
    let kin = Kinematics::new(&m, 0.0);
    let qa = Joints::new(50.0, 50.0, 80.0, 0.5, 0.2);
    let qb = Joints::new(51.0, 50.5, 80.0, 0.501, 0.201);
    let (bp, ba) = deviation_bound(&kin, &qa, &qb).expect("small block");
    assert!(bp < 2e-3 && ba < 1e-5, "{bp} {ba}");
    // Pure translation: exactly zero.
    assert_eq!(deviation_bound(&kin, &qa, &Joints::new(60.0, 50.0, 80.0, 0.5, 0.2)), Some((0.0, 0.0)));
    // A large rotation is left to sampling.
    assert_eq!(deviation_bound(&kin, &qa, &Joints::new(50.0, 50.0, 80.0, 1.5, 0.2)), None);
}
