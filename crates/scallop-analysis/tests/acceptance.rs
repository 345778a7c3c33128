//! Acceptance tests A1-A12 and A14-A19 of finishing.md 16 that belong to surface
//! analysis (A13, connected components, belongs to partitioning). Tolerances are the
//! table's. Inputs are the default parameters unless stated.
#![allow(clippy::unwrap_used)]

mod common;

use std::f64::consts::FRAC_PI_2;

use common::{assert_abs, assert_rel, bilinear, builtin_samples, direction_diff_deg, plane_56x28};
use scallop_analysis::{
    CrossPlane, Cutter, FeedDirection, GridOptions, KinematicModel, MachineLimits, Moments, Pca, Recommendation,
    Rectangle, ToolOptions, analyze, critical_shape_factor, critical_slope, plane_time, rectangle_time_at_angle,
    sample_patch, sample_patch_masked, step_over,
};
use scallop_geom::Point3;
use scallop_geom::nalgebra::Matrix3;
use scallop_geom::rng::SplitMix64;

const SH: f64 = 0.01;

fn machine() -> MachineLimits {
    MachineLimits::default()
}

fn tools() -> ToolOptions {
    ToolOptions::default()
}

#[test]
fn a1_kinematic_constants() {
    let m = machine();
    // Independent SI evaluation: V = 5/60 m/s, A = 6 m/s^2, J = 40 m/s^3.
    let (v, a, j): (f64, f64, f64) = (5.0 / 60.0, 6.0, 40.0);
    assert_rel(m.time_to_acceleration(), a / j, 1e-9, "t_A");
    assert_rel(m.time_to_acceleration(), 0.15, 1e-9, "t_A printed");
    assert_rel(m.time_to_feed(), (v / j).sqrt(), 1e-9, "t_V");
    assert_abs(m.time_to_feed(), 0.04564, 1e-5, "t_V printed");
    assert_rel(m.critical_segment_length(), 1000.0 * 2.0 * (v * v * v / j).sqrt(), 1e-9, "critical length");
    assert_abs(m.critical_segment_length(), 7.607, 1e-3, "critical length printed");
    // Cases 2 and 3 meet at l = sqrt(V^3/J) with the value 4 sqrt(V/J).
    let l = (m.feed.powi(3) / m.jerk).sqrt();
    let case2 = 2.0 * l / m.feed + 2.0 * m.time_to_feed();
    let case3 = 4.0 * (l / m.jerk).cbrt();
    assert_rel(case2, 4.0 * m.time_to_feed(), 1e-9, "case 2 at the boundary");
    assert_rel(case3, 4.0 * m.time_to_feed(), 1e-9, "case 3 at the boundary");
    for model in [KinematicModel::SCurve, KinematicModel::Thesis] {
        let m = MachineLimits { model, ..m };
        assert_rel(m.segment_time(2.0 * l * (1.0 - 1e-12)), 4.0 * m.time_to_feed(), 1e-9, "just below");
        assert_rel(m.segment_time(2.0 * l * (1.0 + 1e-12)), 4.0 * m.time_to_feed(), 1e-9, "just above");
    }
}

#[test]
fn a2_effective_radius() {
    let torus = tools().toroidal();
    assert_abs(torus.effective_radius(60f64.to_radians(), 0.0), 5.4641, 1e-4, "R_eff printed");
    assert_abs(torus.effective_radius(60f64.to_radians(), 0.0), 3.0 / 60f64.to_radians().sin() + 2.0, 1e-6, "Eq. 2.2");
    assert_abs(tools().ball().effective_radius(1.0, 0.3), 5.0, 0.0, "ball");
    // Across the slope the corner radius cuts.
    assert_abs(torus.effective_radius(60f64.to_radians(), FRAC_PI_2), 2.0, 1e-12, "alpha = 90");
    let flat = Cutter::Flat { radius: 5.0, inclination: 30f64.to_radians() };
    assert_abs(flat.effective_radius(0.3, 0.2), 10.0, 1e-12, "flat R / sin(phi)");
}

