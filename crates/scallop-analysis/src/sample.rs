//! Surface sampling: cell-centre grids on parametric patches, one weighted sample
//! per triangle on meshes (finishing.md 4.2-4.4, 9.6).

use rayon::prelude::*;
use scallop_geom::{Point3, Vec3};
use scallop_mesh::TriMesh;
use scallop_surface::{Patch, SurfaceSet};
use serde::{Deserialize, Serialize};

use crate::error::AnalysisError;
use crate::moments::{Moments, add_comoments, comoment_matrix};
use crate::pca::direction_angle_xy;
use crate::tol;

/// The feature vector `x_i = (u_i, v_i, s_i, theta_i)` of one sample (finishing.md
/// 11.1), shared with surface partitioning (clustering).
///
/// Units: `u, v` in `[0, 1]` (fractions of the patch's parameter domain); `slope`
/// `s = arccos(|n_z|)` in `[0, pi/2]` rad; `slope_direction` `theta` in
/// `(-pi/2, pi/2]` rad (a direction modulo pi, see [`Sample::slope_direction`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FeatureVector {
    /// `u` in `[0, 1]`.
    pub u: f64,
    /// `v` in `[0, 1]`.
    pub v: f64,
    /// Tilt `s` (rad).
    pub slope: f64,
    /// Steepest-slope direction `theta` (rad).
    pub slope_direction: f64,
}

impl FeatureVector {
    /// As an array `[u, v, s, theta]`.
    #[must_use]
    pub fn to_array(&self) -> [f64; 4] {
        [self.u, self.v, self.slope, self.slope_direction]
    }
}

/// One surface sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Surface point (mm): the cell-centre point `S(u, v)` or the triangle centroid.
    pub point: Point3,
    /// Unit normal, with one global sign for the whole sample set chosen so that the
    /// (weighted) mean of `n_z` is `>= 0` (finishing.md 4.2).
    pub normal: Vec3,
    /// Surface area represented (mm^2): `|S_u x S_v| du dv` of the cell at its
    /// centre, or the triangle's area.
    pub weight: f64,
    /// Tilt `s = arccos(|n_z|)` in `[0, pi/2]` (rad; 0 horizontal, pi/2 vertical).
    pub slope: f64,
    /// Steepest-slope direction `theta`: the angle from +X of the XY projection
    /// `(n_x, n_y)` of the normal, folded into `(-pi/2, pi/2]` (a direction modulo
    /// pi; equal to `atan(n_y / n_x)`, `pi/2` when `n_x = 0`). 0 when
    /// `|(n_x, n_y)| < tol::HORIZONTAL_XY` (horizontal point, direction undefined).
    pub slope_direction: f64,
    /// `(u, v)` as fractions of the patch's parameter domain (cell centre
    /// `((a + 1/2) / N_u, (b + 1/2) / N_v)`); `None` for mesh samples.
    pub uv: Option<[f64; 2]>,
}

impl Sample {
    /// The feature vector `(u, v, s, theta)`, when `(u, v)` is defined.
    #[must_use]
    pub fn feature(&self) -> Option<FeatureVector> {
        self.uv.map(|[u, v]| FeatureVector { u, v, slope: self.slope, slope_direction: self.slope_direction })
    }

    /// The grid cell `(a, b)` (`a` along u) of a cell-centre sample on an
    /// `N_u x N_v` grid (`grid = [N_u, N_v]`, see [`Samples::grid`]): `floor(u N_u)`,
    /// `floor(v N_v)`; `None` for mesh samples.
    ///
    /// ```
    /// let set = scallop_surface::builtin("rubio").unwrap();
    /// let grid = scallop_analysis::GridOptions { cells_u: 7, cells_v: 5 };
    /// let samples = scallop_analysis::sample_patch(&set.patches()[0], &grid).unwrap();
    /// assert_eq!(samples.samples()[12].grid_cell([7, 5]), Some([2, 2])); // index a * N_v + b
    /// ```
    #[must_use]
    pub fn grid_cell(&self, grid: [usize; 2]) -> Option<[usize; 2]> {
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)] // u in (0, 1): u N in (0, N)
        let cell = |t: f64, n: usize| ((t * n as f64).floor() as usize).min(n.saturating_sub(1));
        self.uv.map(|[u, v]| [cell(u, grid[0]), cell(v, grid[1])])
    }
}

