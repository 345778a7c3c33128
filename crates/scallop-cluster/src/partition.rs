//! Parameters and entry points: [`cluster`] (labels only) and [`partition`]
//! (clusters, connected zones and zone records).

use scallop_analysis::FeatureVector;
use serde::{Deserialize, Serialize};

use crate::ccl::connected_components;
use crate::engine::Setup;
use crate::error::ClusterError;
use crate::features::{Features, NO_LABEL, Sums, ThetaMode};
use crate::hac::{cut_dendrogram, largest_gap_clusters, ward_linkage};
use crate::kmeans::kmeans;
use crate::metric::{Metric, Scope, metric_matrix};
use crate::rpcl::rpcl;
use crate::tol;
use crate::zone::{Zone, zone_records};

/// Where hierarchical clustering cuts its dendrogram.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum HacCut {
    /// Exactly [`ClusterParams::k`] clusters.
    Clusters,
    /// The largest gap between successive merge heights (finishing.md 11.8
    /// \[CORR\]), among partitions of `min..=max` clusters. \[DECISION\] The spec
    /// ranges over merges `m in [2, n - 2]`, which never yields 2 clusters (two
    /// well-separated blobs would come out as 3); here the range is a parameter and
    /// [`HacCut::default`] allows 2.
    LargestGap {
        /// Fewest clusters (>= 1).
        min: usize,
        /// Most clusters (`None`: no limit).
        max: Option<usize>,
    },
}

impl Default for HacCut {
    /// `LargestGap { min: 2, max: None }`.
    fn default() -> Self {
        HacCut::LargestGap { min: 2, max: None }
    }
}

/// The clustering algorithm (finishing.md 11.6-11.8).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Method {
    /// K-means (default; Ch. 4's black box): circle initialisation, exact means,
    /// stop at a fixed point or after `max_iterations` sweeps.
    #[default]
    KMeans,
    /// RPCL, seeded by [`ClusterParams::seed`], settings [`ClusterParams::rpcl`];
    /// may end with fewer clusters than `k` (rivals are driven out).
    Rpcl,
    /// Hierarchical ascending clustering with Ward linkage (nearest-neighbour chain,
    /// O(n) memory, O(n^2) time); the metric must be diagonal
    /// ([`Metric::Euclidean`] or global [`Metric::StdDev`]), applied as a feature
    /// scaling. In [`ThetaMode::Wrapped`] theta is embedded as
    /// `(cos 2 theta, sin 2 theta) / 2` (chord length `|sin d theta|`, equal to the
    /// wrapped difference to first order) so that Ward stays exact and reducible.
    Hac {
        /// Where the dendrogram is cut.
        cut: HacCut,
    },
}

impl Method {
    fn name(&self) -> &'static str {
        match self {
            Method::KMeans => "k-means",
            Method::Rpcl => "RPCL",
            Method::Hac { .. } => "hierarchical clustering (Ward)",
        }
    }
}

/// RPCL settings (finishing.md 11.7, section 13 \[DECISION\]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RpclParams {
    /// Winner learning rate at sweep 0, in `(0, 1]`; decays as `1/(1 + t)`.
    pub alpha_winner: f64,
    /// Rival learning rate at sweep 0, in `[0, 1]`; decays as `1/(1 + t)`.
    pub alpha_rival: f64,
    /// Stop when both rates are below this (>= 0).
    pub tol_alpha: f64,
    /// Stop when fewer than this fraction of the cells changed cluster in a sweep, in `[0, 1]`.
    pub tol_move: f64,
}

impl Default for RpclParams {
    fn default() -> Self {
        RpclParams {
            alpha_winner: tol::RPCL_ALPHA_WINNER,
            alpha_rival: tol::RPCL_ALPHA_RIVAL,
            tol_alpha: tol::RPCL_TOL_ALPHA,
            tol_move: tol::RPCL_TOL_MOVE,
        }
    }
}

