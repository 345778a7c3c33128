//! Shared machinery of K-means and RPCL: circle initialisation (11.4), zone
//! statistics (11.5), frozen per-sweep metric state and the assignment sweep.

use std::f64::consts::PI;

use rayon::prelude::*;
use scallop_analysis::Moments;
use scallop_geom::Point3;

use crate::eigen::top_two;
use crate::features::{Features, NO_LABEL, Sums, ThetaMode, covariance_about, delta};
use crate::metric::{Metric, Quad, Scope, cluster_quad, global_quad};
use crate::tol;

/// The fixed inputs of one clustering run.
pub(crate) struct Setup<'a> {
    pub(crate) features: &'a Features,
    pub(crate) omega: [f64; 4],
    pub(crate) metric: Metric,
    pub(crate) mode: ThetaMode,
    pub(crate) global: Quad,
}

impl<'a> Setup<'a> {
    pub(crate) fn new(features: &'a Features, omega: [f64; 4], metric: Metric, mode: ThetaMode) -> Setup<'a> {
        let global = global_quad(features, &metric, &omega, mode);
        Setup { features, omega, metric, mode, global }
    }

    fn wrapped(&self) -> bool {
        self.mode == ThetaMode::Wrapped
    }

    fn uses_moments(&self) -> bool {
        matches!(self.metric, Metric::Pca { .. })
    }
}

/// Index of the point whose cell centre is nearest to `(u, v)` (the cell that
/// contains `(u, v)` on an unmasked grid); lowest index on ties.
pub(crate) fn nearest_point(features: &Features, u: f64, v: f64) -> usize {
    let [nu, nv] = features.grid();
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)] // clamped to the grid
    let cell = |t: f64, n: usize| ((t * n as f64).floor().max(0.0) as usize).min(n - 1);
    if let Some(p) = features.point_of_cell(cell(u, nu) * nv + cell(v, nv)) {
        return p;
    }
    let mut best = (f64::INFINITY, 0);
    for (i, x) in features.x.iter().enumerate() {
        let d = (x[0] - u).powi(2) + (x[1] - v).powi(2);
        if d < best.0 {
            best = (d, i);
        }
    }
    best.1
}

/// Initial centres on the circle of Eq. 3.4: `(1/2 + cos(2 k pi / K) / 4,
/// 1/2 + sin(2 k pi / K) / 4)`, `k = 1..K`, with `s` and `theta` of the sample
/// nearest to that parameter point (the cell containing it; finishing.md 11.4).
pub(crate) fn circle_centres(features: &Features, k: usize) -> Vec<[f64; 4]> {
    (1..=k)
        .map(|j| {
            let angle = 2.0 * PI * j as f64 / k as f64;
            let (u, v) = (0.5 + 0.25 * angle.cos(), 0.5 + 0.25 * angle.sin());
            let x = features.x[nearest_point(features, u, v)];
            [u, v, x[2], x[3]]
        })
        .collect()
}

/// Per-cluster statistics: feature sums (exact means, 11.2) and, for the PCA
/// metric, the 3D moments `Gamma_k` (stable incremental form, 11.5).
#[derive(Clone, Debug)]
pub(crate) struct Stats {
    pub(crate) sums: Vec<Sums>,
    pub(crate) moments: Option<Vec<Moments>>,
}

impl Stats {
    pub(crate) fn batch(setup: &Setup, labels: &[u32], k: usize) -> Stats {
        let f = setup.features;
        let sums = Sums::per_label(labels, f, k);
        let moments = match (&f.geometry, setup.uses_moments()) {
            (Some((points, _)), true) => {
                let mut m = vec![Moments::new(); k];
                for (i, &l) in labels.iter().enumerate() {
                    m[l as usize].add(&points[i], 1.0);
                }
                Some(m)
            }
            _ => None,
        };
        Stats { sums, moments }
    }

    pub(crate) fn move_point(&mut self, setup: &Setup, i: usize, from: u32, to: u32) {
        let f = setup.features;
        self.sums[from as usize].remove(&f.x[i], &f.doubled[i]);
        self.sums[to as usize].add(&f.x[i], &f.doubled[i]);
        if let (Some(m), Some((points, _))) = (&mut self.moments, &f.geometry) {
            m[from as usize].remove(&points[i], 1.0);
            m[to as usize].add(&points[i], 1.0);
        }
    }

    pub(crate) fn count(&self, k: usize) -> usize {
        self.sums[k].n
    }
}

