//! The optimised orientation of one pass (Jousselin 2020, Ch. 3 §2): the
//! SQP sanity checks of spec 12.1 item 5 (x0 = SPU is feasible; zero weights
//! keep it; every optimised reparameterisation satisfies Eq. 3.17-3.19 as
//! corrected at every sample, over random passes), and analytic cases on
//! coaxial circles where the best reparameterisation is known.
#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

use proptest::prelude::*;
use scallop_geom::{Point3, Vec3};
use scallop_guides::Curve;
use scallop_mesh::Polyline3;
use scallop_rough5::{
    BoundsPenalty, Coverage, OrientSettings, Reparam, Weights, constraints, objective_terms, optimise_pass,
    pitch_trace, synchronise_with,
};

/// A closed loop at height `z`, `n` points counter-clockwise from angle
/// `phase`: radii `a`, `b` about `centre` with a three-lobe wave `wave`.
fn lobed(a: f64, b: f64, wave: f64, centre: (f64, f64), z: f64, n: usize, phase: f64) -> Curve {
    let pts: Vec<Point3> = (0..n)
        .map(|k| {
            let t = phase + std::f64::consts::TAU * k as f64 / n as f64;
            let r = 1.0 + wave * (3.0 * t).cos();
            Point3::new(centre.0 + a * r * t.cos(), centre.1 + b * r * t.sin(), z)
        })
        .collect();
    Curve { line: Polyline3::new(pts, true), normals: vec![Vec3::z(); n] }
}

fn circle(radius: f64, z: f64, n: usize) -> Curve {
    lobed(radius, radius, 0.0, (0.0, 0.0), z, n, 0.0)
}

fn weights(bounds: f64, fluidity: f64, pitch: f64) -> Weights {
    Weights { bounds, fluidity, pitch }
}

/// Eq. 3.17-3.19 as corrected, checked on the cubics themselves at every
/// sample (not through the constraint rows).
fn assert_feasible(r: &Reparam, settings: &OrientSettings) {
    let eps = 1e-9;
    for k in 0..=settings.samples {
        let s = k as f64 / settings.samples as f64;
        assert!(r.path_rate(s) >= -eps, "g_T'({s}) = {}", r.path_rate(s));
        assert!(r.tilt_rate(s) >= -eps, "g_D'({s}) = {}", r.tilt_rate(s));
        assert!(r.path_rate(s) + r.tilt_rate(s) > 0.0, "both stalled at {s}");
    }
    let (cover_t, cover_d) = (r.path(1.0) - r.path(0.0), r.tilt(1.0) - r.tilt(0.0));
    match settings.coverage {
        Coverage::Exact => assert!((cover_t - 1.0).abs() <= eps && (cover_d - 1.0).abs() <= eps, "{r:?}"),
        Coverage::AtLeast => assert!(cover_t >= 1.0 - eps && cover_d >= 1.0 - eps, "{r:?}"),
    }
    if settings.fixed_entry {
        assert!(r.path(0.0).abs() <= eps, "g_T(0) = {}", r.path(0.0));
    }
    assert!(constraints(settings).violation(&r.x) <= eps);
}

/// Spec 12.1 item 5: x0 = SPU = (0,0,1,0,0,0,1,0) satisfies all the
/// constraints, whatever the options.
#[test]
fn spu_satisfies_all_constraints() {
    for coverage in [Coverage::Exact, Coverage::AtLeast] {
        for fixed_entry in [true, false] {
            for samples in [2, 10, 100, 257] {
                let settings =
                    OrientSettings { coverage, fixed_entry, samples, ..OrientSettings::new(weights(0., 0., 0.)) };
                assert_feasible(&Reparam::SPU, &settings);
                assert!(constraints(&settings).violation(&Reparam::SPU.x) <= 0.0);
            }
        }
    }
    assert_eq!(Reparam::SPU, Reparam { x: [0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] });
}

/// Spec 12.1 item 5: with (beta, phi, tau) = (0, 0, 0) the solution stays
/// feasible (it is x0 itself: the objective is flat).
#[test]
fn zero_weights_keep_a_feasible_spu() {
    let path = lobed(30.0, 20.0, 0.1, (0.0, 0.0), 0.0, 90, 0.3);
    let tilt = lobed(34.0, 23.0, 0.05, (1.0, -2.0), 4.0, 70, 1.1);
    let settings = OrientSettings::new(weights(0.0, 0.0, 0.0));
    let o = optimise_pass(&path, &tilt, &Point3::new(30.0, 0.0, 0.0), &settings).unwrap();
    assert_feasible(&o.reparam, &settings);
    assert_eq!(o.reparam, Reparam::SPU);
    assert!(o.objective.abs() < f64::MIN_POSITIVE, "{}", o.objective);
}