/// Everything a partition depends on besides the features.
/// [`Default`]: K-means, `k = 3`, `omega = (1, 1, 1, 1)`, Euclidean, wrapped theta,
/// seed 0, 300 iterations (finishing.md section 13).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ClusterParams {
    /// Number of clusters `K`, `1 <= K <= cells` (for [`Method::Hac`] only with
    /// [`HacCut::Clusters`]).
    pub k: usize,
    /// Weights `omega` of `(u, v, s, theta)`, each in `[0, 1]`.
    pub omega: [f64; 4],
    /// The metric.
    pub metric: Metric,
    /// The algorithm.
    pub method: Method,
    /// Treatment of theta.
    pub theta: ThetaMode,
    /// Seed of RPCL's sample order (other methods are deterministic without it).
    pub seed: u64,
    /// Iteration cap of K-means and RPCL (>= 1), one iteration = one assignment sweep.
    pub max_iterations: usize,
    /// RPCL settings.
    pub rpcl: RpclParams,
}

impl Default for ClusterParams {
    fn default() -> Self {
        ClusterParams {
            k: 3,
            omega: [1.0; 4],
            metric: Metric::Euclidean,
            method: Method::KMeans,
            theta: ThetaMode::Wrapped,
            seed: 0,
            max_iterations: tol::MAX_ITERATIONS,
            rpcl: RpclParams::default(),
        }
    }
}

/// Cluster labels of the points of a [`Features`] (before connected components).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Clustering {
    /// Cluster of every point (kept cell), in `0..clusters`; empty clusters are
    /// dropped and the others keep their order.
    pub labels: Vec<u32>,
    /// Number of non-empty clusters.
    pub clusters: usize,
    /// Assignment sweeps run (0 for HAC).
    pub iterations: usize,
    /// Whether the run stopped on its criterion (K-means: a fixed point; RPCL: small
    /// rates or few moves) rather than on the iteration cap. Always true for HAC.
    pub converged: bool,
}

/// A partition of the clustering grid into clusters and zones.
#[derive(Clone, Debug, PartialEq)]
pub struct Partition {
    /// `[N_u, N_v]`.
    pub grid: [usize; 2],
    /// Cluster of every grid cell `a * N_v + b` ([`NO_LABEL`] when masked).
    pub cluster_of_cell: Vec<u32>,
    /// Zone of every grid cell ([`NO_LABEL`] when masked); zones are numbered in
    /// scan order of their first cell.
    pub zone_of_cell: Vec<u32>,
    /// Cluster of every zone.
    pub zone_cluster: Vec<u32>,
    /// Zone records, in zone order.
    pub zones: Vec<Zone>,
    /// Number of non-empty clusters.
    pub clusters: usize,
    /// Mean feature vector of every cluster (theta per [`ClusterParams::theta`]: the
    /// circular mean when wrapped): K-means' final centres, and the mean
    /// steepest-slope direction that starts the optimiser's `Theta_k`
    /// (finishing.md 12.8; theta is in `(-pi/2, pi/2]`, Theta in `[0, pi]`).
    pub cluster_means: Vec<FeatureVector>,
    /// Assignment sweeps run (0 for HAC).
    pub iterations: usize,
    /// See [`Clustering::converged`].
    pub converged: bool,
}

impl Partition {
    /// Number of zones.
    #[must_use]
    pub fn zone_count(&self) -> usize {
        self.zones.len()
    }
}

