//! Feature vectors `(u, v, s, theta)` on a clustering grid (finishing.md 11.1, 11.2).

use std::f64::consts::{FRAC_PI_2, PI};

use scallop_analysis::{FeatureVector, Samples};
use scallop_geom::{Point3, Vec3};
use serde::{Deserialize, Serialize};

use crate::error::ClusterError;

/// Label of a grid cell that holds no sample (a masked cell, finishing.md 4.1).
pub const NO_LABEL: u32 = u32::MAX;

/// How the steepest-slope direction `theta` (a direction modulo pi) enters
/// differences and means (finishing.md 11.2).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ThetaMode {
    /// Default: `d theta` wrapped into `[-pi/2, pi/2)`; cluster means by the
    /// doubled-angle circular mean `1/2 atan2(sum sin 2 theta, sum cos 2 theta)`;
    /// covariances use the wrapped deviation from that mean. Directions near `-pi/2`
    /// and `pi/2` are close.
    #[default]
    Wrapped,
    /// \[COMPAT\] Plain differences and arithmetic means, as printed in the thesis
    /// (they jump at `+-pi/2`).
    Plain,
}

impl ThetaMode {
    pub(crate) fn index(self) -> usize {
        match self {
            ThetaMode::Wrapped => 0,
            ThetaMode::Plain => 1,
        }
    }
}

/// Wraps a difference of two directions into `[-pi/2, pi/2)`.
///
/// ```
/// use std::f64::consts::FRAC_PI_2;
/// let d = scallop_cluster::wrap_direction_difference(0.49 * std::f64::consts::PI - (-0.49 * std::f64::consts::PI));
/// assert!((d + 0.02 * std::f64::consts::PI).abs() < 1e-12);
/// assert_eq!(scallop_cluster::wrap_direction_difference(FRAC_PI_2), -FRAC_PI_2);
/// ```
#[must_use]
#[inline]
pub fn wrap_direction_difference(d: f64) -> f64 {
    // Differences of two folded directions lie in (-pi, pi]: one correction suffices.
    if d >= FRAC_PI_2 {
        if d < 3.0 * FRAC_PI_2 { d - PI } else { d - PI * ((d + FRAC_PI_2) / PI).floor() }
    } else if d < -FRAC_PI_2 {
        if d >= -3.0 * FRAC_PI_2 { d + PI } else { d - PI * ((d + FRAC_PI_2) / PI).floor() }
    } else {
        d
    }
}

/// Folds an angle into `(-pi/2, pi/2]` (a direction modulo pi).
#[must_use]
#[inline]
pub(crate) fn fold_direction(t: f64) -> f64 {
    if t > -FRAC_PI_2 && t <= FRAC_PI_2 {
        return t;
    }
    let r = t.rem_euclid(PI);
    if r > FRAC_PI_2 { r - PI } else { r }
}

/// The feature vectors of the cells of an `N_u x N_v` clustering grid (finishing.md
/// 11.1): one cell-centre sample per kept cell, in cell order `a * N_v + b` (`a`
/// along u), with the sample's 3D point and normal when known (the PCA metric and
/// the zones' geometry need them).
///
/// Units: `u, v` in `[0, 1]`, `s` in `[0, pi/2]` rad, `theta` in `(-pi/2, pi/2]` rad.
/// No normalisation beyond the chosen metric (finishing.md 11.1): the weights `omega`
/// and the metric are parameters of each [`crate::partition`] call, so one
/// `Features` serves every evaluation of an optimiser.
///
/// Built once per surface; holds the global statistics (mean, covariance of the
/// four components under both [`ThetaMode`]s) that the Mahalanobis and
/// standard-deviation metrics need.
#[derive(Clone, Debug, PartialEq)]
pub struct Features {
    grid: [usize; 2],
    /// Grid cell index of every point (increasing).
    cells: Vec<u32>,
    /// Point index of every grid cell, [`NO_LABEL`] for a masked cell.
    point_of_cell: Vec<u32>,
    /// `[u, v, s, theta]` per point.
    pub(crate) x: Vec<[f64; 4]>,
    /// `[sin 2 theta, cos 2 theta]` per point.
    pub(crate) doubled: Vec<[f64; 2]>,
    /// 3D points and unit normals, when known.
    pub(crate) geometry: Option<(Vec<Point3>, Vec<Vec3>)>,
    /// Global statistics, indexed by [`ThetaMode::index`].
    pub(crate) global: [Global; 2],
}