/// The PCA metric's frozen state of one cluster.
#[derive(Clone, Debug)]
struct PcaCluster {
    /// `f(rho)`, 0 when the cluster has fewer than 3 cells.
    factor: f64,
    /// `theta_I`, the XY angle of `X_I` (None: no XY projection).
    theta_i: Option<f64>,
    /// `S(u_k, v_k)`: the point of the cell nearest to the centre's `(u, v)`.
    centre_point: Point3,
    moments: Moments,
}

/// The per-cluster metric state, frozen during one assignment sweep.
pub(crate) struct Frozen {
    /// The centres (RPCL moves them during its competitive sweep).
    pub(crate) centres: Vec<[f64; 4]>,
    quads: Vec<Quad>,
    diagonal: bool,
    pca: Option<Vec<PcaCluster>>,
}

/// XY angle of a vector, `None` when its projection is shorter than `tol::XY_DEGENERATE`.
fn angle_xy(x: f64, y: f64) -> Option<f64> {
    (x.hypot(y) >= tol::XY_DEGENERATE).then(|| y.atan2(x))
}

impl Frozen {
    /// The state for `centres`; per-cluster covariances and the PCA terms come from
    /// `stats` and `labels` when given (none before the first assignment). With
    /// `base_only`, the PCA metric is reduced to its Euclidean part (RPCL's
    /// competitive step, finishing.md 11.7).
    pub(crate) fn new(
        setup: &Setup,
        centres: Vec<[f64; 4]>,
        current: Option<(&Stats, &[u32])>,
        base_only: bool,
    ) -> Frozen {
        let k = centres.len();
        let mut quads = vec![setup.global; k];
        if let (Scope::PerCluster, Some((stats, labels))) = (setup.metric.scope(), current) {
            let f = setup.features;
            for (c, quad) in quads.iter_mut().enumerate() {
                let count = stats.count(c);
                if count >= tol::MIN_CELLS_PER_CLUSTER_COVARIANCE {
                    let members = labels.iter().zip(&f.x).filter(|(l, _)| **l as usize == c).map(|(_, x)| x);
                    let mean = stats.sums[c].mean(setup.mode).unwrap_or(centres[c]);
                    let sigma = covariance_about(members, &mean, setup.mode);
                    *quad = cluster_quad(&setup.metric, &setup.omega, count, &sigma, &setup.global);
                }
            }
        }
        let diagonal = quads.iter().all(Quad::is_diagonal);
        let pca = match (setup.metric, current, &setup.features.geometry, base_only) {
            (Metric::Pca { factor }, Some((stats, _)), Some((points, _)), false) => {
                let moments = stats.moments.as_ref();
                Some(
                    (0..k)
                        .map(|c| {
                            let m = moments.map_or_else(Moments::new, |m| m[c]);
                            let centre_point = points[nearest_point(setup.features, centres[c][0], centres[c][1])];
                            if m.count() < tol::PCA_MIN_CELLS {
                                return PcaCluster { factor: 0.0, theta_i: None, centre_point, moments: m };
                            }
                            let (l1, l2, axis) = top_two(&m.covariance());
                            let rho = if l1 > 0.0 { (l2 / l1).clamp(0.0, 1.0) } else { 0.0 };
                            PcaCluster {
                                factor: factor.apply(rho),
                                theta_i: angle_xy(axis.x, axis.y),
                                centre_point,
                                moments: m,
                            }
                        })
                        .collect(),
                )
            }
            _ => None,
        };
        Frozen { centres, quads, diagonal, pca }
    }

    /// `d^2(x_i, c_k)` with the base (quadratic-form) part only.
    #[inline]
    pub(crate) fn base(&self, x: &[f64; 4], c: usize, wrapped: bool) -> f64 {
        let d = delta(x, &self.centres[c], wrapped);
        if self.diagonal { self.quads[c].eval_diagonal(&d) } else { self.quads[c].eval(&d) }
    }

    /// The PCA metric's extra term for point `i` and cluster `c` (Eq. 3.2).
    fn pca_term(&self, setup: &Setup, i: usize, c: usize, member: bool) -> f64 {
        let Some(pca) = &self.pca else { return 0.0 };
        let z = &pca[c];
        if z.factor == 0.0 {
            return 0.0;
        }
        let Some((points, _)) = &setup.features.geometry else { return 0.0 };
        let p = points[i];
        let mut term = 0.0;
        if let Some(theta_i) = z.theta_i {
            let offset = p - z.centre_point;
            if let Some(beta) = angle_xy(offset.x, offset.y) {
                term += (theta_i - beta).sin().powi(2);
            }
        }
        let theta_prime = if member {
            z.theta_i
        } else {
            let mut m = z.moments;
            m.add(&p, 1.0);
            let (_, _, axis) = top_two(&m.covariance());
            angle_xy(axis.x, axis.y)
        };
        if let Some(tp) = theta_prime {
            term += (self.centres[c][3] - tp).sin().powi(2);
        }
        z.factor * term
    }

