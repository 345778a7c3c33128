//! Degenerate inputs give the documented, finite answers (never NaN), or a typed error.
// Exact float comparisons check the documented exact answers (0, 90 degrees, +inf, the cap).
#![allow(clippy::unwrap_used, clippy::float_cmp)]

mod common;

use common::{assert_abs, bilinear};
use scallop_analysis::{
    AnalysisError, AnalysisReport, GridOptions, MachineLimits, Note, Pca, PcaWeighting, Recommendation, Sample,
    Samples, ToolOptions, analyze, annex_e_time, critical_shape_factor, plot_svg, sample_mesh, sample_patch,
    sample_patch_masked,
};
use scallop_geom::{Point3, Vec3};
use scallop_mesh::TriMesh;
use scallop_surface::Patch;

const SH: f64 = 0.01;

fn report_of(samples: &Samples) -> AnalysisReport {
    analyze(samples, &ToolOptions::default(), &MachineLimits::default(), SH).unwrap()
}

/// Every number of the JSON report is finite (serde_json writes NaN and infinities
/// as `null`); the only `null` allowed is an infinite critical shape factor.
fn assert_finite_report(report: &AnalysisReport) {
    fn walk(value: &serde_json::Value, key: &str) {
        match value {
            serde_json::Value::Null => assert_eq!(key, "critical_shape_factor", "null (NaN or inf) at {key}"),
            serde_json::Value::Number(n) => assert!(n.as_f64().unwrap().is_finite(), "{key}"),
            serde_json::Value::Array(items) => items.iter().for_each(|v| walk(v, key)),
            serde_json::Value::Object(map) => map.iter().for_each(|(k, v)| walk(v, k)),
            _ => {}
        }
    }
    let json = serde_json::to_value(report).unwrap();
    walk(&json, "");
    let back: AnalysisReport = serde_json::from_value(json).unwrap();
    assert_eq!(&back, report, "JSON round trip");
    let svg = plot_svg(report);
    assert!(!svg.contains("NaN") && !svg.contains("inf"), "plot has no NaN or inf");
}

#[test]
fn vertical_wall() {
    // Plane x = 0, 40 mm along Y, 20 mm high: every normal is +-X.
    let p = |y, z| Point3::new(0.0, y, z);
    let wall = bilinear(p(0.0, 0.0), p(40.0, 0.0), p(0.0, 20.0), p(40.0, 20.0));
    let samples = sample_patch(&wall, &GridOptions::default()).unwrap();
    assert!(samples.samples().iter().all(|s| (s.slope - std::f64::consts::FRAC_PI_2).abs() < 1e-12));
    let report = report_of(&samples);
    assert_finite_report(&report);
    assert_abs(report.slope_deg, 90.0, 1e-9, "slope");
    assert_abs(report.slope_direction_deg, 0.0, 1e-9, "slope direction (normal along X)");
    assert_abs(report.principal_direction_deg, 90.0, 1e-9, "principal direction (along Y)");
    assert_abs(report.shape_factor, 2.0, 1e-9, "mu");
    assert!(report.critical_slope_deg < 90.0);
    assert_eq!(report.recommendation, Recommendation::BallAlongPrincipal);
    assert!(report.notes.contains(&Note::VerticalPlane));
    // The PCA normal of a vertical plane is canonical: largest component positive.
    assert_eq!(report.plane.normal, [1.0, 0.0, 0.0]);
    // Annex E: a vertical plane is not machinable by that model (documented +inf).
    let pca = Pca::from_moments(&samples.moments());
    assert_eq!(annex_e_time(&pca, 0.3, &ToolOptions::default().ball(), SH, &MachineLimits::default()), f64::INFINITY);
}

#[test]
fn vertical_wall_along_its_height() {
    // A wall taller than long: S_I is vertical, the principal direction falls back to
    // the slope direction.
    let p = |y, z| Point3::new(0.0, y, z);
    let wall = bilinear(p(0.0, 0.0), p(20.0, 0.0), p(0.0, 60.0), p(20.0, 60.0));
    let report = report_of(&sample_patch(&wall, &GridOptions::default()).unwrap());
    assert_finite_report(&report);
    assert!(report.notes.contains(&Note::PrincipalAxisVertical));
    assert_abs(report.principal_direction_deg, report.slope_direction_deg, 0.0, "fallback");
}