#[test]
fn a3_analytic_plane_56x28() {
    let rect = Rectangle { width: 56.0, height: 28.0, slope: 60f64.to_radians() };
    let t1 = plane_time(&rect, &tools().toroidal(), FeedDirection::SteepestSlope, SH, &machine());
    let t2 = plane_time(&rect, &tools().ball(), FeedDirection::Principal, SH, &machine());
    assert_abs(t1.step_over, 0.6609, 1e-4, "sod1");
    assert_abs(t2.step_over, 0.6321, 1e-4, "sod2");
    assert_rel(t1.time, 43.06, 5e-4, "T1");
    assert_rel(t1.length, 2428.7, 5e-4, "L1");
    assert_rel(t2.time, 37.34, 5e-4, "T2");
    assert_rel(t2.length, 2508.5, 5e-4, "L2");
    // The corrected closed forms of 8.2 and 8.3, evaluated independently in SI.
    let (v, j, sh): (f64, f64, f64) = (5.0 / 60.0, 40.0, 1e-5);
    let (mu, chi): (f64, f64) = (2.0, 0.056 * 0.028);
    let sod1 = 2.0 * (2.0 * sh * (3e-3 / 60f64.to_radians().sin() + 2e-3) - sh * sh).sqrt();
    let sod2 = 2.0 * (2.0 * sh * 5e-3 - sh * sh).sqrt();
    let big_t1 = (mu * chi).sqrt() / sod1
        * (chi.sqrt() / (mu.sqrt() * v) + 2.0 * (v / j).sqrt() + 4.0 * (sod1 / (2.0 * j)).cbrt());
    let big_l1 = chi / sod1 + (mu * chi).sqrt();
    let n2 = chi.sqrt() / (mu.sqrt() * sod2);
    let big_t2 = n2 * ((chi * mu).sqrt() / v + 2.0 * (v / j).sqrt() + 4.0 * (sod2 / (2.0 * j)).cbrt());
    let big_l2 = n2 * ((chi * mu).sqrt() + sod2);
    assert_rel(t1.time, big_t1, 1e-9, "T1 closed form");
    assert_rel(t1.length, 1000.0 * big_l1, 1e-9, "L1 closed form");
    assert_rel(t2.time, big_t2, 1e-9, "T2 closed form");
    assert_rel(t2.length, 1000.0 * big_l2, 1e-9, "L2 closed form");
}

#[test]
fn a4_critical_slope_mu2() {
    let s_c = critical_slope(2.0, 1568.0, &tools(), SH, &machine()).to_degrees();
    assert_abs(s_c, 33.8, 0.1, "s_c(2) printed");
    assert_abs(s_c, 33.86, 0.01, "s_c(2) derived");
}

#[test]
fn a5_critical_slope_table() {
    let mus = [1.1, 1.25, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 7.0, 9.0];
    let rows: [(f64, f64, [f64; 10]); 3] = [
        (0.01, 1568.0, [66.54, 55.10, 44.68, 33.86, 27.88, 23.96, 18.99, 15.90, 12.16, 9.93]),
        (0.01, 3137.0, [69.46, 59.23, 49.70, 39.44, 33.57, 29.60, 24.40, 21.05, 16.83, 14.20]),
        (0.1, 1568.0, [64.82, 52.68, 41.79, 30.69, 24.70, 20.84, 16.05, 13.14, 9.71, 7.73]),
    ];
    for (sh, chi, expected) in rows {
        for (mu, want) in mus.iter().zip(expected) {
            let s_c = critical_slope(*mu, chi, &tools(), sh, &machine());
            assert_abs(s_c.to_degrees(), want, 0.1, &format!("s_c(mu = {mu}, chi = {chi}, sh = {sh})"));
            let back = critical_shape_factor(s_c, chi, &tools(), sh, &machine());
            assert_rel(back, *mu, 1e-9, &format!("mu_c(s_c({mu}))"));
        }
        let at_one = critical_slope(1.0, chi, &tools(), sh, &machine());
        assert_abs(at_one.to_degrees(), 90.0, 1e-3, "s_c(1)");
    }
}

