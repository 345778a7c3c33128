//! Metrics between a cell's feature vector and a cluster centre (finishing.md 11.3).
//!
//! The point-to-centre metrics 1-4 are quadratic forms `d^2 = dx^T A dx` of the
//! difference `dx = x_i - c_k` (theta component per [`ThetaMode`]). The weights
//! `omega` enter every one of them the same way: `A = W^(1/2) M W^(1/2)`,
//! `W = diag(omega)`, where `M` is the metric's own matrix (identity for Euclidean,
//! `Sigma^-1` for Mahalanobis, `diag(1/sigma)` or `diag(1/sigma^2)` for the
//! standard-deviation metric). For Euclidean this is the weighted pseudo-metric of
//! Ch. 4; for the normalising metrics it weighs the normalised components (applying
//! `omega` to the features before a Mahalanobis metric would cancel out).

use scallop_geom::nalgebra::{Matrix4, SymmetricEigen};
use serde::{Deserialize, Serialize};

use crate::features::{Features, ThetaMode};
use crate::tol;

/// Whether a normalising metric uses the covariance of the whole surface or of
/// each cluster (finishing.md 11.3 \[DECISION\]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Scope {
    /// Default: the covariance of the whole clustering grid (the definition).
    #[default]
    Global,
    /// The covariance of each cluster, recomputed after every assignment sweep; a
    /// cluster with fewer than [`tol::MIN_CELLS_PER_CLUSTER_COVARIANCE`] cells or a
    /// singular covariance uses the global one. K-means loses its convergence
    /// guarantee (the iteration cap applies).
    PerCluster,
}

/// Divisor of the standard-deviation metric (finishing.md 11.3, item 4).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StdScaling {
    /// Default, as printed: `dx_j^2 / sigma_j`.
    #[default]
    Sigma,
    /// `dx_j^2 / sigma_j^2` (a diagonal Mahalanobis metric).
    Variance,
}

/// The weight `f(rho)`, `rho = lambda_II / lambda_I`, of the PCA metric's
/// direction terms (finishing.md 11.3, Eq. 3.3).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PcaFactor {
    /// Default \[DECISION\]: `f = 1 - rho^2` (vanishes for an isotropic cluster, whose
    /// principal direction is ill-defined).
    #[default]
    OneMinusRhoSquared,
    /// `f = rho^2`.
    RhoSquared,
}

impl PcaFactor {
    /// `f(rho)`.
    #[must_use]
    pub fn apply(self, rho: f64) -> f64 {
        match self {
            PcaFactor::OneMinusRhoSquared => 1.0 - rho * rho,
            PcaFactor::RhoSquared => rho * rho,
        }
    }
}

/// The metric of K-means and RPCL (finishing.md 11.3). Ward, the fifth metric of
/// the spec, is a cluster-to-cluster distance: it is the linkage of
/// [`crate::Method::Hac`], which accepts [`Metric::Euclidean`] and global
/// [`Metric::StdDev`] (both diagonal, applied as a feature scaling).
///
/// Every metric is weighted by `omega` (see the module docs); `omega = 1` gives the
/// unweighted metric.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Metric {
    /// Default: the (weighted) Euclidean metric
    /// `d^2 = sum_j omega_j dx_j^2` (metrics 1 and 2).
    #[default]
    Euclidean,
    /// `d^2 = dx^T W^(1/2) Sigma^-1 W^(1/2) dx` (metric 3). A singular global Sigma
    /// (a component constant over the surface) uses the pseudo-inverse.
    Mahalanobis {
        /// Global or per-cluster covariance.
        scope: Scope,
    },
    /// `d^2 = sum_j omega_j dx_j^2 / sigma_j` (or `/ sigma_j^2`, metric 4); a
    /// component with `sigma_j <= tol::MIN_SIGMA` weighs 0 (it is constant).
    StdDev {
        /// `sigma` (default, as printed) or `sigma^2`.
        scaling: StdScaling,
        /// Global or per-cluster sigma.
        scope: Scope,
    },
    /// The PCA-based metric (metric 6, Eqs. 3.2, 3.3): the weighted Euclidean part
    /// plus `f(rho) [sin^2(theta_I - beta_ik) + sin^2(theta_k - theta'_I)]`. Needs
    /// the samples' 3D points. K-means may not converge with it (iteration cap).
    Pca {
        /// `f(rho)`.
        factor: PcaFactor,
    },
}

