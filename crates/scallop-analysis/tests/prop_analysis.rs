//! Property tests: critical parameters are inverse functions, plane times are
//! continuous across the kinematic cases, PCA of planar rectangles converges to
//! `w^2/12`, `h^2/12`, incremental statistics equal batch ones, sampling is exact
//! and independent of the thread count.
#![allow(clippy::unwrap_used)]

mod common;

use common::{assert_rel, bilinear};
use proptest::prelude::*;
use scallop_analysis::{
    FeedDirection, GridOptions, KinematicModel, MachineLimits, Moments, Pca, Rectangle, ToolOptions,
    critical_shape_factor, critical_slope, plane_time, sample_mesh, sample_patch,
};
use scallop_geom::nalgebra::{Rotation3, Vector3};
use scallop_geom::rng::SplitMix64;
use scallop_geom::{Point3, Vec3};
use scallop_mesh::TriMesh;
use scallop_surface::Patch;

fn machine_strategy() -> impl Strategy<Value = MachineLimits> {
    (1.0f64..40.0, 0.5f64..10.0, 5.0f64..100.0, prop::bool::ANY).prop_map(|(v, a, j, thesis)| {
        let mut m = MachineLimits::from_thesis_units(v, a, j);
        if thesis {
            m.model = KinematicModel::Thesis;
        }
        m
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    /// mu_c(s_c(mu)) = mu (finishing.md 8.6: exact round trip).
    #[test]
    fn critical_shape_factor_inverts_critical_slope(
        mu in 1.02f64..30.0,
        chi in 50.0f64..50_000.0,
        sh in 0.001f64..0.1,
        corner in 0.5f64..4.5,
        feed in 1.0f64..20.0,
    ) {
        let tools = ToolOptions { corner_radius: corner, ..ToolOptions::default() };
        let machine = MachineLimits::from_thesis_units(feed, 6.0, 40.0);
        let s_c = critical_slope(mu, chi, &tools, sh, &machine);
        prop_assume!(s_c < 0.999 * std::f64::consts::FRAC_PI_2); // not clamped at 90 degrees
        let back = critical_shape_factor(s_c, chi, &tools, sh, &machine);
        prop_assert!(((back - mu) / mu).abs() <= 1e-9, "mu {} -> s_c {} -> mu_c {}", mu, s_c.to_degrees(), back);
    }

    /// s_c decreases with mu (finishing.md 8.7).
    #[test]
    fn critical_slope_decreases_with_shape_factor(mu in 1.0f64..20.0, step in 0.01f64..2.0, chi in 100.0f64..20_000.0) {
        let (tools, machine) = (ToolOptions::default(), MachineLimits::default());
        let a = critical_slope(mu, chi, &tools, 0.01, &machine);
        let b = critical_slope(mu + step, chi, &tools, 0.01, &machine);
        prop_assert!(b <= a + 1e-12);
    }

    /// Segment and plane times are continuous at every kinematic case boundary.
    #[test]
    fn plane_times_continuous_across_kinematic_cases(m in machine_strategy(), width in 20.0f64..200.0, slope in 0.05f64..1.5) {
        let (v, a, j) = (m.feed, m.acceleration, m.jerk);
        let mut boundaries = vec![2.0 * (v.powi(3) / j).sqrt()];
        if v * j > a * a && m.model == KinematicModel::SCurve {
            boundaries.push(2.0 * a.powi(3) / (j * j));
            boundaries.push(v * (v / a + a / j));
        }
        let tools = ToolOptions::default();
        for length in boundaries {
            let (below, above) = (length * (1.0 - 1e-13), length * (1.0 + 1e-13));
            let (t_below, t_above) = (m.segment_time(below), m.segment_time(above));
            prop_assert!((t_below - t_above).abs() <= 1e-9 * t_above, "segment {} vs {} at {}", t_below, t_above, length);
            // Rectangles whose pass length (the height along the slope) crosses the boundary.
            // Toroidal along the slope: passes of length h; ball along S_I: passes of length w.
            let along_slope = |l: f64| Rectangle { width: width.max(l), height: l, slope };
            let along_principal = |l: f64| Rectangle { width: l, height: 0.5 * l, slope };
            for (cutter, feed, rect) in [
                (tools.toroidal(), FeedDirection::SteepestSlope, &along_slope as &dyn Fn(f64) -> Rectangle),
                (tools.ball(), FeedDirection::Principal, &along_principal),
            ] {
                let t_below = plane_time(&rect(below), &cutter, feed, 0.01, &m).time;
                let t_above = plane_time(&rect(above), &cutter, feed, 0.01, &m).time;
                prop_assert!((t_below - t_above).abs() <= 1e-9 * t_above, "plane {} vs {}", t_below, t_above);
            }
        }
    }

    /// PCA of a planar rectangle, any pose, N_u x N_v cell centres:
    /// lambda = w^2 (1 - 1/N_u^2)/12, h^2 (1 - 1/N_v^2)/12 (Annex B), so -> w^2/12, h^2/12.
    #[test]
    fn pca_of_planar_rectangle(
        w in 1.0f64..200.0,
        ratio in 0.05f64..0.95,
        (nu, nv) in (2usize..200, 2usize..200),
        angles in (-3.2f64..3.2, -3.2f64..3.2, -3.2f64..3.2),
        offset in (-500.0f64..500.0, -500.0f64..500.0, -500.0f64..500.0),
    ) {
        let h = w * ratio;
        let rotation = Rotation3::from_euler_angles(angles.0, angles.1, angles.2);
        let t = Vector3::new(offset.0, offset.1, offset.2);
        let corner = |x: f64, y: f64| Point3::from(rotation * Vector3::new(x, y, 0.0) + t);
        let patch = bilinear(corner(-w / 2.0, -h / 2.0), corner(w / 2.0, -h / 2.0), corner(-w / 2.0, h / 2.0), corner(w / 2.0, h / 2.0));
        let samples = sample_patch(&patch, &GridOptions { cells_u: nu, cells_v: nv }).unwrap();
        let pca = Pca::from_moments(&samples.moments());
        let (nu, nv) = (nu as f64, nv as f64);
        let mut expected = [w * w * (1.0 - 1.0 / (nu * nu)) / 12.0, h * h * (1.0 - 1.0 / (nv * nv)) / 12.0];
        expected.sort_by(|a, b| b.total_cmp(a));
        prop_assert!(((pca.eigenvalues[0] - expected[0]) / expected[0]).abs() <= 1e-9);
        prop_assert!(((pca.eigenvalues[1] - expected[1]) / expected[1]).abs() <= 1e-9);
        prop_assert!(pca.eigenvalues[2] <= 1e-9 * w * w);
        // Convergence: within the cell-centre deficit of the continuous values.
        prop_assert!(pca.eigenvalues[0] <= w * w / 12.0 * (1.0 + 1e-9));
        prop_assert!(w * w / 12.0 - pca.eigenvalues[0] <= w * w / (12.0 * nu.min(nv).powi(2)) * (1.0 + 1e-9) + 1e-9 * w * w);
        // The PCA plane is the rectangle's plane.
        let normal = rotation * Vector3::z();
        prop_assert!((pca.axes[2].dot(&normal).abs() - 1.0).abs() <= 1e-9);
        prop_assert!((pca.slope() - normal.z.abs().min(1.0).acos()).abs() <= 1e-6);
    }

    /// Incremental add/remove (stable form) equals batch statistics after 10^5 operations.
    #[test]
    fn incremental_equals_batch(seed in any::<u64>(), center in -1000.0f64..1000.0, spread in 0.1f64..100.0) {
        let mut rng = SplitMix64::new(seed);
        let mut moments = Moments::new();
        let mut present: Vec<Point3> = Vec::new();
        for _ in 0..100_000 {
            if present.len() < 10 || (present.len() < 1000 && rng.next_u64().is_multiple_of(2)) {
                let p = Point3::new(
                    center + spread * rng.uniform(-1.0, 1.0),
                    center + spread * rng.uniform(-1.0, 1.0),
                    center + 0.1 * spread * rng.uniform(-1.0, 1.0),
                );
                moments.add(&p, 1.0);
                present.push(p);
            } else {
                let k = (rng.next_u64() % present.len() as u64) as usize;
                moments.remove(&present.swap_remove(k), 1.0);
            }
        }
        let batch = Moments::of_points(&present);
        let err = (moments.covariance() - batch.covariance()).norm() / batch.covariance().norm();
        prop_assert!(err <= 1e-9, "relative {}", err);
        prop_assert!((moments.mean() - batch.mean()).norm() <= 1e-9 * batch.mean().coords.norm().max(1.0));
    }

    /// A mesh rectangle (two triangles, any pose) has lambda = w^2/12, h^2/12 exactly.
    #[test]
    fn mesh_pca_is_exact(w in 1.0f64..100.0, ratio in 0.05f64..0.95, angles in (-3.2f64..3.2, -3.2f64..3.2, -3.2f64..3.2)) {
        let h = w * ratio;
        let rotation = Rotation3::from_euler_angles(angles.0, angles.1, angles.2);
        let c = |x: f64, y: f64| Point3::from(rotation * Vector3::new(x, y, 0.0));
        let (mesh, _) = TriMesh::from_soup(&[[c(0.0, 0.0), c(w, 0.0), c(w, h)], [c(0.0, 0.0), c(w, h), c(0.0, h)]]).unwrap();
        let pca = Pca::from_moments(&sample_mesh(&mesh).moments());
        prop_assert!(((pca.eigenvalues[0] - w * w / 12.0) / (w * w / 12.0)).abs() <= 1e-9);
        prop_assert!(((pca.eigenvalues[1] - h * h / 12.0) / (h * h / 12.0)).abs() <= 1e-9);
    }
}

fn assert_samples_match_patch(patch: &Patch, n: usize) {
    let samples = sample_patch(patch, &GridOptions { cells_u: n, cells_v: n + 3 }).unwrap();
    let flip = if samples.samples()[0].normal.dot(&patch.normal(0.5 / n as f64, 0.5 / (n + 3) as f64)) < 0.0 {
        -1.0
    } else {
        1.0
    };
    for s in samples.samples() {
        let [u, v] = s.uv.unwrap();
        let d = patch.derivatives(u, v);
        let scale = d.point.coords.norm().max(1.0);
        assert!((s.point - d.point).norm() <= 1e-12 * scale, "point at ({u}, {v})");
        assert!((s.normal - patch.normal(u, v) * flip).norm() <= 1e-12, "normal at ({u}, {v})");
        let weight = d.du.cross(&d.dv).norm() / (n * (n + 3)) as f64;
        assert_rel(s.weight, weight, 1e-12, "cell area");
    }
}

#[test]
fn fast_bezier_evaluation_matches_patch() {
    for name in ["choi", "rubio"] {
        assert_samples_match_patch(&scallop_surface::builtin(name).unwrap().patches()[0], 37);
    }
    let p = |x, y, z| Point3::new(x, y, z);
    let rational = Patch::bezier(
        "rational",
        [2, 1],
        &[
            vec![p(0., 0., 0.), p(0., 10., 1.)],
            vec![p(5., 0., 4.), p(5., 10., 6.)],
            vec![p(10., 0., 0.), p(10., 10., 2.)],
        ],
        Some(&[vec![1.0, 1.0], vec![0.5, 2.0], vec![1.0, 1.0]]),
    )
    .unwrap();
    assert_samples_match_patch(&rational, 23);
}

#[test]
fn sampling_and_moments_independent_of_thread_count() {
    let set = scallop_surface::builtin("rubio").unwrap();
    let grid = GridOptions { cells_u: 300, cells_v: 250 };
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let samples = sample_patch(&set.patches()[0], &grid).unwrap();
            let moments = samples.moments();
            let report =
                scallop_analysis::analyze(&samples, &ToolOptions::default(), &MachineLimits::default(), 0.01).unwrap();
            (samples, moments, report)
        })
    };
    let (a, b) = (run(1), run(3));
    assert!(a.0 == b.0, "samples differ");
    assert!(a.1 == b.1, "moments differ");
    assert!(a.2 == b.2, "reports differ");
}