/// How samples are weighted in the PCA covariance (finishing.md 9.6).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PcaWeighting {
    /// Every sample counts 1: the parametric measure of cell-centre sampling, the
    /// thesis's convention and the default for patches (reproduces its PCA values).
    #[default]
    Parametric,
    /// Each sample weighs its area ([`Sample::weight`]): the surface-area measure;
    /// the default for meshes.
    Area,
}

/// Cell-centre sampling grid (finishing.md 4.3). [`Default`]: 80 x 80 (the spec's
/// PCA and clustering mesh).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct GridOptions {
    /// Cells along u (`N_u`).
    pub cells_u: usize,
    /// Cells along v (`N_v`).
    pub cells_v: usize,
}

impl Default for GridOptions {
    fn default() -> Self {
        GridOptions { cells_u: 80, cells_v: 80 }
    }
}

/// A validated set of samples of one surface, ready for [`crate::analyze`].
///
/// Invariants: at least one sample; unit normals with one global orientation;
/// finite values; `spreads` is empty or has one entry per sample.
#[derive(Clone, Debug, PartialEq)]
pub struct Samples {
    samples: Vec<Sample>,
    spreads: Vec<[f64; 6]>,
    grid: Option<[usize; 2]>,
    weighting: PcaWeighting,
    stats: Stats,
}

/// Statistics of a sample set under both weightings, computed once at construction
/// in one fixed-order chunked pass.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Stats {
    /// `[parametric, area]` moments of the points.
    moments: [Moments; 2],
    /// `[parametric, area]` weighted sums of the tilts `s_i`.
    slope_sums: [f64; 2],
    /// `[parametric, area]` weighted sums of `n_z` (before orientation).
    normal_z_sums: [f64; 2],
}

impl PcaWeighting {
    fn index(self) -> usize {
        match self {
            PcaWeighting::Parametric => 0,
            PcaWeighting::Area => 1,
        }
    }
}

impl Samples {
    /// Samples built elsewhere (e.g. a zone of a partition). Normals are
    /// re-normalised and globally re-oriented (mean `n_z >= 0`, weighted by
    /// `weighting`); slopes and directions are recomputed from them.
    ///
    /// # Errors
    /// [`AnalysisError::NoSamples`] when `samples` is empty,
    /// [`AnalysisError::BadSample`] for a non-finite value or a negative weight.
    pub fn from_samples(mut samples: Vec<Sample>, weighting: PcaWeighting) -> Result<Samples, AnalysisError> {
        if samples.is_empty() {
            return Err(AnalysisError::NoSamples);
        }
        let valid = |s: &Sample| {
            s.point.coords.iter().chain(s.normal.iter()).chain(s.uv.iter().flatten()).all(|c| c.is_finite())
                && s.weight.is_finite()
                && s.weight >= 0.0
        };
        if let Some(index) = samples.iter().position(|s| !valid(s)) {
            return Err(AnalysisError::BadSample { index });
        }
        samples.par_iter_mut().for_each(|s| {
            let n = s.normal.norm();
            s.normal = if n > 0.0 && n.is_finite() { s.normal / n } else { Vec3::z() };
            (s.slope, s.slope_direction) = slope_and_direction(&s.normal);
        });
        Ok(Samples::finish(samples, Vec::new(), None, weighting))
    }

    /// Computes the statistics and applies the global normal orientation (mean
    /// `n_z >= 0` under `weighting`, finishing.md 4.2).
    fn finish(
        mut samples: Vec<Sample>,
        spreads: Vec<[f64; 6]>,
        grid: Option<[usize; 2]>,
        weighting: PcaWeighting,
    ) -> Samples {
        let stats = statistics(&samples, &spreads);
        if stats.normal_z_sums[weighting.index()] < 0.0 {
            samples.par_iter_mut().for_each(|s| s.normal = -s.normal);
        }
        Samples { samples, spreads, grid, weighting, stats }
    }

    /// The samples, grid samples in cell order `a * N_v + b` (masked cells skipped).
    #[must_use]
    pub fn samples(&self) -> &[Sample] {
        &self.samples
    }

    /// Number of samples (>= 1).
    #[must_use]
    pub fn len(&self) -> usize {
        self.samples.len()
    }

    /// Always false (a `Samples` is never empty); for API symmetry.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// `[N_u, N_v]` for the sampling of one patch; `None` otherwise.
    #[must_use]
    pub fn grid(&self) -> Option<[usize; 2]> {
        self.grid
    }