#[test]
fn a6_critical_slope_of_test_cases() {
    // Fed with the thesis's printed PCA values.
    let rubio = critical_slope(2.07, 3315.47, &tools(), SH, &machine()).to_degrees();
    let choi = critical_slope(1.19, 3137.0, &tools(), SH, &machine()).to_degrees();
    assert_abs(rubio, 38.9, 0.1, "Rubio s_c");
    assert_abs(choi, 62.6, 0.1, "Choi s_c");
    // Full pipeline, derived PCA values.
    for (name, thesis, derived) in [("rubio", 38.9, 38.86), ("choi", 62.6, 62.39)] {
        let report = analyze(&builtin_samples(name, 80), &tools(), &machine(), SH).unwrap();
        assert_abs(report.critical_slope_deg, thesis, 0.3, &format!("{name} pipeline s_c vs thesis"));
        assert_abs(report.critical_slope_deg, derived, 0.01, &format!("{name} pipeline s_c vs derived"));
    }
}

#[test]
fn a7_pca_choi() {
    let samples = builtin_samples("choi", 80);
    let pca = Pca::from_moments(&samples.moments());
    assert_abs(pca.eigenvalues[0], 312.07, 0.02, "lambda_I");
    assert_abs(pca.eigenvalues[1], 219.02, 0.02, "lambda_II");
    assert_abs(pca.eigenvalues[2], 3.21, 0.01, "lambda_III derived");
    assert_abs(pca.shape_factor(), 1.19, 0.01, "mu");
    assert_abs(pca.size(), 3137.0, 1.0, "chi");
    assert_abs(direction_diff_deg(pca.principal_direction().to_degrees(), 90.0), 0.0, 0.1, "principal direction");
    assert_abs(direction_diff_deg(pca.slope_direction().to_degrees(), 0.0), 0.0, 0.1, "slope direction");
    assert_abs(pca.slope().to_degrees(), 17.18, 0.1, "tilt derived");
    assert_abs(pca.slope().to_degrees(), 17.13, 0.1, "tilt thesis");
}

#[test]
fn a8_pca_rubio() {
    let samples = builtin_samples("rubio", 80);
    let pca = Pca::from_moments(&samples.moments());
    assert_rel(pca.eigenvalues[0], 572.62, 1e-3, "lambda_I");
    assert_rel(pca.eigenvalues[1], 133.31, 1e-3, "lambda_II");
    assert_abs(pca.eigenvalues[0], 572.61, 0.01, "lambda_I derived");
    assert_abs(pca.eigenvalues[1], 133.23, 0.01, "lambda_II derived");
    assert_abs(pca.shape_factor(), 2.07, 0.01, "mu");
    assert_rel(pca.size(), 3315.47, 1e-3, "chi");
    assert_abs(pca.slope().to_degrees(), 42.34, 0.1, "tilt");
    assert_abs(direction_diff_deg(pca.slope_direction().to_degrees(), 66.97), 0.0, 0.2, "slope direction");
    assert_abs(pca.principal_direction(), -0.17, 0.005, "principal direction (rad)");
    assert_abs(pca.principal_direction().to_degrees(), -9.94, 0.01, "principal direction derived");
}

#[test]
fn a9_tool_choice_predictions() {
    let rubio = analyze(&builtin_samples("rubio", 80), &tools(), &machine(), SH).unwrap();
    assert_eq!(rubio.recommendation, Recommendation::BallAlongPrincipal);
    let choi = analyze(&builtin_samples("choi", 80), &tools(), &machine(), SH).unwrap();
    assert_eq!(choi.recommendation, Recommendation::ToroidalAlongSlope);
    let plane = sample_patch(&plane_56x28(), &GridOptions::default()).unwrap();
    let plane = analyze(&plane, &tools(), &machine(), SH).unwrap();
    assert_eq!(plane.recommendation, Recommendation::BallAlongPrincipal);
    assert_abs(plane.shape_factor, 2.0, 1e-9, "plane mu");
    assert_abs(plane.slope_deg, 60.0, 1e-9, "plane slope");
    // The Annex A.2 rule agrees: mu < mu_c(s) <=> toroidal.
    for report in [&rubio, &choi, &plane] {
        let toroidal = report.shape_factor < report.critical_shape_factor.unwrap();
        assert_eq!(toroidal, report.recommendation == Recommendation::ToroidalAlongSlope);
    }
    assert_abs(rubio.critical_shape_factor.unwrap(), 1.85, 0.01, "Rubio mu_c");
    assert_abs(choi.critical_shape_factor.unwrap(), 6.8, 0.1, "Choi mu_c");
    assert_abs(plane.critical_shape_factor.unwrap(), 1.174, 1e-3, "plane mu_c");
}