/// Checks `params` against `features`.
///
/// # Errors
/// See [`cluster`].
pub fn validate(features: &Features, params: &ClusterParams) -> Result<(), ClusterError> {
    let cells = features.len();
    let k_used = !matches!(params.method, Method::Hac { cut: HacCut::LargestGap { .. } });
    if k_used && (params.k == 0 || params.k > cells) {
        return Err(ClusterError::BadClusterCount { k: params.k, cells });
    }
    for (index, &value) in params.omega.iter().enumerate() {
        if !(0.0..=1.0).contains(&value) {
            return Err(ClusterError::BadWeight { index, value });
        }
    }
    if params.max_iterations == 0 {
        return Err(ClusterError::BadSetting {
            name: "max_iterations",
            value: 0.0,
            fix: "allow at least 1 assignment sweep (default 300)",
        });
    }
    let r = &params.rpcl;
    let checks = [
        (
            "rpcl.alpha_winner",
            r.alpha_winner,
            r.alpha_winner > 0.0 && r.alpha_winner <= 1.0,
            "use a rate in (0, 1] (default 0.05)",
        ),
        (
            "rpcl.alpha_rival",
            r.alpha_rival,
            (0.0..=1.0).contains(&r.alpha_rival),
            "use a rate in [0, 1] (default 0.005)",
        ),
        (
            "rpcl.tol_alpha",
            r.tol_alpha,
            r.tol_alpha >= 0.0 && r.tol_alpha.is_finite(),
            "use a finite value >= 0 (default 1e-4)",
        ),
        ("rpcl.tol_move", r.tol_move, (0.0..=1.0).contains(&r.tol_move), "use a fraction in [0, 1] (default 0.01)"),
    ];
    if params.method == Method::Rpcl {
        for (name, value, ok, fix) in checks {
            if !ok {
                return Err(ClusterError::BadSetting { name, value, fix });
            }
        }
    }
    if matches!(params.metric, Metric::Pca { .. }) && features.geometry().is_none() {
        return Err(ClusterError::NeedsGeometry);
    }
    if let Method::Hac { cut } = params.method {
        let diagonal = matches!(params.metric, Metric::Euclidean | Metric::StdDev { scope: Scope::Global, .. });
        if !diagonal {
            return Err(ClusterError::Unsupported {
                method: params.method.name(),
                metric: params.metric.name(),
                fix: "use the euclidean or the global std_dev metric (Ward works on centroids), or k-means",
            });
        }
        if cells > tol::HAC_MAX_CELLS {
            return Err(ClusterError::BadSetting {
                name: "cells for hierarchical clustering",
                value: cells as f64,
                fix: "HAC is O(n^2) in time: use at most 40000 cells (e.g. a 200 x 200 grid), or k-means",
            });
        }
        if let HacCut::LargestGap { min, max } = cut
            && (min == 0 || max.is_some_and(|m| m < min))
        {
            return Err(ClusterError::BadSetting {
                name: "hac cut min clusters",
                value: min as f64,
                fix: "use 1 <= min <= max",
            });
        }
    }
    Ok(())
}

/// Clusters the points of `features` (finishing.md 11.4-11.8) without splitting
/// clusters into connected zones.
///
/// ```
/// use scallop_cluster::{cluster, ClusterParams, Features};
/// let set = scallop_surface::builtin("rubio").unwrap();
/// let grid = scallop_analysis::GridOptions { cells_u: 20, cells_v: 20 };
/// let samples = scallop_analysis::sample_patch(&set.patches()[0], &grid).unwrap();
/// let features = Features::from_samples(&samples).unwrap();
/// let c = cluster(&features, &ClusterParams::default()).unwrap();
/// assert!(c.converged && c.clusters <= 3 && c.labels.len() == 400);
/// ```
///
/// # Errors
/// [`ClusterError::BadClusterCount`] (`k` outside `1..=cells`),
/// [`ClusterError::BadWeight`] (an `omega_i` outside `[0, 1]` or NaN),
/// [`ClusterError::BadSetting`] (`max_iterations = 0`, RPCL rates, HAC size or
/// cut), [`ClusterError::NeedsGeometry`] (PCA metric without 3D points),
/// [`ClusterError::Unsupported`] (HAC with a non-diagonal metric).
pub fn cluster(features: &Features, params: &ClusterParams) -> Result<Clustering, ClusterError> {
    validate(features, params)?;
    let setup = Setup::new(features, params.omega, params.metric, params.theta);
    Ok(match params.method {
        Method::KMeans => kmeans(&setup, params.k, params.max_iterations),
        Method::Rpcl => rpcl(&setup, params.k, params.max_iterations, &params.rpcl, params.seed),
        Method::Hac { cut } => hac(features, params, cut),
    })
}