/// Mean and population covariance of the four components over all points.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Global {
    pub(crate) mean: [f64; 4],
    pub(crate) covariance: [[f64; 4]; 4],
}

impl Features {
    /// The features of cell-centre samples of one patch ([`scallop_analysis::sample_patch`]
    /// or [`scallop_analysis::sample_patch_masked`]), with their points and normals.
    ///
    /// ```
    /// let set = scallop_surface::builtin("choi").unwrap();
    /// let samples = scallop_analysis::sample_patch(&set.patches()[0], &Default::default()).unwrap();
    /// let features = scallop_cluster::Features::from_samples(&samples).unwrap();
    /// assert_eq!((features.grid(), features.len()), ([80, 80], 6400));
    /// ```
    ///
    /// # Errors
    /// [`ClusterError::NoGrid`] when the samples have no grid (several patches, a
    /// mesh); [`ClusterError::NotOnGrid`] for a sample without `(u, v)`;
    /// [`ClusterError::CellOrder`] when two samples share a cell;
    /// [`ClusterError::BadFeature`] for a non-finite value.
    pub fn from_samples(samples: &Samples) -> Result<Features, ClusterError> {
        let grid = samples.grid().ok_or(ClusterError::NoGrid)?;
        let mut cells = Vec::with_capacity(samples.len());
        let mut features = Vec::with_capacity(samples.len());
        let mut points = Vec::with_capacity(samples.len());
        let mut normals = Vec::with_capacity(samples.len());
        for (index, s) in samples.samples().iter().enumerate() {
            let not_on_grid = ClusterError::NotOnGrid { index, cells_u: grid[0], cells_v: grid[1] };
            let [a, b] = s.grid_cell(grid).ok_or_else(|| not_on_grid.clone())?;
            cells.push(a * grid[1] + b);
            features.push(s.feature().ok_or(not_on_grid)?);
            points.push(s.point);
            normals.push(s.normal);
        }
        Features::from_cells(grid, &cells, &features)?.with_geometry(points, normals)
    }

    /// The features of a full `N_u x N_v` grid in cell order `a * N_v + b`, without
    /// 3D geometry.
    ///
    /// # Errors
    /// [`ClusterError::EmptyGrid`], [`ClusterError::LengthMismatch`] when
    /// `features.len() != N_u N_v`, [`ClusterError::BadFeature`].
    pub fn from_grid(grid: [usize; 2], features: &[FeatureVector]) -> Result<Features, ClusterError> {
        let cells: Vec<usize> = (0..grid[0].saturating_mul(grid[1])).collect();
        if features.len() != cells.len() && grid[0] > 0 && grid[1] > 0 {
            return Err(ClusterError::LengthMismatch { what: "features", expected: cells.len(), got: features.len() });
        }
        Features::from_cells(grid, &cells, features)
    }