#[test]
fn a10_annex_b_rectangle() {
    let (w, h) = (37.0, 11.0);
    let patch = bilinear(
        Point3::new(-w / 2.0, -h / 2.0, 0.0),
        Point3::new(w / 2.0, -h / 2.0, 0.0),
        Point3::new(-w / 2.0, h / 2.0, 0.0),
        Point3::new(w / 2.0, h / 2.0, 0.0),
    );
    for (nu, nv) in [(80, 80), (7, 13), (200, 150)] {
        let samples = sample_patch(&patch, &GridOptions { cells_u: nu, cells_v: nv }).unwrap();
        let pca = Pca::from_moments(&samples.moments());
        let (nu, nv) = (nu as f64, nv as f64);
        assert_rel(pca.eigenvalues[0], w * w * (1.0 - 1.0 / (nu * nu)) / 12.0, 1e-9, "lambda_I");
        assert_rel(pca.eigenvalues[1], h * h * (1.0 - 1.0 / (nv * nv)) / 12.0, 1e-9, "lambda_II");
        assert_abs(pca.eigenvalues[2], 0.0, 1e-12, "lambda_III");
        let c = samples.moments().covariance();
        for (r, k) in [(0, 1), (0, 2), (1, 2)] {
            assert_abs(c[(r, k)], 0.0, 1e-12, "covariances vanish");
        }
    }
}

fn cross_samples(cross: &CrossPlane, cell: f64) -> scallop_analysis::Samples {
    let (half_x, half_y) = (cross.bar_width / 2.0, cross.bar_height / 2.0 + cross.arm_length);
    let patch = bilinear(
        Point3::new(-half_x, -half_y, 0.0),
        Point3::new(half_x, -half_y, 0.0),
        Point3::new(-half_x, half_y, 0.0),
        Point3::new(half_x, half_y, 0.0),
    );
    let (nu, nv) = ((2.0 * half_x / cell).round() as usize, (2.0 * half_y / cell).round() as usize);
    sample_patch_masked(&patch, &GridOptions { cells_u: nu, cells_v: nv }, |a, b| {
        let x = -half_x + (a as f64 + 0.5) * cell;
        let y = -half_y + (b as f64 + 0.5) * cell;
        cross.contains(x, y)
    })
    .unwrap()
}

#[test]
fn a11_cross_covariance() {
    let cross = CrossPlane::THESIS;
    let samples = cross_samples(&cross, 1.0);
    assert_eq!(samples.len(), 3200, "1 mm cells over a 3200 mm^2 cross");
    let c = samples.moments().covariance();
    let [var_x, var_y] = cross.variances();
    assert_rel(c[(0, 0)], var_x, 5e-4, "Var(Sx)");
    assert_rel(c[(1, 1)], var_y, 5e-4, "Var(Sy)");
    assert!(var_x > var_y && c[(0, 0)] > c[(1, 1)], "principal direction is X");
    assert_abs(c[(0, 1)], 0.0, 1e-9, "Cov(Sx, Sy)");
    let pca = Pca::from_moments(&samples.moments());
    assert_abs(direction_diff_deg(pca.principal_direction().to_degrees(), 0.0), 0.0, 1e-6, "S_I along X");
}