impl Metric {
    /// Short name for messages.
    #[must_use]
    pub fn name(&self) -> &'static str {
        match self {
            Metric::Euclidean => "euclidean",
            Metric::Mahalanobis { .. } => "mahalanobis",
            Metric::StdDev { .. } => "std_dev",
            Metric::Pca { .. } => "pca",
        }
    }

    pub(crate) fn scope(&self) -> Scope {
        match self {
            Metric::Mahalanobis { scope } | Metric::StdDev { scope, .. } => *scope,
            Metric::Euclidean | Metric::Pca { .. } => Scope::Global,
        }
    }
}

/// A quadratic form `dx^T A dx` packed as the diagonal and the upper triangle
/// `[a00, a11, a22, a33, a01, a02, a03, a12, a13, a23]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Quad(pub(crate) [f64; 10]);

impl Quad {
    #[inline]
    pub(crate) fn eval(&self, d: &[f64; 4]) -> f64 {
        let a = &self.0;
        a[0] * d[0] * d[0]
            + a[1] * d[1] * d[1]
            + a[2] * d[2] * d[2]
            + a[3] * d[3] * d[3]
            + 2.0 * (a[4] * d[0] * d[1] + a[5] * d[0] * d[2] + a[6] * d[0] * d[3])
            + 2.0 * (a[7] * d[1] * d[2] + a[8] * d[1] * d[3] + a[9] * d[2] * d[3])
    }

    #[inline]
    pub(crate) fn eval_diagonal(&self, d: &[f64; 4]) -> f64 {
        let a = &self.0;
        a[0] * d[0] * d[0] + a[1] * d[1] * d[1] + a[2] * d[2] * d[2] + a[3] * d[3] * d[3]
    }

    pub(crate) fn is_diagonal(&self) -> bool {
        self.0[4..].iter().all(|&a| a == 0.0)
    }

    /// `W^(1/2) M W^(1/2)` of a symmetric `m`.
    pub(crate) fn weighted(m: &[[f64; 4]; 4], omega: &[f64; 4]) -> Quad {
        let w = omega.map(f64::sqrt);
        let e = |r: usize, c: usize| w[r] * w[c] * m[r][c];
        Quad([e(0, 0), e(1, 1), e(2, 2), e(3, 3), e(0, 1), e(0, 2), e(0, 3), e(1, 2), e(1, 3), e(2, 3)])
    }

    pub(crate) fn diagonal(diag: &[f64; 4], omega: &[f64; 4]) -> Quad {
        let mut q = [0.0; 10];
        for k in 0..4 {
            q[k] = omega[k] * diag[k];
        }
        Quad(q)
    }
}

/// The matrix `M` of a normalising metric for the covariance `sigma`;
/// `None` when `sigma` is singular and `pseudo` is false.
pub(crate) fn metric_matrix(metric: &Metric, sigma: &[[f64; 4]; 4], pseudo: bool) -> Option<[[f64; 4]; 4]> {
    match metric {
        Metric::Euclidean | Metric::Pca { .. } => {
            let mut m = [[0.0; 4]; 4];
            for (k, row) in m.iter_mut().enumerate() {
                row[k] = 1.0;
            }
            Some(m)
        }
        Metric::Mahalanobis { .. } => inverse(sigma, pseudo),
        Metric::StdDev { scaling, .. } => {
            let mut m = [[0.0; 4]; 4];
            for k in 0..4 {
                let sd = sigma[k][k].max(0.0).sqrt();
                if sd <= tol::MIN_SIGMA {
                    if !pseudo {
                        return None;
                    }
                    continue;
                }
                m[k][k] = match scaling {
                    StdScaling::Sigma => 1.0 / sd,
                    StdScaling::Variance => 1.0 / (sd * sd),
                };
            }
            Some(m)
        }
    }
}