/// Ward HAC on the scaled features.
fn hac(features: &Features, params: &ClusterParams, cut: HacCut) -> Clustering {
    let mode = params.theta;
    let scale = metric_matrix(&params.metric, &features.covariance(mode), true).unwrap_or([[0.0; 4]; 4]);
    let w: [f64; 4] = std::array::from_fn(|j| (params.omega[j] * scale[j][j]).sqrt());
    let dim = if mode == ThetaMode::Wrapped { 5 } else { 4 };
    let mut points = Vec::with_capacity(features.len() * dim);
    for (x, d) in features.x.iter().zip(&features.doubled) {
        points.extend_from_slice(&[w[0] * x[0], w[1] * x[1], w[2] * x[2]]);
        match mode {
            ThetaMode::Wrapped => points.extend_from_slice(&[0.5 * w[3] * d[1], 0.5 * w[3] * d[0]]),
            ThetaMode::Plain => points.push(w[3] * x[3]),
        }
    }
    let n = features.len();
    let merges = ward_linkage(&points, dim);
    let clusters = match cut {
        HacCut::Clusters => params.k,
        HacCut::LargestGap { min, max } => largest_gap_clusters(n, &merges, min, max.unwrap_or(usize::MAX)),
    };
    let labels = cut_dendrogram(n, &merges, clusters);
    let clusters = labels.iter().map(|&l| l as usize + 1).max().unwrap_or(0);
    Clustering { labels, clusters, iterations: 0, converged: true }
}

/// Partitions the surface (finishing.md 11): clusters the points, splits every
/// cluster into its 4-connected components (the zones, 11.9) and builds the zone
/// records (11.10). The optimiser's black box calls this once per evaluation.
///
/// ```
/// use scallop_cluster::{partition, ClusterParams, Features};
/// let set = scallop_surface::builtin("choi").unwrap();
/// let samples = scallop_analysis::sample_patch(&set.patches()[0], &Default::default()).unwrap();
/// let features = Features::from_samples(&samples).unwrap();
/// let p = partition(&features, &ClusterParams { k: 3, ..Default::default() }).unwrap();
/// assert!(p.zone_count() >= p.clusters);
/// assert_eq!(p.zones.iter().map(|z| z.len()).sum::<usize>(), 6400);
/// ```
///
/// # Errors
/// As [`cluster`].
pub fn partition(features: &Features, params: &ClusterParams) -> Result<Partition, ClusterError> {
    let clustering = cluster(features, params)?;
    let mut cluster_of_cell = vec![NO_LABEL; features.cell_count()];
    for (&cell, &label) in features.cells().iter().zip(&clustering.labels) {
        cluster_of_cell[cell as usize] = label;
    }
    let (zone_of_cell, count) = connected_components(features.grid(), &cluster_of_cell)?;
    let zones = zone_records(features, &zone_of_cell, &cluster_of_cell, count, params.theta);
    let zone_cluster = zones.iter().map(|z| z.cluster).collect();
    let sums = Sums::per_label(&clustering.labels, features, clustering.clusters);
    let cluster_means = sums
        .iter()
        .map(|s| {
            let [u, v, slope, slope_direction] = s.mean(params.theta).unwrap_or([0.0; 4]);
            FeatureVector { u, v, slope, slope_direction }
        })
        .collect();
    Ok(Partition {
        grid: features.grid(),
        cluster_of_cell,
        zone_of_cell,
        zone_cluster,
        zones,
        clusters: clustering.clusters,
        cluster_means,
        iterations: clustering.iterations,
        converged: clustering.converged,
    })
}