/// Coaxial circles of the same radius: SPU keeps the axis vertical
/// (theta_t = 0); a constant shift of the tilt parameter leans it forward by
/// a constant angle, so the pitch target 10 deg is reachable everywhere and
/// the optimum holds it to the sampling (E_t near zero).
#[test]
fn pitch_target_is_reached_on_coaxial_circles() {
    let (path, tilt) = (circle(20.0, 0.0, 180), circle(20.0, 4.0, 180));
    let start = Point3::new(20.0, 0.0, 0.0);
    let settings = OrientSettings { target: 10f64.to_radians(), ..OrientSettings::new(weights(0.0, 0.0, 1.0)) };
    let spu = pitch_trace(&path, &tilt, &start, &Reparam::SPU, 100);
    assert!(spu.iter().all(|(_, t)| t.abs() < 1e-9));
    let o = optimise_pass(&path, &tilt, &start, &settings).unwrap();
    assert_feasible(&o.reparam, &settings);
    let trace = pitch_trace(&path, &tilt, &start, &o.reparam, 100);
    let worst = trace.iter().map(|(_, t)| (t.to_degrees() - 10.0).abs()).fold(0.0, f64::max);
    assert!(worst < 0.05, "worst deviation {worst} deg, {o:?}");
    assert!(o.objective < 1e-3 * o.spu_objective, "{o:?}");
}

/// Bounds [-30, -5] deg on the same circles: the optimum pushes (theta_t < 0)
/// inside the interval at every sample, with either penalty.
#[test]
fn bounds_bring_the_pitch_into_the_interval() {
    let (path, tilt) = (circle(20.0, 0.0, 180), circle(20.0, 4.0, 180));
    let start = Point3::new(20.0, 0.0, 0.0);
    for penalty in [BoundsPenalty::Smooth, BoundsPenalty::Printed] {
        let settings = OrientSettings {
            interval: [(-30f64).to_radians(), (-5f64).to_radians()],
            penalty,
            ..OrientSettings::new(weights(1.0, 0.0, 0.0))
        };
        let o = optimise_pass(&path, &tilt, &start, &settings).unwrap();
        assert_feasible(&o.reparam, &settings);
        let trace = pitch_trace(&path, &tilt, &start, &o.reparam, settings.samples);
        let thetas: Vec<f64> = trace.iter().map(|(_, t)| *t).collect();
        assert!(objective_terms(&thetas, &settings)[0] < 1e-6 * o.spu_objective.max(1.0), "{penalty:?}: {o:?}");
        assert!(thetas.iter().all(|t| t.to_degrees() <= -4.99 && t.to_degrees() >= -30.01), "{penalty:?}: {thetas:?}");
    }
}

/// The constant-step resampling keeps the path points equally spaced along
/// the path curve and closes the loop.
#[test]
fn resampling_is_at_a_constant_step_along_the_path() {
    let (path, tilt) = (circle(20.0, 0.0, 360), circle(24.0, 4.0, 200));
    let start = Point3::new(20.0, 0.0, 0.0);
    let r = Reparam { x: [0.5, -0.75, 1.25, 0.0, -0.4, 0.6, 0.8, 0.05] };
    let pairs = synchronise_with(&path, &tilt, &start, 1.0, &r);
    let gaps: Vec<f64> = pairs.windows(2).map(|w| (w[1].path - w[0].path).norm()).collect();
    let (lo, hi) = gaps.iter().fold((f64::INFINITY, 0.0f64), |(a, b), g| (a.min(*g), b.max(*g)));
    assert!(hi - lo < 1e-3 && hi <= 1.0, "{lo} .. {hi}");
    assert!((pairs[0].path - pairs[pairs.len() - 1].path).norm() < 1e-9);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]
    /// Spec 12.1 item 5: after any optimisation the constraints hold at all
    /// samples, and the objective is not above SPU's (random passes, weights,
    /// intervals, targets and options).
    #[test]
    fn optimised_reparameterisation_is_feasible_at_every_sample(
        a in 10.0..40.0f64, b in 10.0..40.0f64, wave in 0.0..0.15f64,
        da in -6.0..6.0f64, db in -6.0..6.0f64, cx in -3.0..3.0f64, cy in -3.0..3.0f64,
        h in 3.0..6.0f64, n in 40usize..120, m in 40usize..120, phase in 0.0..6.3f64,
        w in (0.0..20.0f64, 0.0..10.0f64, 0.0..5.0f64),
        lo in -45.0..10.0f64, width in 5.0..40.0f64, target in -20.0..20.0f64,
        options in (any::<bool>(), any::<bool>(), any::<bool>()), samples in 20usize..120,
    ) {
        let path = lobed(a, b, wave, (0.0, 0.0), 0.0, n, 0.0);
        let tilt = lobed(a + da, b + db, wave * 0.5, (cx, cy), h, m, phase);
        let settings = OrientSettings {
            interval: [lo.to_radians(), (lo + width).to_radians()],
            target: target.to_radians(),
            samples,
            penalty: if options.0 { BoundsPenalty::Printed } else { BoundsPenalty::Smooth },
            coverage: if options.1 { Coverage::Exact } else { Coverage::AtLeast },
            fixed_entry: options.2,
            max_iterations: 40,
            ..OrientSettings::new(weights(w.0, w.1, w.2))
        };
        let o = optimise_pass(&path, &tilt, &Point3::new(a, 0.0, 0.0), &settings).unwrap();
        assert_feasible(&o.reparam, &settings);
        prop_assert!(o.objective <= o.spu_objective);
    }
}