/// Inverse (or pseudo-inverse) of a symmetric positive semi-definite 4x4 matrix by
/// eigen-decomposition: eigenvalues at most `tol::SINGULAR_EIGEN_REL` times the
/// largest count as 0.
#[allow(clippy::needless_range_loop)] // symmetric 4 x 4 matrix: indices read best
fn inverse(sigma: &[[f64; 4]; 4], pseudo: bool) -> Option<[[f64; 4]; 4]> {
    let m = Matrix4::from_fn(|r, c| sigma[r][c]);
    let eigen = SymmetricEigen::new(m);
    let largest = eigen.eigenvalues.iter().fold(0.0f64, |a, &b| a.max(b));
    if largest <= 0.0 || !largest.is_finite() {
        return if pseudo { Some([[0.0; 4]; 4]) } else { None };
    }
    let mut out = [[0.0; 4]; 4];
    for k in 0..4 {
        let lambda = eigen.eigenvalues[k];
        if lambda <= tol::SINGULAR_EIGEN_REL * largest {
            if !pseudo {
                return None;
            }
            continue;
        }
        let v = eigen.eigenvectors.column(k);
        for r in 0..4 {
            for c in 0..4 {
                out[r][c] += v[r] * v[c] / lambda;
            }
        }
    }
    // Exactly symmetric.
    for r in 0..4 {
        for c in r + 1..4 {
            let s = 0.5 * (out[r][c] + out[c][r]);
            out[r][c] = s;
            out[c][r] = s;
        }
    }
    Some(out)
}

/// The global quadratic form of `metric` with weights `omega`.
pub(crate) fn global_quad(features: &Features, metric: &Metric, omega: &[f64; 4], mode: ThetaMode) -> Quad {
    match metric {
        Metric::Euclidean | Metric::Pca { .. } => Quad::diagonal(&[1.0; 4], omega),
        _ => {
            let sigma = features.covariance(mode);
            let m = metric_matrix(metric, &sigma, true).unwrap_or([[0.0; 4]; 4]);
            Quad::weighted(&m, omega)
        }
    }
}

/// The quadratic form of one cluster: its own covariance when it has enough cells
/// and it is regular, else `global`.
pub(crate) fn cluster_quad(
    metric: &Metric,
    omega: &[f64; 4],
    count: usize,
    sigma: &[[f64; 4]; 4],
    global: &Quad,
) -> Quad {
    if count < tol::MIN_CELLS_PER_CLUSTER_COVARIANCE {
        return *global;
    }
    metric_matrix(metric, sigma, false).map_or(*global, |m| Quad::weighted(&m, omega))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quad_forms_agree() {
        let m = [[2.0, 0.5, 0.1, 0.0], [0.5, 3.0, 0.2, 0.3], [0.1, 0.2, 1.0, 0.4], [0.0, 0.3, 0.4, 5.0]];
        let omega = [1.0, 0.5, 0.25, 0.0];
        let q = Quad::weighted(&m, &omega);
        let d = [0.3, -1.2, 0.7, 2.0];
        let mut direct = 0.0;
        for r in 0..4 {
            for c in 0..4 {
                direct += d[r] * omega[r].sqrt() * m[r][c] * omega[c].sqrt() * d[c];
            }
        }
        assert!((q.eval(&d) - direct).abs() < 1e-12);
    }

    #[test]
    fn pseudo_inverse_of_singular_covariance() {
        let sigma = [[2.0, 0.0, 0.0, 0.0], [0.0, 4.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]];
        let inv = inverse(&sigma, true).unwrap();
        for (k, expected) in [0.5, 0.25, 0.0, 1.0].iter().enumerate() {
            assert!((inv[k][k] - expected).abs() < 1e-12);
        }
        assert!(inverse(&sigma, false).is_none());
    }
}