    /// The full `d^2(x_i, c_c)` (base part plus the PCA term when active).
    #[inline]
    pub(crate) fn distance2(&self, setup: &Setup, i: usize, c: usize, previous: Option<&[u32]>) -> f64 {
        let mut d = self.base(&setup.features.x[i], c, setup.wrapped());
        if self.pca.is_some() {
            let member = previous.is_some_and(|p| p[i] as usize == c);
            d += self.pca_term(setup, i, c, member);
        }
        d
    }

    /// The nearest centre of point `i` (lowest index on ties).
    #[inline]
    fn nearest(&self, setup: &Setup, i: usize, previous: Option<&[u32]>) -> u32 {
        let mut best = (f64::INFINITY, 0u32);
        #[allow(clippy::cast_possible_truncation)] // k <= cells < u32::MAX
        for c in 0..self.centres.len() {
            let d = self.distance2(setup, i, c, previous);
            if d < best.0 {
                best = (d, c as u32);
            }
        }
        best.1
    }

    /// Assigns every point to its nearest centre (finishing.md 11.6, step 2);
    /// `previous` tells cluster membership to the PCA metric.
    pub(crate) fn assign(&self, setup: &Setup, previous: Option<&[u32]>, out: &mut Vec<u32>) {
        let n = setup.features.len();
        let wrapped = setup.wrapped();
        out.resize(n, NO_LABEL);
        let parallel = self.pca.is_some() || n.saturating_mul(self.centres.len()) >= tol::PARALLEL_MIN_PAIRS;
        if parallel {
            out.par_chunks_mut(tol::PARALLEL_CHUNK).enumerate().for_each(|(chunk, part)| {
                let start = chunk * tol::PARALLEL_CHUNK;
                for (j, label) in part.iter_mut().enumerate() {
                    *label = self.nearest(setup, start + j, previous);
                }
            });
        } else if self.diagonal && self.pca.is_none() {
            // Hot path of the optimiser: diagonal forms, no PCA term.
            let x = &setup.features.x;
            for (label, xi) in out.iter_mut().zip(x) {
                let mut best = (f64::INFINITY, 0u32);
                #[allow(clippy::cast_possible_truncation)]
                for (c, (centre, quad)) in self.centres.iter().zip(&self.quads).enumerate() {
                    let d = quad.eval_diagonal(&delta(xi, centre, wrapped));
                    if d < best.0 {
                        best = (d, c as u32);
                    }
                }
                *label = best.1;
            }
        } else {
            for (i, label) in out.iter_mut().enumerate() {
                *label = self.nearest(setup, i, previous);
            }
        }
    }
}

/// The exact cluster means (11.2); an empty cluster keeps `previous[c]`.
pub(crate) fn means(stats: &Stats, previous: &[[f64; 4]], mode: ThetaMode) -> Vec<[f64; 4]> {
    stats.sums.iter().zip(previous).map(|(s, p)| s.mean(mode).unwrap_or(*p)).collect()
}

/// [`means`] into a caller-owned buffer of the same length.
pub(crate) fn means_into(stats: &Stats, previous: &[[f64; 4]], mode: ThetaMode, out: &mut [[f64; 4]]) {
    for ((o, s), p) in out.iter_mut().zip(&stats.sums).zip(previous) {
        *o = s.mean(mode).unwrap_or(*p);
    }
}