#[test]
fn a11_cross_formulas() {
    let cross = CrossPlane::THESIS;
    let times = cross.times(5.0, SH, &machine());
    // Independent SI evaluation of the 14.4 formulas (corrected T2 with w/V).
    let (w, h, q, p): (f64, f64, f64, f64) = (0.08, 0.03, 0.01, 0.04);
    let (v, j, sh, r): (f64, f64, f64, f64) = (5.0 / 60.0, 40.0, 1e-5, 5e-3);
    let sod = 2.0 * (2.0 * sh * r - sh * sh).sqrt();
    let k_c = 2.0 * (v / j).sqrt() + 4.0 * (sod / (2.0 * j)).cbrt();
    let x_l = 2.0 * (p / sod) * (q + sod) + (h / sod) * (w + sod);
    let x_t = 2.0 * (p / sod) * (q / v + k_c) + (h / sod) * (w / v + k_c);
    let y_l = 2.0 * ((w - q) / (2.0 * sod)) * (h + sod) + (q / sod) * (h + 2.0 * p + sod);
    let y_t = 2.0 * ((w - q) / (2.0 * sod)) * (h / v + k_c) + (q / sod) * ((h + 2.0 * p) / v + k_c);
    let z_l = (h / sod) * (w + sod) + 2.0 * (q / sod) * (p + sod);
    let z_t = (h / sod) * (w / v + k_c) + 2.0 * (q / sod) * (p / v + k_c);
    for (got, (length, time), what) in [
        (times.along_x, (x_l, x_t), "along X"),
        (times.along_y, (y_l, y_t), "along Y"),
        (times.three_zones, (z_l, z_t), "three zones"),
    ] {
        assert_rel(got.length, 1000.0 * length, 1e-9, &format!("{what} length"));
        assert_rel(got.time, time, 1e-9, &format!("{what} time"));
    }
    // The counter-example: the principal direction X is not the fastest single zone.
    assert!(times.along_y.time < times.along_x.time && times.three_zones.time < times.along_y.time);
}

/// Batch population covariance of weighted points, two-pass, for reference.
fn batch(points: &[(Point3, f64)]) -> (Point3, Matrix3<f64>) {
    let total: f64 = points.iter().map(|(_, w)| w).sum();
    let mean = points.iter().fold(scallop_geom::Vec3::zeros(), |m, (p, w)| m + p.coords * *w) / total;
    let cov = points.iter().fold(Matrix3::zeros(), |c, (p, w)| {
        let d = p.coords - mean;
        c + d * d.transpose() * *w
    }) / total;
    (Point3::from(mean), cov)
}

#[test]
fn a12_incremental_covariance() {
    for weighted in [false, true] {
        let mut rng = SplitMix64::new(if weighted { 7 } else { 3 });
        let mut moments = Moments::new();
        let mut present: Vec<(Point3, f64)> = Vec::new();
        for op in 0..100_000 {
            let add = present.len() < 20 || (present.len() < 2000 && rng.uniform(0.0, 1.0) < 0.5);
            if add {
                let p = Point3::new(rng.uniform(80.0, 140.0), rng.uniform(-30.0, 30.0), rng.uniform(10.0, 12.0));
                let w = if weighted { rng.uniform(0.1, 3.0) } else { 1.0 };
                moments.add(&p, w);
                present.push((p, w));
            } else {
                let k = (rng.next_u64() % present.len() as u64) as usize;
                let (p, w) = present.swap_remove(k);
                moments.remove(&p, w);
            }
            if op % 20_000 == 19_999 || op == 99_999 {
                let (mean, cov) = batch(&present);
                let err = (moments.covariance() - cov).norm() / cov.norm();
                assert!(err <= 1e-9, "covariance after {op} ops (weighted {weighted}): relative {err}");
                assert!((moments.mean() - mean).norm() <= 1e-9 * mean.coords.norm(), "mean");
                assert_eq!(moments.count(), present.len());
            }
        }
    }
}

