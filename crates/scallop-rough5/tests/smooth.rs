//! The smoothing of the tool axes along a run (`smooth_axes`; docs/rough5.md,
//! "Where the machine time goes").

use proptest::prelude::*;
use scallop_geom::Vec3;
use scallop_rough5::{SMOOTH_MIN_TILT, axis_steps, smooth_axes};

fn axis(tilt_deg: f64, azimuth_deg: f64) -> Vec3 {
    let (t, a) = (tilt_deg.to_radians(), azimuth_deg.to_radians());
    Vec3::new(t.sin() * a.cos(), t.sin() * a.sin(), t.cos())
}

const STEPS: (f64, f64) = (0.034_906_585_039_886_59, 0.087_266_462_599_716_48); // 2 deg, 5 deg

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]
    /// Whatever the axes and whichever tools the placer refuses: the ends,
    /// the refused tools and the axes within 1 deg of +Z (and their
    /// neighbours) are kept; every axis changed is one the placer accepted;
    /// two consecutive axes are within one angular step of each other unless
    /// neither changed.
    #[test]
    fn smoothing_keeps_what_it_must(
        tilts in prop::collection::vec(0.0..20.0f64, 3..40),
        noise in prop::collection::vec(-4.0..4.0f64, 40),
        refused in prop::collection::vec(any::<bool>(), 40),
        pole in prop::collection::vec(prop::bool::weighted(0.1), 40),
    ) {
        let axes: Vec<Vec3> = tilts
            .iter()
            .enumerate()
            .map(|(k, t)| if pole[k] { Vec3::z() } else { axis(*t, 10.0 * k as f64 / 8.0 + noise[k]) })
            .collect();
        let n = axes.len();
        let place = |k: usize, u: &Vec3| (!refused[k]).then_some(*u);
        let (out, changed) = smooth_axes(&axes, STEPS, &place);
        prop_assert_eq!(out.len(), n);
        prop_assert_eq!(out[0], axes[0]);
        prop_assert_eq!(out[n - 1], axes[n - 1]);
        let moved: Vec<bool> = (0..n).map(|k| out[k] != axes[k]).collect();
        prop_assert_eq!(moved.iter().filter(|m| **m).count(), changed);
        for k in 0..n {
            let near_pole = (k.saturating_sub(1)..=(k + 1).min(n - 1))
                .any(|j| axes[j].angle(&Vec3::z()) < SMOOTH_MIN_TILT);
            if refused[k] || near_pole {
                prop_assert!(!moved[k], "axis {} changed", k);
            }
            if moved[k] {
                prop_assert!((out[k].norm() - 1.0).abs() < 1e-12);
                prop_assert!(out[k].angle(&Vec3::z()) >= SMOOTH_MIN_TILT);
            }
        }
        for k in 1..n {
            if moved[k - 1] || moved[k] {
                prop_assert!(axis_steps(&out[k - 1], &out[k], STEPS.0, STEPS.1) <= 1, "axes {} and {}", k - 1, k);
            }
        }
    }
}

/// An axis at 8 deg whose azimuth zigzags by 4 deg each point (the
/// impeller's passes, where the C table swung back and forth): smoothed, the
/// azimuth's total swing falls by more than half and no azimuth step reverses
/// by more than 1 deg; the same run at 0.5 deg of tilt (within 1 deg of +Z) is
/// left alone.
#[test]
fn a_zigzag_azimuth_is_smoothed_away_from_the_pole_only() {
    let zigzag =
        |tilt: f64| -> Vec<Vec3> { (0..24).map(|k| axis(tilt, if k % 2 == 0 { -5.0 } else { -9.0 })).collect() };
    let azimuth = |u: &Vec3| u.y.atan2(u.x).to_degrees();
    let swing = |a: &[Vec3]| a.windows(2).map(|w| (azimuth(&w[1]) - azimuth(&w[0])).abs()).sum::<f64>();
    let axes = zigzag(8.0);
    let (out, changed) = smooth_axes(&axes, STEPS, &|_, u| Some(*u));
    assert_eq!(changed, axes.len() - 2);
    assert!(swing(&out) < 0.5 * swing(&axes), "{} against {}", swing(&out), swing(&axes));
    let interior = &out[2..out.len() - 2];
    assert!(interior.windows(2).all(|w| (azimuth(&w[1]) - azimuth(&w[0])).abs() < 1.0));
    let (near, none) = smooth_axes(&zigzag(0.5), STEPS, &|_, u| Some(*u));
    assert_eq!((near, none), (zigzag(0.5), 0));
}