    /// Per-sample second central moments `[xx, yy, zz, xy, xz, yz]` per unit weight
    /// (mm^2; mesh samples: the triangle's area distribution about its centroid);
    /// `None` for point samples.
    #[must_use]
    pub fn spreads(&self) -> Option<&[[f64; 6]]> {
        if self.spreads.is_empty() { None } else { Some(&self.spreads) }
    }

    /// The PCA weighting used by [`Samples::moments`] and [`crate::analyze`].
    #[must_use]
    pub fn weighting(&self) -> PcaWeighting {
        self.weighting
    }

    /// The same samples with another PCA weighting.
    #[must_use]
    pub fn with_weighting(mut self, weighting: PcaWeighting) -> Samples {
        self.weighting = weighting;
        self
    }

    /// Feature vectors `(u, v, s, theta)` of every sample (`None` for mesh samples).
    pub fn features(&self) -> impl Iterator<Item = Option<FeatureVector>> + '_ {
        self.samples.iter().map(Sample::feature)
    }

    /// Mean and covariance of the sample points weighted per
    /// [`Samples::weighting`] (mesh samples include their triangles' own spreads).
    /// Computed once at construction: two-pass per fixed chunk of
    /// [`tol::REDUCTION_CHUNK`] samples, chunks merged in order, so the result is
    /// identical for any thread count.
    #[must_use]
    pub fn moments(&self) -> Moments {
        self.stats.moments[self.weighting.index()]
    }

    /// Weighted mean of the sample tilts `E(s_i)` (Eq. 2.15), rad.
    #[must_use]
    pub fn mean_slope(&self) -> f64 {
        let k = self.weighting.index();
        let weight = self.stats.moments[k].weight();
        if weight > 0.0 { self.stats.slope_sums[k] / weight } else { 0.0 }
    }
}

/// The statistics of `samples` (and their optional spreads) under both weightings.
fn statistics(samples: &[Sample], spreads: &[[f64; 6]]) -> Stats {
    let chunk = tol::REDUCTION_CHUNK;
    let partial: Vec<Stats> = samples
        .par_chunks(chunk)
        .enumerate()
        .map(|(c, part)| {
            let spreads = if spreads.is_empty() { None } else { Some(&spreads[c * chunk..c * chunk + part.len()]) };
            chunk_statistics(part, spreads)
        })
        .collect();
    let mut total = Stats { moments: [Moments::new(); 2], slope_sums: [0.0; 2], normal_z_sums: [0.0; 2] };
    for p in &partial {
        for k in 0..2 {
            total.moments[k].merge(&p.moments[k]);
            total.slope_sums[k] += p.slope_sums[k];
            total.normal_z_sums[k] += p.normal_z_sums[k];
        }
    }
    total
}

/// Two-pass statistics of one chunk under both weightings.
fn chunk_statistics(part: &[Sample], spreads: Option<&[[f64; 6]]>) -> Stats {
    // Pass 1: weights, weighted sums of points, tilts and n_z.
    let (mut area, mut sum_parametric, mut sum_area) = (0.0, Vec3::zeros(), Vec3::zeros());
    let (mut slope_sums, mut normal_z_sums) = ([0.0; 2], [0.0; 2]);
    for s in part {
        area += s.weight;
        sum_parametric += s.point.coords;
        sum_area += s.point.coords * s.weight;
        slope_sums[0] += s.slope;
        slope_sums[1] += s.weight * s.slope;
        normal_z_sums[0] += s.normal.z;
        normal_z_sums[1] += s.weight * s.normal.z;
    }
    #[allow(clippy::cast_precision_loss)] // chunk length <= REDUCTION_CHUNK
    let count = part.len() as f64;
    let means = [sum_parametric / count, if area > 0.0 { sum_area / area } else { sum_parametric / count }];
    // Pass 2 (chunk still in cache): centred co-moments [xx, yy, zz, xy, xz, yz].
    let mut comoments = [[0.0; 6]; 2];
    for (i, s) in part.iter().enumerate() {
        let own = spreads.map(|sp| &sp[i]);
        for (k, weight) in [(0, 1.0), (1, s.weight)] {
            add_comoments(&mut comoments[k], weight, &(s.point.coords - means[k]), own);
        }
    }
    let moments = [(0, count), (1, area)].map(|(k, weight)| {
        Moments::from_parts(part.len(), weight, &Point3::from(means[k]), &comoment_matrix(&comoments[k]))
    });
    Stats { moments, slope_sums, normal_z_sums }
}