#[test]
fn flat_horizontal_plane() {
    let p = |x, y| Point3::new(x, y, 7.0);
    let plane = bilinear(p(0.0, 0.0), p(60.0, 0.0), p(0.0, 25.0), p(60.0, 25.0));
    let samples = sample_patch(&plane, &GridOptions::default()).unwrap();
    assert!(samples.samples().iter().all(|s| s.slope == 0.0 && s.slope_direction == 0.0 && s.normal == Vec3::z()));
    let report = report_of(&samples);
    assert_finite_report(&report);
    assert_eq!(report.slope_deg, 0.0);
    assert_eq!(report.slope_direction_deg, 0.0);
    assert_eq!(report.recommendation, Recommendation::ToroidalAlongSlope);
    assert_eq!(report.critical_shape_factor, None, "mu_c is infinite on a horizontal plane");
    assert!(report.notes.contains(&Note::HorizontalPlane));
    // The toroidal step-over is the flat-bottom cap sod_max (finishing.md 5.3).
    let cap = ToolOptions::default().toroidal().max_step_over(SH);
    assert_eq!(report.toroidal_along_slope.estimate.step_over, cap);
    assert!(report.toroidal_along_slope.estimate.time < report.ball_along_principal.estimate.time);
    assert_eq!(
        critical_shape_factor(0.0, 1500.0, &ToolOptions::default(), SH, &MachineLimits::default()),
        f64::INFINITY
    );
}

#[test]
fn all_normals_horizontal() {
    // A curved vertical wall: a parabolic arc in XY extruded along Z.
    let p = |x, y, z| Point3::new(x, y, z);
    let wall = Patch::bezier(
        "curved wall",
        [2, 1],
        &[
            vec![p(0., 0., 0.), p(0., 0., 30.)],
            vec![p(25., 12., 0.), p(25., 12., 30.)],
            vec![p(50., 0., 0.), p(50., 0., 30.)],
        ],
        None,
    )
    .unwrap();
    let samples = sample_patch(&wall, &GridOptions::default()).unwrap();
    assert!(samples.samples().iter().all(|s| s.normal.z == 0.0 && s.slope == std::f64::consts::FRAC_PI_2));
    let report = report_of(&samples);
    assert_finite_report(&report);
    assert_abs(report.mean_sample_slope_deg, 90.0, 1e-9, "mean sample slope");
    assert_abs(report.slope_deg, 90.0, 1e-9, "PCA slope");
    assert_eq!(report.recommendation, Recommendation::BallAlongPrincipal);
}

#[test]
fn single_triangle() {
    let (mesh, _) =
        TriMesh::from_soup(&[[Point3::new(0.0, 0.0, 0.0), Point3::new(10.0, 0.0, 0.0), Point3::new(0.0, 10.0, 5.0)]])
            .unwrap();
    let samples = sample_mesh(&mesh);
    assert_eq!(samples.len(), 1);
    assert_eq!(samples.weighting(), PcaWeighting::Area);
    let s = samples.samples()[0];
    assert_abs(s.weight, 0.5 * (50.0f64.powi(2) + 100.0f64.powi(2)).sqrt(), 1e-9, "area = |(0, -50, 100)| / 2");
    let facet_tilt = s.normal.z.acos();
    let report = report_of(&samples);
    assert_finite_report(&report);
    // The exact triangle covariance has the facet as its PCA plane.
    assert_abs(report.slope_deg, facet_tilt.to_degrees(), 1e-9, "slope = facet tilt");
    assert_abs(report.plane.eigenvalues[2], 0.0, 1e-9, "lambda_III");
    assert!(s.feature().is_none(), "no (u, v) on meshes");
}