#[test]
fn a12_thesis_forms_equal_stable_form() {
    // Eqs. 3.5 and 3.6 (Annex D (12), (16)) on (n, E, Sigma).
    let thesis_add = |n: f64, e: &scallop_geom::Vec3, s: &Matrix3<f64>, x: &scallop_geom::Vec3| {
        let e1 = e * (n / (n + 1.0)) + x / (n + 1.0);
        let s1 = (s + e * e.transpose()) * (n / (n + 1.0)) + x * x.transpose() / (n + 1.0) - e1 * e1.transpose();
        (e1, s1)
    };
    let thesis_remove = |n: f64, e: &scallop_geom::Vec3, s: &Matrix3<f64>, x: &scallop_geom::Vec3| {
        let e1 = e * (n / (n - 1.0)) - x / (n - 1.0);
        let s1 = (s + e * e.transpose()) * (n / (n - 1.0)) - x * x.transpose() / (n - 1.0) - e1 * e1.transpose();
        (e1, s1)
    };
    let mut rng = SplitMix64::new(11);
    let mut moments = Moments::new();
    let (mut e, mut s) = (scallop_geom::Vec3::zeros(), Matrix3::zeros());
    let mut present: Vec<scallop_geom::Vec3> = Vec::new();
    for _ in 0..2000 {
        let n = present.len() as f64;
        if present.len() < 5 || rng.uniform(0.0, 1.0) < 0.5 {
            let x = scallop_geom::Vec3::new(rng.uniform(-20.0, 20.0), rng.uniform(-10.0, 10.0), rng.uniform(-2.0, 2.0));
            (e, s) = thesis_add(n, &e, &s, &x);
            moments.add(&Point3::from(x), 1.0);
            present.push(x);
        } else {
            let k = (rng.next_u64() % present.len() as u64) as usize;
            let x = present.swap_remove(k);
            (e, s) = thesis_remove(n, &e, &s, &x);
            moments.remove(&Point3::from(x), 1.0);
        }
        if present.len() < 2 {
            continue;
        }
        let err = (moments.covariance() - s).norm() / s.norm();
        assert!(err <= 1e-9, "thesis form vs stable form: relative {err}");
        assert!((moments.mean().coords - e).norm() <= 1e-9 * e.norm().max(1.0));
    }
}

#[test]
fn a14_full_s_curve() {
    // V J > A^2: V = 30 m/min, A = 2 m/s^2, J = 40 m/s^3.
    let m = MachineLimits::from_thesis_units(30.0, 2.0, 40.0);
    let (v, a, j) = (m.feed, m.acceleration, m.jerk);
    assert!(v * j > a * a);
    let l_a = a.powi(3) / (j * j);
    let l_va = v * (v / a + a / j) / 2.0;
    for l in [l_a, l_va] {
        let below = m.segment_time(2.0 * l * (1.0 - 1e-14));
        let above = m.segment_time(2.0 * l * (1.0 + 1e-14));
        assert_rel(below, above, 1e-12, "continuity");
    }
    // Case values at the boundaries.
    assert_rel(m.segment_time(2.0 * l_a), 4.0 * a / j, 1e-12, "l_A");
    assert_rel(m.segment_time(2.0 * l_va), 2.0 * l_va / v + a / j + v / a, 1e-12, "l_VA");
    // Equals the thesis model whenever V J <= A^2.
    for feed in [1.0, 5.0, 10.0] {
        let s_curve = MachineLimits::from_thesis_units(feed, 6.0, 40.0);
        let thesis = MachineLimits { model: KinematicModel::Thesis, ..s_curve };
        for k in 0..200 {
            let length = 0.01 * 1.07f64.powi(k);
            assert_rel(s_curve.segment_time(length), thesis.segment_time(length), 1e-12, "S-curve = thesis");
        }
    }
}

#[test]
fn a15_annex_e_limits() {
    let m = machine();
    let (w, h) = (56.0, 28.0);
    let p = step_over(SH, 5.0);
    let overhead = 2.0 * m.time_to_feed() + 4.0 * (p / (2.0 * m.jerk)).cbrt();
    let t2_form = h / p * (w / m.feed + overhead);
    let t1_form = w / p * (h / m.feed + overhead);
    assert_rel(rectangle_time_at_angle(w, h, 0.0, p, &m), t2_form, 1e-9, "alpha = 0");
    assert_rel(rectangle_time_at_angle(w, h, FRAC_PI_2, p, &m), t1_form, 1e-9, "alpha = pi/2");
    assert_rel(rectangle_time_at_angle(w, h, 1e-12, p, &m), t2_form, 1e-7, "alpha = 1e-12");
    assert_rel(rectangle_time_at_angle(w, h, FRAC_PI_2 - 1e-12, p, &m), t1_form, 1e-7, "alpha = pi/2 - 1e-12");
    let switch = (h / w).atan();
    let below = rectangle_time_at_angle(w, h, switch * (1.0 - 1e-13), p, &m);
    let above = rectangle_time_at_angle(w, h, switch * (1.0 + 1e-13), p, &m);
    assert_rel(below, above, 1e-9, "cases meet at tan(alpha) = h/w");
    // With the plane step-overs, the annex reproduces T2 and T1 of 8.2-8.3.
    let rect = Rectangle { width: w, height: h, slope: 60f64.to_radians() };
    let t2 = plane_time(&rect, &tools().ball(), FeedDirection::Principal, SH, &m);
    assert_rel(rectangle_time_at_angle(w, h, 0.0, t2.step_over, &m), t2.time, 1e-9, "T2");
    let t1 = plane_time(&rect, &tools().toroidal(), FeedDirection::SteepestSlope, SH, &m);
    assert_rel(rectangle_time_at_angle(w, h, FRAC_PI_2, t1.step_over, &m), t1.time, 1e-9, "T1");
}

