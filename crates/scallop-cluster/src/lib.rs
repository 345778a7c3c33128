//! Surface partitioning for finishing (finishing.md chapter 3, sections 11.1-11.10):
//! cluster the cells of a clustering grid by their feature vectors
//! `(u, v, s, theta)`, then split every cluster into 4-connected zones.
//!
//! - [`Features`]: the feature vectors of an `N_u x N_v` grid of cell-centre samples
//!   (from [`scallop_analysis::sample_patch`]), with their 3D points and normals;
//! - [`Metric`]: (weighted) Euclidean, Mahalanobis and standard-deviation metrics
//!   (global or per cluster) and the PCA-based metric; theta is a direction modulo pi
//!   ([`ThetaMode::Wrapped`], default) or plain ([`ThetaMode::Plain`], \[COMPAT\]);
//! - [`Method`]: K-means (circle initialisation, fixed-point stop, 300-sweep cap),
//!   seeded RPCL, Ward hierarchical clustering ([`ward_linkage`], a
//!   nearest-neighbour chain in O(n) memory);
//! - [`connected_components`]: 4-connectivity, explicit stack;
//! - [`partition`]: the optimiser's entry point, returning per-cell cluster and zone
//!   labels and the zone records ([`Zone`]).
//!
//! ```
//! use scallop_cluster::{partition, ClusterParams, Features, Method, Metric};
//! let set = scallop_surface::builtin("choi").unwrap();
//! let samples = scallop_analysis::sample_patch(&set.patches()[0], &Default::default()).unwrap();
//! let features = Features::from_samples(&samples).unwrap(); // once per surface
//! let params = ClusterParams { k: 3, omega: [1.0, 1.0, 0.5, 1.0], metric: Metric::Euclidean,
//!                              method: Method::KMeans, ..Default::default() };
//! let p = partition(&features, &params).unwrap();
//! for (z, zone) in p.zones.iter().enumerate() {
//!     assert_eq!(p.zone_cluster[z], zone.cluster);
//!     assert!(zone.geometry.unwrap().pca.eigenvalues[0] > 0.0);
//! }
//! ```
//!
//! # Decisions (where finishing.md leaves room)
//! - Circle initialisation (11.4) takes `s` and `theta` from the cell that contains
//!   `(u_k, v_k)` (the nearest kept cell on a masked grid) instead of evaluating the
//!   surface there: the crate sees samples, not patches (at 80 x 80 the two differ by
//!   half a cell). Likewise the PCA metric's `S(u_k, v_k)` is that cell's point.
//! - `omega` weighs every metric as `W^(1/2) M W^(1/2)` (see [`Metric`]); for
//!   Mahalanobis, scaling the features instead would cancel out.
//! - K-means on the global diagonal metrics uses Hamerly's bounds and a scan
//!   pruned by centre-centre distances, with the same labels and sweeps as the
//!   plain algorithm (tested bit for bit).
//! - HAC in [`ThetaMode::Wrapped`] embeds theta as `(cos 2 theta, sin 2 theta) / 2`;
//!   its gap cut may return 2 clusters (see [`HacCut`]).
//! - A global Mahalanobis covariance that is singular (a constant component) uses
//!   the pseudo-inverse; a singular per-cluster one falls back to the global one.
//!
//! # Units
//! `u, v` in `[0, 1]` (fractions of the parameter domain), `s` and `theta` in rad,
//! 3D statistics in mm and mm^2.
//!
//! # Invariants
//! - Never performs I/O, never prints, never reads the clock or the environment.
//! - Deterministic: the same labels for the same inputs and seed, on any number of
//!   rayon threads (parallel assignment sweeps write each cell's label by index from
//!   frozen statistics; every sum runs in a fixed sequential order).
//! - Never panics on bad parameters: [`ClusterError`] names the parameter and the fix.
//! - Every numeric threshold lives in [`tol`].

mod ccl;
mod eigen;
mod engine;
mod error;
mod features;
mod hac;
mod kmeans;
mod metric;
mod partition;
mod rpcl;
pub mod tol;
mod zone;

pub use ccl::connected_components;
pub use error::ClusterError;
pub use features::{Features, NO_LABEL, ThetaMode, wrap_direction_difference};
pub use hac::{Merge, cut_dendrogram, largest_gap_clusters, ward_linkage};
pub use metric::{Metric, PcaFactor, Scope, StdScaling};
pub use partition::{ClusterParams, Clustering, HacCut, Method, Partition, RpclParams, cluster, partition, validate};
pub use zone::{Zone, ZoneGeometry};