    /// The features of the kept cells `cells` (grid indices `a * N_v + b`,
    /// strictly increasing) of an `N_u x N_v` grid; the other cells are masked.
    ///
    /// # Errors
    /// [`ClusterError::EmptyGrid`] (a zero dimension or no cell),
    /// [`ClusterError::LengthMismatch`], [`ClusterError::CellOrder`] (a cell outside
    /// the grid, repeated or out of order), [`ClusterError::BadFeature`].
    pub fn from_cells(grid: [usize; 2], cells: &[usize], features: &[FeatureVector]) -> Result<Features, ClusterError> {
        let total = grid[0].saturating_mul(grid[1]);
        if total == 0 || cells.is_empty() {
            return Err(ClusterError::EmptyGrid { cells_u: grid[0], cells_v: grid[1] });
        }
        if features.len() != cells.len() {
            return Err(ClusterError::LengthMismatch { what: "features", expected: cells.len(), got: features.len() });
        }
        if total > NO_LABEL as usize {
            return Err(ClusterError::BadSetting {
                name: "grid cells",
                value: total as f64,
                fix: "use fewer than 2^32 - 1 cells",
            });
        }
        let mut point_of_cell = vec![NO_LABEL; total];
        let mut previous = None;
        for (index, &cell) in cells.iter().enumerate() {
            if cell >= total || previous.is_some_and(|p| cell <= p) {
                return Err(ClusterError::CellOrder { index, cell });
            }
            previous = Some(cell);
            #[allow(clippy::cast_possible_truncation)] // index < total < u32::MAX
            {
                point_of_cell[cell] = index as u32;
            }
        }
        let mut x = Vec::with_capacity(features.len());
        let mut doubled = Vec::with_capacity(features.len());
        for (index, f) in features.iter().enumerate() {
            let a = f.to_array();
            if !a.iter().all(|c| c.is_finite()) {
                return Err(ClusterError::BadFeature { index });
            }
            let theta = fold_direction(a[3]);
            x.push([a[0], a[1], a[2], theta]);
            let (sin, cos) = (2.0 * theta).sin_cos();
            doubled.push([sin, cos]);
        }
        #[allow(clippy::cast_possible_truncation)] // checked above: total < u32::MAX
        let cells = cells.iter().map(|&c| c as u32).collect();
        let global = [ThetaMode::Wrapped, ThetaMode::Plain].map(|mode| global_statistics(&x, &doubled, mode));
        Ok(Features { grid, cells, point_of_cell, x, doubled, geometry: None, global })
    }

    /// Attaches the 3D points (mm) and unit normals of the samples, in point order.
    ///
    /// # Errors
    /// [`ClusterError::LengthMismatch`] when a length differs from [`Features::len`],
    /// [`ClusterError::BadFeature`] for a non-finite point or normal.
    pub fn with_geometry(mut self, points: Vec<Point3>, normals: Vec<Vec3>) -> Result<Features, ClusterError> {
        for (what, got) in [("points", points.len()), ("normals", normals.len())] {
            if got != self.len() {
                return Err(ClusterError::LengthMismatch { what, expected: self.len(), got });
            }
        }
        let finite = |p: &Point3, n: &Vec3| p.coords.iter().chain(n.iter()).all(|c| c.is_finite());
        if let Some(index) = points.iter().zip(&normals).position(|(p, n)| !finite(p, n)) {
            return Err(ClusterError::BadFeature { index });
        }
        self.geometry = Some((points, normals));
        Ok(self)
    }

    /// `[N_u, N_v]`.
    #[must_use]
    pub fn grid(&self) -> [usize; 2] {
        self.grid
    }

    /// Number of points (kept cells).
    #[must_use]
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Always false (a `Features` has at least one point).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Number of grid cells `N_u N_v` (kept or masked).
    #[must_use]
    pub fn cell_count(&self) -> usize {
        self.point_of_cell.len()
    }

    /// Grid cell index `a * N_v + b` of every point, increasing.
    #[must_use]
    pub fn cells(&self) -> &[u32] {
        &self.cells
    }

    /// Point index of grid cell `cell` (`None` when masked or outside the grid).
    #[must_use]
    pub fn point_of_cell(&self, cell: usize) -> Option<usize> {
        self.point_of_cell.get(cell).filter(|&&p| p != NO_LABEL).map(|&p| p as usize)
    }

    /// The feature vector of point `i` (`theta` folded into `(-pi/2, pi/2]`).
    ///
    /// # Panics
    /// When `i >= self.len()`.
    #[must_use]
    pub fn feature(&self, i: usize) -> FeatureVector {
        let [u, v, slope, slope_direction] = self.x[i];
        FeatureVector { u, v, slope, slope_direction }
    }

    /// 3D points and unit normals, when known.
    #[must_use]
    pub fn geometry(&self) -> Option<(&[Point3], &[Vec3])> {
        self.geometry.as_ref().map(|(p, n)| (p.as_slice(), n.as_slice()))
    }

    /// Mean feature vector over all points under `mode` (finishing.md 11.2).
    #[must_use]
    pub fn mean(&self, mode: ThetaMode) -> FeatureVector {
        let [u, v, slope, slope_direction] = self.global[mode.index()].mean;
        FeatureVector { u, v, slope, slope_direction }
    }