/// Drops empty clusters: relabels `labels` to `0..m` keeping the order of the
/// original cluster indices; returns `m` and the kept original indices.
pub(crate) fn compact(labels: &mut [u32], k: usize) -> (usize, Vec<usize>) {
    let mut used = vec![false; k];
    for &l in labels.iter() {
        used[l as usize] = true;
    }
    let mut map = vec![NO_LABEL; k];
    let mut kept = Vec::new();
    for (c, &u) in used.iter().enumerate() {
        if u {
            #[allow(clippy::cast_possible_truncation)]
            {
                map[c] = kept.len() as u32;
            }
            kept.push(c);
        }
    }
    for l in labels.iter_mut() {
        *l = map[*l as usize];
    }
    (kept.len(), kept)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metric::PcaFactor;
    use scallop_analysis::{GridOptions, Pca, sample_patch};

    /// The PCA metric (Eq. 3.2) against a direct evaluation with the analysis
    /// crate's PCA, for members and non-members, both factors.
    #[test]
    fn pca_metric_matches_direct_formula() {
        let set = scallop_surface::builtin("rubio").unwrap();
        let samples = sample_patch(&set.patches()[0], &GridOptions { cells_u: 12, cells_v: 9 }).unwrap();
        let f = Features::from_samples(&samples).unwrap();
        let (points, _) = f.geometry().unwrap();
        let labels: Vec<u32> = f.x.iter().map(|x| u32::from(x[0] > 0.5) + u32::from(x[1] > 0.6)).collect();
        for factor in [PcaFactor::OneMinusRhoSquared, PcaFactor::RhoSquared] {
            let setup = Setup::new(&f, [1.0; 4], Metric::Pca { factor }, ThetaMode::Wrapped);
            let stats = Stats::batch(&setup, &labels, 3);
            let centres = means(&stats, &[[0.0; 4]; 3], ThetaMode::Wrapped);
            let frozen = Frozen::new(&setup, centres.clone(), Some((&stats, &labels)), false);
            let angle = |v: scallop_geom::Vec3| v.y.atan2(v.x);
            for i in (0..f.len()).step_by(7) {
                for c in 0..3 {
                    let members: Vec<Point3> =
                        (0..f.len()).filter(|&j| labels[j] as usize == c).map(|j| points[j]).collect();
                    let pca = Pca::from_moments(&Moments::of_points(&members));
                    let rho = pca.eigenvalues[1] / pca.eigenvalues[0];
                    let weight = factor.apply(rho);
                    let theta_i = angle(pca.axes[0]);
                    let centre = points[nearest_point(&f, centres[c][0], centres[c][1])];
                    let beta = angle(points[i] - centre);
                    let theta_prime = if labels[i] as usize == c {
                        theta_i
                    } else {
                        let mut with = members.clone();
                        with.push(points[i]);
                        angle(Pca::from_moments(&Moments::of_points(&with)).axes[0])
                    };
                    let d = delta(&f.x[i], &centres[c], true);
                    let base: f64 = d.iter().map(|v| v * v).sum();
                    let expected =
                        base + weight * ((theta_i - beta).sin().powi(2) + (centres[c][3] - theta_prime).sin().powi(2));
                    let got = frozen.distance2(&setup, i, c, Some(&labels));
                    assert!((got - expected).abs() < 1e-9, "cell {i} cluster {c}: {got} vs {expected}");
                }
            }
        }
    }

    /// Incremental sums (add/remove in any order) give the batch means (A12 for the
    /// feature statistics; the 3D moments are tested in scallop-analysis).
    #[test]
    fn incremental_sums_equal_batch() {
        let features: Vec<scallop_analysis::FeatureVector> = (0..50)
            .map(|i| {
                let t = i as f64;
                scallop_analysis::FeatureVector {
                    u: (t * 0.37).fract(),
                    v: (t * 0.61).fract(),
                    slope: (t * 0.13).fract(),
                    slope_direction: (t * 0.77).fract() * 3.0 - 1.5,
                }
            })
            .collect();
        let f = Features::from_grid([5, 10], &features).unwrap();
        let setup = Setup::new(&f, [1.0; 4], Metric::Euclidean, ThetaMode::Wrapped);
        let mut labels: Vec<u32> = (0..50).map(|i| (i % 3) as u32).collect();
        let mut stats = Stats::batch(&setup, &labels, 3);
        for step in 0..200usize {
            let i = (step * 17) % 50;
            let to = ((step * 7) % 3) as u32;
            if labels[i] != to {
                stats.move_point(&setup, i, labels[i], to);
                labels[i] = to;
            }
        }
        let batch = Stats::batch(&setup, &labels, 3);
        for mode in [ThetaMode::Wrapped, ThetaMode::Plain] {
            for c in 0..3 {
                let (a, b) = (stats.sums[c].mean(mode).unwrap(), batch.sums[c].mean(mode).unwrap());
                for k in 0..4 {
                    assert!((a[k] - b[k]).abs() < 1e-12, "{mode:?} cluster {c} component {k}");
                }
            }
        }
    }
}
