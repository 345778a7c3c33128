//! K-means (finishing.md 11.6): fixed point, analytic cases, determinism.

mod common;

use std::f64::consts::FRAC_PI_2;

use common::{assert_fixed_point, canonical, grid, random_grid};
use proptest::prelude::*;
use scallop_cluster::{ClusterParams, Method, Metric, Scope, StdScaling, ThetaMode, cluster, partition};
use scallop_geom::nalgebra::Matrix4;

fn diag(w: [f64; 4]) -> [[f64; 4]; 4] {
    let mut m = [[0.0; 4]; 4];
    for k in 0..4 {
        m[k][k] = w[k];
    }
    m
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// At the end every point belongs to its nearest cluster mean under the
    /// (weighted) Euclidean metric, in both theta modes.
    #[test]
    fn euclidean_fixed_point(seed in any::<u64>(), nu in 4usize..24, nv in 4usize..24, k in 1usize..8,
                             w in prop::array::uniform4(0.0f64..=1.0), plain in any::<bool>()) {
        let features = random_grid([nu, nv], seed);
        let theta = if plain { ThetaMode::Plain } else { ThetaMode::Wrapped };
        let params = ClusterParams { k, omega: w, theta, ..Default::default() };
        let c = cluster(&features, &params).unwrap();
        prop_assert!(c.clusters >= 1 && c.clusters <= k);
        prop_assert!(c.converged, "Euclidean K-means converges ({} sweeps)", c.iterations);
        prop_assert!(c.labels.iter().all(|&l| (l as usize) < c.clusters));
        assert_fixed_point(&features, &c.labels, c.clusters, theta, &diag(w));
    }

    /// The global Mahalanobis and standard-deviation metrics also end at a fixed
    /// point of their own quadratic form.
    #[test]
    fn normalising_metrics_fixed_point(seed in any::<u64>(), k in 2usize..6, which in 0usize..3) {
        let features = random_grid([15, 17], seed);
        let theta = ThetaMode::Wrapped;
        let sigma = features.covariance(theta);
        let (metric, a) = match which {
            0 => {
                let inv = Matrix4::from_fn(|r, c| sigma[r][c]).try_inverse().unwrap();
                (Metric::Mahalanobis { scope: Scope::Global }, std::array::from_fn(|r| std::array::from_fn(|c| inv[(r, c)])))
            }
            1 => (Metric::StdDev { scaling: StdScaling::Sigma, scope: Scope::Global },
                  diag(std::array::from_fn(|j| 1.0 / sigma[j][j].sqrt()))),
            _ => (Metric::StdDev { scaling: StdScaling::Variance, scope: Scope::Global },
                  diag(std::array::from_fn(|j| 1.0 / sigma[j][j]))),
        };
        let c = cluster(&features, &ClusterParams { k, metric, ..Default::default() }).unwrap();
        prop_assert!(c.converged);
        assert_fixed_point(&features, &c.labels, c.clusters, theta, &a);
    }
}

/// Two well-separated blobs in (s, theta) give exactly two clusters, the blobs.
#[test]
fn two_blobs_two_clusters() {
    let features = grid([20, 20], |u, v| {
        let noise = 0.01 * ((17.0 * u + 29.0 * v).sin());
        if u < 0.5 { (0.2 + noise, 0.3 + noise) } else { (1.3 + noise, -1.0 + noise) }
    });
    for method in [Method::KMeans, Method::Rpcl, Method::Hac { cut: Default::default() }] {
        let p = partition(&features, &ClusterParams { k: 2, method, ..Default::default() }).unwrap();
        assert_eq!(p.clusters, 2, "{method:?}");
        assert_eq!(p.zone_count(), 2, "{method:?}");
        for cell in 0..400 {
            let left = cell / 20 < 10;
            assert_eq!(p.cluster_of_cell[cell] == p.cluster_of_cell[0], left, "{method:?} cell {cell}");
        }
    }
}