    /// Population covariance of `(u, v, s, theta)` over all points under `mode` (the
    /// global Sigma of the Mahalanobis and standard-deviation metrics).
    #[must_use]
    pub fn covariance(&self, mode: ThetaMode) -> [[f64; 4]; 4] {
        self.global[mode.index()].covariance
    }
}

/// `x - c` with the theta component per `mode`.
#[inline]
pub(crate) fn delta(x: &[f64; 4], c: &[f64; 4], wrapped: bool) -> [f64; 4] {
    let t = x[3] - c[3];
    [x[0] - c[0], x[1] - c[1], x[2] - c[2], if wrapped { wrap_direction_difference(t) } else { t }]
}

/// Running sums of a set of points: exact means under both theta modes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Sums {
    pub(crate) n: usize,
    sum: [f64; 4],
    sin: f64,
    cos: f64,
}

impl Sums {
    /// The sums of every label `0..k` over the points (`labels[i]` of point `i`).
    /// A run of points of one label accumulates in registers (grid neighbours
    /// share labels): the same additions in the same order as one `add` per
    /// point into `sums[label]`, without a store-to-load chain through memory.
    pub(crate) fn per_label(labels: &[u32], f: &Features, k: usize) -> Vec<Sums> {
        let mut sums = vec![Sums::default(); k];
        let (mut i, n) = (0, labels.len().min(f.x.len()).min(f.doubled.len()));
        while i < n {
            let l = labels[i] as usize;
            let mut acc = sums[l];
            while i < n && labels[i] as usize == l {
                acc.add(&f.x[i], &f.doubled[i]);
                i += 1;
            }
            sums[l] = acc;
        }
        sums
    }

    #[inline]
    pub(crate) fn add(&mut self, x: &[f64; 4], d: &[f64; 2]) {
        self.n += 1;
        for (s, v) in self.sum.iter_mut().zip(x) {
            *s += v;
        }
        self.sin += d[0];
        self.cos += d[1];
    }

    #[inline]
    pub(crate) fn remove(&mut self, x: &[f64; 4], d: &[f64; 2]) {
        if self.n <= 1 {
            *self = Sums::default();
            return;
        }
        self.n -= 1;
        for (s, v) in self.sum.iter_mut().zip(x) {
            *s -= v;
        }
        self.sin -= d[0];
        self.cos -= d[1];
    }

    /// The mean (`None` for an empty set); theta per `mode` (finishing.md 11.2).
    pub(crate) fn mean(&self, mode: ThetaMode) -> Option<[f64; 4]> {
        if self.n == 0 {
            return None;
        }
        let n = self.n as f64;
        let theta = match mode {
            ThetaMode::Wrapped => 0.5 * self.sin.atan2(self.cos),
            ThetaMode::Plain => self.sum[3] / n,
        };
        Some([self.sum[0] / n, self.sum[1] / n, self.sum[2] / n, theta])
    }
}

/// Two-pass global mean and covariance.
fn global_statistics(x: &[[f64; 4]], doubled: &[[f64; 2]], mode: ThetaMode) -> Global {
    let mut sums = Sums::default();
    for (p, d) in x.iter().zip(doubled) {
        sums.add(p, d);
    }
    let mean = sums.mean(mode).unwrap_or([0.0; 4]);
    let covariance = covariance_about(x.iter(), &mean, mode);
    Global { mean, covariance }
}

/// Population covariance of `points` about `mean` (theta deviation per `mode`).
#[allow(clippy::needless_range_loop)] // symmetric 4 x 4 matrix: indices read best
pub(crate) fn covariance_about<'a>(
    points: impl Iterator<Item = &'a [f64; 4]>,
    mean: &[f64; 4],
    mode: ThetaMode,
) -> [[f64; 4]; 4] {
    let wrapped = mode == ThetaMode::Wrapped;
    let mut m = [[0.0; 4]; 4];
    let mut n = 0usize;
    for p in points {
        let d = delta(p, mean, wrapped);
        for r in 0..4 {
            for c in r..4 {
                m[r][c] += d[r] * d[c];
            }
        }
        n += 1;
    }
    if n > 0 {
        let inv = 1.0 / n as f64;
        for r in 0..4 {
            for c in r..4 {
                m[r][c] *= inv;
                m[c][r] = m[r][c];
            }
        }
    }
    m
}