#[test]
fn normals_oriented_upward() {
    // A patch whose parametrisation gives downward normals is flipped globally.
    let p = |x, y| Point3::new(x, y, 0.1 * x);
    let down = bilinear(p(0.0, 0.0), p(0.0, 10.0), p(10.0, 0.0), p(10.0, 10.0));
    assert!(down.normal(0.5, 0.5).z < 0.0);
    let samples = sample_patch(&down, &GridOptions { cells_u: 4, cells_v: 4 }).unwrap();
    assert!(samples.samples().iter().all(|s| s.normal.z > 0.0));
    let _ = Vec3::z();
}

#[test]
fn nurbs_path_matches_bezier_path() {
    // The Choi patch as a clamped NURBS over [2, 5] x [-1, 1]: the generic path
    // (Patch::derivatives) must give the same points, normals and features as the
    // Bezier tables; cell areas scale with the domain (du dv = 3 * 2 / N^2 times
    // |S_u x S_v| in the new parameters, i.e. the same surface area).
    let set = scallop_surface::builtin("choi").unwrap();
    let bezier = &set.patches()[0];
    let control: Vec<Vec<Point3>> = (0..4).map(|i| (0..4).map(|j| bezier.control_point(i, j)).collect()).collect();
    let knots = |a: f64, b: f64| vec![a, a, a, a, b, b, b, b];
    let nurbs = Patch::nurbs("choi nurbs", [3, 3], [knots(2.0, 5.0), knots(-1.0, 1.0)], &control, None).unwrap();
    let grid = GridOptions { cells_u: 17, cells_v: 11 };
    let (a, b) = (sample_patch(bezier, &grid).unwrap(), sample_patch(&nurbs, &grid).unwrap());
    for (x, y) in a.samples().iter().zip(b.samples()) {
        assert!((x.point - y.point).norm() <= 1e-12 * 100.0);
        assert!((x.normal - y.normal).norm() <= 1e-12);
        assert_rel(y.weight, x.weight, 1e-12, "cell area");
        assert_eq!(x.uv, y.uv);
    }
    let (ma, mb) = (a.moments(), b.moments());
    assert!((ma.covariance() - mb.covariance()).norm() <= 1e-9 * ma.covariance().norm());
}

#[test]
fn surface_set_concatenates_patches() {
    let set = scallop_surface::builtin("rubio").unwrap();
    let grid = GridOptions { cells_u: 9, cells_v: 7 };
    let single = scallop_analysis::sample_surface_set(&set, &grid).unwrap();
    assert!(single == sample_patch(&set.patches()[0], &grid).unwrap());
    let p = |x, y| Point3::new(x, y, 0.0);
    let q = |x, y| Point3::new(x, y, 5.0);
    let two = scallop_surface::SurfaceSet::new(vec![
        bilinear(p(0.0, 0.0), p(10.0, 0.0), p(0.0, 10.0), p(10.0, 10.0)),
        Patch::bezier("upper", [1, 1], &[vec![q(0.0, 0.0), q(0.0, 10.0)], vec![q(10.0, 0.0), q(10.0, 10.0)]], None)
            .unwrap(),
    ])
    .unwrap();
    let both = scallop_analysis::sample_surface_set(&two, &grid).unwrap();
    assert_eq!(both.len(), 2 * 63);
    assert_eq!(both.grid(), None);
    assert!((both.moments().mean().z - 2.5).abs() < 1e-12);
}