/// Directions just above -pi/2 and just below pi/2 are the same direction: in
/// Wrapped mode they form one cluster against theta = 0; theta alone decides.
#[test]
fn wrapped_theta_joins_opposite_ends() {
    let eps = 0.01;
    let features = grid([16, 16], |u, v| {
        let t = if u < 0.5 {
            if ((v * 16.0) as usize).is_multiple_of(2) { -FRAC_PI_2 + eps } else { FRAC_PI_2 - eps }
        } else {
            0.0
        };
        (0.5, t)
    });
    let params = ClusterParams { k: 2, omega: [0.0, 0.0, 0.0, 1.0], ..Default::default() };
    let p = partition(&features, &params).unwrap();
    assert_eq!(p.clusters, 2);
    for cell in 0..256 {
        assert_eq!(p.cluster_of_cell[cell] == p.cluster_of_cell[0], cell / 16 < 8, "cell {cell}");
    }
    // The left cluster's circular mean is +-pi/2 (not 0, the plain mean).
    let left = &p.zones[p.zone_of_cell[0] as usize];
    assert!(FRAC_PI_2 - left.feature_mean.slope_direction.abs() < 1e-9);
    // Plain mode sees -pi/2 + eps and pi/2 - eps as far apart (difference pi - 2 eps).
    let plain = cluster(&features, &ClusterParams { theta: ThetaMode::Plain, ..params }).unwrap();
    let left_labels: Vec<u32> = (0..128).map(|i| plain.labels[i]).collect();
    assert!(left_labels.iter().any(|&l| l != left_labels[0]));
}

/// Same labels twice, and on one and two rayon threads, for every method and metric
/// (the PCA metric and large grids take the parallel assignment path).
#[test]
fn deterministic_across_runs_and_threads() {
    let set = scallop_surface::builtin("rubio").unwrap();
    let grid = scallop_analysis::GridOptions { cells_u: 40, cells_v: 40 };
    let samples = scallop_analysis::sample_patch(&set.patches()[0], &grid).unwrap();
    let features = scallop_cluster::Features::from_samples(&samples).unwrap();
    let big = random_grid([400, 400], 7);
    let pools = [1, 2].map(|n| rayon::ThreadPoolBuilder::new().num_threads(n).build().unwrap());
    let cases = [
        (ClusterParams::default(), &features),
        (ClusterParams { k: 5, method: Method::Rpcl, seed: 11, ..Default::default() }, &features),
        (
            ClusterParams { k: 4, metric: Metric::Mahalanobis { scope: Scope::PerCluster }, ..Default::default() },
            &features,
        ),
        (
            ClusterParams {
                k: 3,
                metric: Metric::StdDev { scaling: StdScaling::Sigma, scope: Scope::PerCluster },
                ..Default::default()
            },
            &features,
        ),
        (ClusterParams { k: 3, metric: Metric::Pca { factor: Default::default() }, ..Default::default() }, &features),
        (ClusterParams { k: 4, method: Method::Hac { cut: Default::default() }, ..Default::default() }, &features),
        (ClusterParams { k: 6, max_iterations: 20, ..Default::default() }, &big),
    ];
    for (params, features) in cases {
        let runs: Vec<_> = pools.iter().map(|pool| pool.install(|| partition(features, &params).unwrap())).collect();
        let again = pools[0].install(|| partition(features, &params).unwrap());
        assert_eq!(runs[0], runs[1], "{params:?}: 1 vs 2 threads");
        assert_eq!(runs[0], again, "{params:?}: run twice");
        assert!(runs[0].iterations <= params.max_iterations);
    }
}

/// K = 1 is one cluster after one sweep; K = cells is valid.
#[test]
fn extreme_cluster_counts() {
    let features = random_grid([5, 4], 3);
    let c = cluster(&features, &ClusterParams { k: 20, ..Default::default() }).unwrap();
    assert!(c.clusters >= 1 && c.clusters <= 20);
    assert!(c.labels.iter().all(|&l| (l as usize) < c.clusters));
    assert_eq!(canonical(&c.labels).iter().max().map(|&m| m as usize + 1), Some(c.clusters));
    let one = cluster(&features, &ClusterParams { k: 1, ..Default::default() }).unwrap();
    assert_eq!((one.clusters, one.iterations), (1, 1));
    assert!(one.labels.iter().all(|&l| l == 0));
}