/// Tilt `s = arccos(|n_z|)` (computed as `atan(|(n_x, n_y)| / |n_z|)`) and direction
/// `theta` of a unit normal (finishing.md 4.4).
///
/// ```
/// use scallop_geom::Vec3;
/// let (s, theta) = scallop_analysis::slope_and_direction(&Vec3::new(0.5, 0.5, 0.5f64.sqrt()));
/// assert!((s.to_degrees() - 45.0).abs() < 1e-12 && (theta.to_degrees() - 45.0).abs() < 1e-12);
/// ```
#[must_use]
pub fn slope_and_direction(normal: &Vec3) -> (f64, f64) {
    // arccos(|n_z|) = atan(|(n_x, n_y)| / |n_z|) for a unit normal; the atan form is
    // better conditioned near s = 0 and cheaper (pi/2 exactly when n_z = 0).
    let horizontal = (normal.x * normal.x + normal.y * normal.y).sqrt();
    let slope = if horizontal > 0.0 { (horizontal / normal.z.abs()).atan() } else { 0.0 };
    (slope, direction_angle_xy(normal.x, normal.y))
}

/// Samples one patch at the centres of a uniform `N_u x N_v` grid of its parameter
/// domain (finishing.md 4.3): cell `(a, b)` at `u = (a + 1/2)/N_u`,
/// `v = (b + 1/2)/N_v` (fractions of the domain). Per sample: the point, the unit
/// normal `S_u x S_v / |S_u x S_v|` (with the patch's own fallback at degenerate
/// points, [`Patch::normal`]), the cell area, `s` and `theta`. One global normal sign
/// makes the mean `n_z >= 0`. PCA weighting: [`PcaWeighting::Parametric`].
///
/// Bezier patches (rational or not) are evaluated with per-row and per-column
/// Bernstein tables (exact; no per-cell basis evaluation); NURBS patches call
/// [`Patch::derivatives`]. Cells are evaluated in parallel and collected by index:
/// the result does not depend on the thread count.
///
/// ```
/// let set = scallop_surface::builtin("choi").unwrap();
/// let samples = scallop_analysis::sample_patch(&set.patches()[0], &Default::default()).unwrap();
/// assert_eq!(samples.len(), 6400);
/// let f = samples.samples()[0].feature().unwrap();
/// assert_eq!((f.u, f.v), (0.5 / 80.0, 0.5 / 80.0));
/// ```
///
/// # Errors
/// [`AnalysisError::EmptyGrid`] when a dimension is 0.
pub fn sample_patch(patch: &Patch, grid: &GridOptions) -> Result<Samples, AnalysisError> {
    finish_grid(grid, grid_samples(patch, grid, None)?)
}

/// [`sample_patch`] keeping only the cells `(a, b)` for which `mask(a, b)` is true
/// (a trimmed or masked domain, finishing.md 4.1).
///
/// # Errors
/// [`AnalysisError::EmptyGrid`] when a dimension is 0, [`AnalysisError::NoSamples`]
/// when the mask keeps no cell.
pub fn sample_patch_masked(
    patch: &Patch,
    grid: &GridOptions,
    mask: impl Fn(usize, usize) -> bool + Sync,
) -> Result<Samples, AnalysisError> {
    finish_grid(grid, grid_samples(patch, grid, Some(&mask))?)
}

fn finish_grid(grid: &GridOptions, samples: Vec<Sample>) -> Result<Samples, AnalysisError> {
    if samples.is_empty() {
        return Err(AnalysisError::NoSamples);
    }
    Ok(Samples::finish(samples, Vec::new(), Some([grid.cells_u, grid.cells_v]), PcaWeighting::Parametric))
}

/// Samples every patch of a set with the same grid and concatenates them (patch
/// order, then cell order); one global normal orientation over all samples.
/// `uv` is per patch; [`Samples::grid`] is `None` unless the set has one patch.
///
/// # Errors
/// [`AnalysisError::EmptyGrid`] when a dimension is 0.
pub fn sample_surface_set(set: &SurfaceSet, grid: &GridOptions) -> Result<Samples, AnalysisError> {
    let mut samples = Vec::new();
    for patch in set.patches() {
        let more = grid_samples(patch, grid, None)?;
        // The first patch's samples are moved, not copied (a 1000 x 1000 grid is ~100 MB).
        if samples.is_empty() { samples = more } else { samples.extend(more) }
    }
    if samples.is_empty() {
        return Err(AnalysisError::NoSamples);
    }
    let single = set.patches().len() == 1;
    Ok(Samples::finish(samples, Vec::new(), single.then_some([grid.cells_u, grid.cells_v]), PcaWeighting::Parametric))
}

