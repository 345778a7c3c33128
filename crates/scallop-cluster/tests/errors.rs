//! Bad parameters and inputs give errors that name the parameter and the fix.

mod common;

use scallop_analysis::FeatureVector;
use scallop_cluster::{ClusterError, ClusterParams, Features, HacCut, Method, Metric, Scope, cluster, partition};

#[test]
fn cluster_count_out_of_range() {
    let features = common::random_grid([4, 5], 1);
    for k in [0, 21] {
        let err = partition(&features, &ClusterParams { k, ..Default::default() }).unwrap_err();
        assert_eq!(err, ClusterError::BadClusterCount { k, cells: 20 });
        assert!(err.to_string().contains("1 <= k <= 20"), "{err}");
    }
}

#[test]
fn weights_outside_unit_interval() {
    let features = common::random_grid([4, 5], 1);
    for (index, value) in [(0, -0.1), (2, 1.5), (3, f64::NAN), (1, f64::INFINITY)] {
        let mut omega = [1.0; 4];
        omega[index] = value;
        let err = cluster(&features, &ClusterParams { omega, ..Default::default() }).unwrap_err();
        assert!(matches!(err, ClusterError::BadWeight { index: i, .. } if i == index), "{err}");
        assert!(err.to_string().contains(&format!("omega[{index}]")) && err.to_string().contains("[0, 1]"));
    }
}

#[test]
fn empty_grid_and_bad_features() {
    assert_eq!(Features::from_grid([0, 5], &[]).unwrap_err(), ClusterError::EmptyGrid { cells_u: 0, cells_v: 5 });
    let f = FeatureVector { u: 0.5, v: 0.5, slope: f64::NAN, slope_direction: 0.0 };
    assert_eq!(Features::from_grid([1, 1], &[f]).unwrap_err(), ClusterError::BadFeature { index: 0 });
    let ok = FeatureVector { slope: 0.1, ..f };
    assert!(matches!(Features::from_grid([2, 1], &[ok]).unwrap_err(), ClusterError::LengthMismatch { .. }));
    assert_eq!(
        Features::from_cells([2, 2], &[1, 1], &[ok, ok]).unwrap_err(),
        ClusterError::CellOrder { index: 1, cell: 1 }
    );
    assert_eq!(Features::from_cells([2, 2], &[4], &[ok]).unwrap_err(), ClusterError::CellOrder { index: 0, cell: 4 });
}

#[test]
fn samples_without_grid() {
    use scallop_analysis::{PcaWeighting, Sample, Samples};
    use scallop_geom::{Point3, Vec3};
    let sample =
        Sample { point: Point3::origin(), normal: Vec3::z(), weight: 1.0, slope: 0.0, slope_direction: 0.0, uv: None };
    let samples = Samples::from_samples(vec![sample], PcaWeighting::Area).unwrap();
    assert_eq!(Features::from_samples(&samples).unwrap_err(), ClusterError::NoGrid);
}

#[test]
fn unsupported_combinations_and_settings() {
    let features = common::random_grid([6, 6], 2);
    let pca = ClusterParams { metric: Metric::Pca { factor: Default::default() }, ..Default::default() };
    assert_eq!(cluster(&features, &pca).unwrap_err(), ClusterError::NeedsGeometry);
    let hac = ClusterParams {
        method: Method::Hac { cut: HacCut::Clusters },
        metric: Metric::Mahalanobis { scope: Scope::Global },
        ..Default::default()
    };
    let err = cluster(&features, &hac).unwrap_err();
    assert!(matches!(err, ClusterError::Unsupported { .. }) && err.to_string().contains("euclidean"), "{err}");
    let capped = ClusterParams { max_iterations: 0, ..Default::default() };
    assert!(cluster(&features, &capped).unwrap_err().to_string().contains("max_iterations"));
    let bad_cut = ClusterParams {
        method: Method::Hac { cut: HacCut::LargestGap { min: 3, max: Some(2) } },
        ..Default::default()
    };
    assert!(matches!(cluster(&features, &bad_cut).unwrap_err(), ClusterError::BadSetting { .. }));
    let bad_rate = ClusterParams {
        method: Method::Rpcl,
        rpcl: scallop_cluster::RpclParams { alpha_winner: 0.0, ..Default::default() },
        ..Default::default()
    };
    assert!(cluster(&features, &bad_rate).unwrap_err().to_string().contains("rpcl.alpha_winner"));
}

/// Parameters round-trip through serde (job files), every method and metric.
#[test]
fn params_round_trip() {
    use scallop_cluster::{PcaFactor, StdScaling, ThetaMode};
    let cases = [
        ClusterParams::default(),
        ClusterParams {
            k: 7,
            omega: [0.5, 1.0, 0.0, 0.25],
            metric: Metric::StdDev { scaling: StdScaling::Variance, scope: Scope::PerCluster },
            method: Method::Rpcl,
            theta: ThetaMode::Plain,
            seed: 42,
            ..Default::default()
        },
        ClusterParams { metric: Metric::Pca { factor: PcaFactor::RhoSquared }, ..Default::default() },
        ClusterParams {
            method: Method::Hac { cut: HacCut::LargestGap { min: 3, max: Some(8) } },
            ..Default::default()
        },
        ClusterParams { method: Method::Hac { cut: HacCut::default() }, ..Default::default() },
    ];
    for params in cases {
        let text = serde_json::to_string(&params).unwrap();
        let back: ClusterParams = serde_json::from_str(&text).unwrap();
        assert_eq!(back, params, "{text}");
    }
    let partial: ClusterParams =
        serde_json::from_str(r#"{"k": 5, "method": {"kind": "hac", "cut": {"kind": "clusters"}}}"#).unwrap();
    assert_eq!(partial, ClusterParams { k: 5, method: Method::Hac { cut: HacCut::Clusters }, ..Default::default() });
    assert!(serde_json::from_str::<ClusterParams>(r#"{"kk": 5}"#).is_err());
}
