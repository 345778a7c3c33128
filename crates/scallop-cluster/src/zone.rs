//! Zone records (finishing.md 11.10).

use scallop_analysis::{FeatureVector, Moments, Pca};

use crate::features::{Features, NO_LABEL, Sums, ThetaMode, covariance_about};

/// One zone: a 4-connected component of one cluster (finishing.md 11.9, 11.10).
#[derive(Clone, Debug, PartialEq)]
pub struct Zone {
    /// The cluster the zone comes from.
    pub cluster: u32,
    /// Its grid cells `a * N_v + b`, increasing.
    pub cells: Vec<u32>,
    /// Mean feature vector (theta per the run's [`ThetaMode`]: circular mean when
    /// wrapped): the zone centre `c_k`.
    pub feature_mean: FeatureVector,
    /// Population covariance of `(u, v, s, theta)` about the mean (theta deviation
    /// wrapped in [`ThetaMode::Wrapped`]).
    pub feature_covariance: [[f64; 4]; 4],
    /// 3D statistics, when the features carry geometry.
    pub geometry: Option<ZoneGeometry>,
}

impl Zone {
    /// Number of cells (samples) of the zone.
    #[must_use]
    pub fn len(&self) -> usize {
        self.cells.len()
    }

    /// Always false: a zone has at least one cell.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.cells.is_empty()
    }
}

/// 3D statistics of a zone (finishing.md 11.10).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ZoneGeometry {
    /// 3D mean and covariance `Gamma_k` of the zone's sample points (mm, mm^2;
    /// population form).
    pub moments: Moments,
    /// PCA of `Gamma_k`: eigenvalues, axes `X_I, X_II, X_III`, and through its
    /// methods the shape factor `mu~` ([`Pca::shape_factor`]), size `chi~`
    /// ([`Pca::size`]), slope `s~` ([`Pca::slope`]), slope direction
    /// ([`Pca::slope_direction`]) and principal direction
    /// ([`Pca::principal_direction`]).
    pub pca: Pca,
    /// Mean slope vector `D`: the mean of the XY projections `(n_x, n_y)` of the
    /// zone's unit normals (finishing.md 12.5).
    pub mean_slope_vector: [f64; 2],
}

/// The records of `count` zones given the zone and cluster of every grid cell.
pub(crate) fn zone_records(
    features: &Features,
    zone_of_cell: &[u32],
    cluster_of_cell: &[u32],
    count: usize,
    mode: ThetaMode,
) -> Vec<Zone> {
    let mut members: Vec<Vec<u32>> = vec![Vec::new(); count];
    let mut cluster = vec![0u32; count];
    for (cell, &z) in zone_of_cell.iter().enumerate() {
        if z != NO_LABEL {
            #[allow(clippy::cast_possible_truncation)] // cell < u32::MAX (checked by Features)
            members[z as usize].push(cell as u32);
            cluster[z as usize] = cluster_of_cell[cell];
        }
    }
    let points_of =
        |cells: &[u32]| -> Vec<usize> { cells.iter().filter_map(|&c| features.point_of_cell(c as usize)).collect() };
    members
        .into_iter()
        .zip(cluster)
        .map(|(cells, cluster)| {
            let points = points_of(&cells);
            let mut sums = Sums::default();
            for &i in &points {
                sums.add(&features.x[i], &features.doubled[i]);
            }
            let mean = sums.mean(mode).unwrap_or([0.0; 4]);
            let feature_covariance = covariance_about(points.iter().map(|&i| &features.x[i]), &mean, mode);
            let [u, v, slope, slope_direction] = mean;
            let geometry = features.geometry.as_ref().map(|(p, normals)| {
                let mut moments = Moments::new();
                let mut d = [0.0; 2];
                for &i in &points {
                    moments.add(&p[i], 1.0);
                    d[0] += normals[i].x;
                    d[1] += normals[i].y;
                }
                let inv = 1.0 / points.len().max(1) as f64;
                ZoneGeometry { moments, pca: Pca::from_moments(&moments), mean_slope_vector: [d[0] * inv, d[1] * inv] }
            });
            Zone {
                cluster,
                cells,
                feature_mean: FeatureVector { u, v, slope, slope_direction },
                feature_covariance,
                geometry,
            }
        })
        .collect()
}