/// Samples a mesh with one sample per triangle: the centroid `g`, the facet normal,
/// the area as weight, and the triangle's exact second central moment
/// `(1/12) sum_k (v_k - g)(v_k - g)^T` as its spread. With the default
/// [`PcaWeighting::Area`] the PCA covariance is then **exactly** that of the
/// triangulated surface under the area measure (no sampling error, a single triangle
/// included). Deterministic (no random sampling); no `(u, v)`. Normal orientation:
/// one global sign making the area-weighted mean `n_z >= 0`.
///
/// ```
/// use scallop_geom::Point3;
/// let p = |x, y| Point3::new(x, y, 0.0);
/// let (mesh, _) = scallop_mesh::TriMesh::from_soup(&[[p(0., 0.), p(4., 0.), p(4., 2.)], [p(0., 0.), p(4., 2.), p(0., 2.)]]).unwrap();
/// let samples = scallop_analysis::sample_mesh(&mesh);
/// let pca = scallop_analysis::Pca::from_moments(&samples.moments());
/// assert!((pca.eigenvalues[0] - 16.0 / 12.0).abs() < 1e-12); // w^2 / 12, exactly
/// ```
#[must_use]
pub fn sample_mesh(mesh: &TriMesh) -> Samples {
    let (samples, spreads): (Vec<Sample>, Vec<[f64; 6]>) = (0..mesh.triangles().len())
        .into_par_iter()
        .map(|i| {
            let [a, b, c] = mesh.triangle(i);
            let centroid = Point3::from((a.coords + b.coords + c.coords) / 3.0);
            let cross = (b - a).cross(&(c - a));
            let norm = cross.norm();
            let normal = if norm > 0.0 { cross / norm } else { Vec3::z() };
            let (slope, slope_direction) = slope_and_direction(&normal);
            let mut spread = [0.0; 6];
            for v in [a, b, c] {
                let d = v - centroid;
                let terms = [d.x * d.x, d.y * d.y, d.z * d.z, d.x * d.y, d.x * d.z, d.y * d.z];
                for (s, t) in spread.iter_mut().zip(terms) {
                    *s += t / 12.0;
                }
            }
            let sample = Sample { point: centroid, normal, weight: 0.5 * norm, slope, slope_direction, uv: None };
            (sample, spread)
        })
        .unzip();
    Samples::finish(samples, spreads, None, PcaWeighting::Area)
}

/// Evaluates the kept cells of a grid, in cell order, in parallel.
fn grid_samples(
    patch: &Patch,
    grid: &GridOptions,
    mask: Option<&(dyn Fn(usize, usize) -> bool + Sync)>,
) -> Result<Vec<Sample>, AnalysisError> {
    let (nu, nv) = (grid.cells_u, grid.cells_v);
    if nu == 0 || nv == 0 {
        return Err(AnalysisError::EmptyGrid { cells_u: nu, cells_v: nv });
    }
    let cells = nu as u128 * nv as u128;
    if cells > crate::tol::MAX_GRID_CELLS as u128 {
        return Err(AnalysisError::TooManyCells { cells_u: nu, cells_v: nv, cells, max: crate::tol::MAX_GRID_CELLS });
    }
    let fractions = |n: usize| -> Vec<f64> { (0..n).map(|a| (a as f64 + 0.5) / n as f64).collect() };
    let (fu, fv) = (fractions(nu), fractions(nv));
    let domain = patch.domain();
    let cell_area = (domain.u[1] - domain.u[0]) / nu as f64 * ((domain.v[1] - domain.v[0]) / nv as f64);
    let tables = patch.is_bezier().then(|| BezierTables::new(patch, &fu, &fv));
    let split = split_index(nv);
    let evaluate_cell = |index: usize| -> Sample {
        let (a, b) = split(index);
        let (u, v) = domain.lerp(fu[a], fv[b]);
        let (point, su, sv) = match &tables {
            Some(t) => t.evaluate(a, b),
            None => {
                let d = patch.derivatives(u, v);
                (d.point, d.du, d.dv)
            }
        };
        let cross = su.cross(&sv);
        let norm = cross.norm();
        let normal = if norm > scallop_surface::tol::NORMAL_DEGENERATE_REL * (su.norm_squared() + sv.norm_squared()) {
            cross * norm.recip()
        } else {
            patch.normal(u, v)
        };
        let (slope, slope_direction) = slope_and_direction(&normal);
        Sample { point, normal, weight: norm * cell_area, slope, slope_direction, uv: Some([fu[a], fv[b]]) }
    };
    let total = nu * nv;
    let mut samples = Vec::new();
    match mask {
        None => (0..total).into_par_iter().map(evaluate_cell).collect_into_vec(&mut samples),
        Some(mask) => {
            samples = (0..total)
                .into_par_iter()
                .filter(|&i| {
                    let (a, b) = split(i);
                    mask(a, b)
                })
                .map(evaluate_cell)
                .collect();
        }
    }
    Ok(samples)
}