#[test]
fn collinear_and_point_samples_are_errors() {
    let sample = |x: f64| Sample {
        point: Point3::new(x, 2.0 * x, 0.0),
        normal: Vec3::z(),
        weight: 1.0,
        slope: 0.0,
        slope_direction: 0.0,
        uv: None,
    };
    let line =
        Samples::from_samples((0..10).map(|k| sample(f64::from(k))).collect(), PcaWeighting::Parametric).unwrap();
    let err = analyze(&line, &ToolOptions::default(), &MachineLimits::default(), SH).unwrap_err();
    assert!(matches!(err, AnalysisError::DegenerateSamples { .. }), "{err}");
    let point = Samples::from_samples(vec![sample(3.0)], PcaWeighting::Parametric).unwrap();
    let err = analyze(&point, &ToolOptions::default(), &MachineLimits::default(), SH).unwrap_err();
    assert!(matches!(err, AnalysisError::DegenerateSamples { .. }), "{err}");
    assert_eq!(Samples::from_samples(Vec::new(), PcaWeighting::Area).unwrap_err(), AnalysisError::NoSamples);
    let mut bad = vec![sample(1.0), sample(2.0)];
    bad[1].weight = -1.0;
    assert_eq!(Samples::from_samples(bad, PcaWeighting::Area).unwrap_err(), AnalysisError::BadSample { index: 1 });
    let mut bad = vec![sample(1.0)];
    bad[0].point.x = f64::NAN;
    assert_eq!(Samples::from_samples(bad, PcaWeighting::Area).unwrap_err(), AnalysisError::BadSample { index: 0 });
}

#[test]
fn patch_collapsed_to_a_curve() {
    // Every control point on one line: zero-area cells, samples on a line.
    let p = |t: f64| Point3::new(t, 2.0 * t, 0.5 * t);
    let line = bilinear(p(0.0), p(10.0), p(1.0), p(11.0));
    let samples = sample_patch(&line, &GridOptions { cells_u: 8, cells_v: 8 }).unwrap();
    assert!(samples.samples().iter().all(|s| s.weight == 0.0 && s.normal.iter().all(|c| c.is_finite())));
    for weighting in [PcaWeighting::Parametric, PcaWeighting::Area] {
        let samples = samples.clone().with_weighting(weighting);
        assert!(samples.moments().covariance().iter().all(|c| c.is_finite()));
        assert!(samples.mean_slope().is_finite());
        let err = analyze(&samples, &ToolOptions::default(), &MachineLimits::default(), SH).unwrap_err();
        assert!(matches!(err, AnalysisError::DegenerateSamples { .. }), "{weighting:?}: {err}");
    }
}

#[test]
fn bad_inputs_are_errors() {
    let set = scallop_surface::builtin("choi").unwrap();
    let patch = &set.patches()[0];
    let grid = |cells_u, cells_v| GridOptions { cells_u, cells_v };
    assert_eq!(sample_patch(patch, &grid(0, 5)).unwrap_err(), AnalysisError::EmptyGrid { cells_u: 0, cells_v: 5 });
    assert_eq!(sample_patch_masked(patch, &grid(4, 4), |_, _| false).unwrap_err(), AnalysisError::NoSamples);
    let samples = sample_patch(patch, &grid(10, 10)).unwrap();
    let (tools, machine) = (ToolOptions::default(), MachineLimits::default());
    for sh in [0.0, -1.0, f64::NAN, 5.0] {
        assert!(matches!(analyze(&samples, &tools, &machine, sh), Err(AnalysisError::BadScallopHeight { .. })));
    }
    let bad_corner = ToolOptions { corner_radius: 6.0, ..tools };
    assert!(matches!(analyze(&samples, &bad_corner, &machine, SH), Err(AnalysisError::BadTool { .. })));
    let bad_machine = MachineLimits { feed: f64::INFINITY, ..machine };
    assert!(matches!(analyze(&samples, &tools, &bad_machine, SH), Err(AnalysisError::BadMachine { .. })));
}

#[test]
fn choi_report_json_and_plot() {
    let set = scallop_surface::builtin("choi").unwrap();
    let samples = sample_patch(&set.patches()[0], &GridOptions::default()).unwrap();
    let report = report_of(&samples);
    assert_finite_report(&report);
    assert!(report.notes.is_empty(), "{:?}", report.notes);
    let json = serde_json::to_string(&report).unwrap();
    assert!(json.contains("\"recommendation\":\"toroidal_along_slope\""), "{json}");
    let svg = plot_svg(&report);
    assert!(svg.contains("toroidal along steepest slope"));
    assert_eq!(svg, plot_svg(&report), "deterministic");
}