#[test]
fn a15_annex_e_on_pca_plane() {
    // Annex E on the sampled 56 x 28 plane: feed along X_I (Y) is T2 with the ball;
    // feed along the slope (X) is T1 with the toroidal cutter.
    let samples = sample_patch(&plane_56x28(), &GridOptions { cells_u: 400, cells_v: 400 }).unwrap();
    let pca = Pca::from_moments(&samples.moments());
    let rect = Rectangle { width: pca.width(), height: pca.height(), slope: pca.slope() };
    let m = machine();
    let ball = scallop_analysis::annex_e_time(&pca, FRAC_PI_2, &tools().ball(), SH, &m);
    let t2 = plane_time(&rect, &tools().ball(), FeedDirection::Principal, SH, &m);
    assert_rel(ball, t2.time, 1e-9, "ball along X_I");
    let torus = scallop_analysis::annex_e_time(&pca, 0.0, &tools().toroidal(), SH, &m);
    let t1 = plane_time(&rect, &tools().toroidal(), FeedDirection::SteepestSlope, SH, &m);
    assert_rel(torus, t1.time, 1e-9, "toroidal along the slope");
}

#[test]
fn a16_horizontal_plane_cap() {
    assert_abs(tools().toroidal().max_step_over(SH), 6.3995, 1e-4, "sod_max");
    let exact = 2.0 * 3.0 + 2.0 * (2.0 * 2.0 * SH - SH * SH).sqrt();
    assert_abs(tools().toroidal().max_step_over(SH), exact, 1e-12, "sod_max formula");
    assert_abs(tools().toroidal().step_over(SH, 0.0, 0.3), exact, 1e-12, "horizontal step-over is capped");
}

#[test]
fn a17_critical_slope_at_mu_one() {
    for chi in [200.0, 1568.0, 3137.0, 20_000.0] {
        let s_c = critical_slope(1.0, chi, &tools(), SH, &machine());
        assert_abs(s_c.to_degrees(), 90.0, 1e-3, "s_c(1)");
    }
}

#[test]
fn a18_eq_2_16_guard() {
    for (name, tilt, printed) in [("rubio", 42.35, 47.65), ("choi", 17.18, 72.82)] {
        let pca = Pca::from_moments(&builtin_samples(name, 80).moments());
        assert_abs(pca.slope().to_degrees(), tilt, 0.01, &format!("{name} tilt"));
        // The printed Eq. 2.16, pi/2 - arccos(S_III . Z), is the complement: not used.
        let eq_2_16 = 90.0 - pca.axes[2].z.acos().to_degrees();
        assert_abs(eq_2_16, printed, 0.01, &format!("{name} printed Eq. 2.16"));
        assert!((pca.slope().to_degrees() - eq_2_16).abs() > 1.0);
    }
}

#[test]
fn a19_oblique_effective_radius() {
    let (s, alpha) = (60f64.to_radians(), 45f64.to_radians());
    let r_eff = tools().toroidal().effective_radius(s, alpha);
    let alpha_t = (s.cos() * alpha.tan()).atan();
    assert_abs(alpha_t.to_degrees(), 26.565, 1e-3, "alpha_t");
    let tangent_form = 3.0 * alpha_t.cos().powi(2) / s.sin() + 2.0;
    assert_abs(r_eff, tangent_form, 1e-6, "Eq. 1.5 = tangent-plane form");
    assert_abs(r_eff, 4.77128, 1e-5, "printed");
}