/// `index -> (index / n, index % n)` without an integer division per call:
/// `a = floor((index + 1/2) / n)` in floating point is exact because
/// `(index + 1/2)/n` is at least `1/(2n)` away from an integer and the rounding error
/// is below `2^-52 index/n` (far smaller for any grid that fits in memory).
fn split_index(n: usize) -> impl Fn(usize) -> (usize, usize) + Sync {
    let inverse = 1.0 / n as f64;
    move |index| {
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)] // non-negative, < index
        let a = ((index as f64 + 0.5) * inverse) as usize;
        (a, index - a * n)
    }
}

/// Bernstein tables of a (rational) Bezier patch on a fixed grid: per grid row `a`,
/// the homogeneous control columns contracted along u,
/// `Q_j(a) = sum_i B_i(u_a) w_ij P_ij` and `Q'_j(a) = sum_i B_i'(u_a) w_ij P_ij`,
/// and per grid column `b` the values and derivatives `B_j(v_b)`, `B_j'(v_b)`. Then
/// `A = sum_j B_j Q_j`, `A_u = sum_j B_j Q'_j`, `A_v = sum_j B_j' Q_j` and the
/// quotient rule gives `S = A / W`, `S_u = (A_u - W_u S) / W`, `S_v = (A_v - W_v S) / W`.
struct BezierTables {
    columns: usize,
    rational: bool,
    /// `rows[a * columns + j] = Q_j(a)` (homogeneous `[wx, wy, wz, w]`).
    rows: Vec<[f64; 4]>,
    /// `rows_du[a * columns + j] = Q'_j(a)`.
    rows_du: Vec<[f64; 4]>,
    /// `basis_v[b * columns + j] = B_j(v_b)`.
    basis_v: Vec<f64>,
    /// `basis_dv[b * columns + j] = B_j'(v_b)`.
    basis_dv: Vec<f64>,
}

impl BezierTables {
    fn new(patch: &Patch, fu: &[f64], fv: &[f64]) -> BezierTables {
        let [p, q] = patch.degree();
        let columns = q + 1;
        let weights = patch.weights();
        let control = patch.control_points();
        let homogeneous = |i: usize, j: usize| -> [f64; 4] {
            let k = i * columns + j;
            let w = weights.map_or(1.0, |w| w[k]);
            let c = control[k];
            [c.x * w, c.y * w, c.z * w, w]
        };
        let mut rows = Vec::with_capacity(fu.len() * columns);
        let mut rows_du = Vec::with_capacity(fu.len() * columns);
        for &u in fu {
            let (bu, dbu) = bernstein(p, u);
            for j in 0..columns {
                let (mut value, mut derivative) = ([0.0; 4], [0.0; 4]);
                for i in 0..=p {
                    let h = homogeneous(i, j);
                    for k in 0..4 {
                        value[k] += bu[i] * h[k];
                        derivative[k] += dbu[i] * h[k];
                    }
                }
                rows.push(value);
                rows_du.push(derivative);
            }
        }
        let mut basis_v = Vec::with_capacity(fv.len() * columns);
        let mut basis_dv = Vec::with_capacity(fv.len() * columns);
        for &v in fv {
            let (bv, dbv) = bernstein(q, v);
            basis_v.extend(bv);
            basis_dv.extend(dbv);
        }
        BezierTables { columns, rational: weights.is_some(), rows, rows_du, basis_v, basis_dv }
    }

    fn evaluate(&self, a: usize, b: usize) -> (Point3, Vec3, Vec3) {
        // Fixed column counts (degree 1 to 3 in v) get fully unrolled loops.
        let (s, su, sv) = match self.columns {
            2 => self.contract::<2>(a, b),
            3 => self.contract::<3>(a, b),
            4 => self.contract::<4>(a, b),
            _ => self.contract_any(a, b),
        };
        let (point, du, dv) =
            (Vec3::new(s[0], s[1], s[2]), Vec3::new(su[0], su[1], su[2]), Vec3::new(sv[0], sv[1], sv[2]));
        if !self.rational {
            // W = 1 and W_u = W_v = 0 exactly (partition of unity).
            return (Point3::from(point), du, dv);
        }
        let w = s[3];
        let point = point / w;
        (Point3::from(point), (du - point * su[3]) / w, (dv - point * sv[3]) / w)
    }

    /// Homogeneous `A`, `A_u`, `A_v` at cell `(a, b)` for `C` columns.
    fn contract<const C: usize>(&self, a: usize, b: usize) -> ([f64; 4], [f64; 4], [f64; 4]) {
        let q: &[[f64; 4]; C] = self.rows[a * C..(a + 1) * C].try_into().unwrap_or(&[[0.0; 4]; C]);
        let qu: &[[f64; 4]; C] = self.rows_du[a * C..(a + 1) * C].try_into().unwrap_or(&[[0.0; 4]; C]);
        let bv: &[f64; C] = self.basis_v[b * C..(b + 1) * C].try_into().unwrap_or(&[0.0; C]);
        let dbv: &[f64; C] = self.basis_dv[b * C..(b + 1) * C].try_into().unwrap_or(&[0.0; C]);
        combine(q, qu, bv, dbv)
    }

    /// [`BezierTables::contract`] for any column count.
    fn contract_any(&self, a: usize, b: usize) -> ([f64; 4], [f64; 4], [f64; 4]) {
        let c = self.columns;
        let (q, qu) = (&self.rows[a * c..(a + 1) * c], &self.rows_du[a * c..(a + 1) * c]);
        let (bv, dbv) = (&self.basis_v[b * c..(b + 1) * c], &self.basis_dv[b * c..(b + 1) * c]);
        combine(q, qu, bv, dbv)
    }
}

/// `sum_j bv_j q_j`, `sum_j bv_j qu_j` and `sum_j dbv_j q_j` (homogeneous `A`,
/// `A_u`, `A_v` from a cell's rows and column basis), summed in `j` order.
/// Inlined, so that the fixed column counts of [`BezierTables::contract`] unroll.
#[inline(always)]
fn combine(q: &[[f64; 4]], qu: &[[f64; 4]], bv: &[f64], dbv: &[f64]) -> ([f64; 4], [f64; 4], [f64; 4]) {
    let (mut s, mut su, mut sv) = ([0.0; 4], [0.0; 4], [0.0; 4]);
    for (((b, db), qj), quj) in bv.iter().zip(dbv).zip(q).zip(qu) {
        for k in 0..4 {
            s[k] += b * qj[k];
            su[k] += b * quj[k];
            sv[k] += db * qj[k];
        }
    }
    (s, su, sv)
}

/// Bernstein polynomials of degree `n >= 1` at `t` and their derivatives
/// (`B_i' = n (B_{i-1}^{n-1} - B_i^{n-1})`), by the stable triangle recurrence.
fn bernstein(n: usize, t: f64) -> (Vec<f64>, Vec<f64>) {
    let all = |degree: usize| -> Vec<f64> {
        let mut b = vec![0.0; degree + 1];
        b[0] = 1.0;
        for j in 1..=degree {
            let mut saved = 0.0;
            for value in b.iter_mut().take(j) {
                let temp = *value;
                *value = saved + (1.0 - t) * temp;
                saved = t * temp;
            }
            b[j] = saved;
        }
        b
    };
    let lower = all(n - 1);
    let at = |k: isize| -> f64 { if k < 0 || k as usize >= lower.len() { 0.0 } else { lower[k as usize] } };
    let values = all(n);
    let derivatives = (0..=n).map(|i| n as f64 * (at(i as isize - 1) - at(i as isize))).collect();
    (values, derivatives)
}
