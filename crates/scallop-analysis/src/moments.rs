//! Weighted mean and covariance of 3D points, batch and incremental
//! (finishing.md 9.1, 11.5).
//!
//! The statistics are kept as the total weight `W`, the mean `E` and the co-moment
//! `M = sum_i w_i (x_i - E)(x_i - E)^T`, so that the population covariance (1/n, the
//! spec's convention) is `Sigma = M / W`. Adding and removing a point use the
//! numerically stable (Welford) form of 11.5, written symmetrically:
//!
//! ```text
//! add x (weight w):     d = x - E;  W' = W + w;  E' = E + (w / W') d;  M' = M + w (W / W') d d^T
//! remove x (weight w):  d = x - E;  W' = W - w;  E' = E - (w / W') d;  M' = M - w (W / W') d d^T
//! ```
//!
//! (`x - E' = (W / W') d` for an add, so `(x - E)(x - E')^T` of the spec is the
//! symmetric `(W / W') d d^T`; likewise for a removal with `x - E = (W'/W)(x - E')`.)
//! Merging two sets (Chan et al.) is `E = E_a + (W_b / W) delta`,
//! `M = M_a + M_b + (W_a W_b / W) delta delta^T`, `delta = E_b - E_a`; batch
//! statistics merge fixed-size chunks in index order, so results do not depend on
//! the thread count.

use scallop_geom::nalgebra::Matrix3;
use scallop_geom::{Point3, Vec3};

/// Weighted first and second moments of a set of 3D points (see the module docs).
///
/// ```
/// use scallop_analysis::Moments;
/// use scallop_geom::Point3;
/// let mut m = Moments::new();
/// for x in [0.0, 1.0, 2.0, 3.0] {
///     m.add(&Point3::new(x, 0.0, 0.0), 1.0);
/// }
/// m.remove(&Point3::new(3.0, 0.0, 0.0), 1.0);
/// assert!((m.covariance()[(0, 0)] - 2.0 / 3.0).abs() < 1e-15); // Var{0,1,2}, 1/n
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Moments {
    count: usize,
    weight: f64,
    mean: Vec3,
    comoment: Matrix3<f64>,
}

impl Default for Moments {
    fn default() -> Self {
        Self::new()
    }
}

impl Moments {
    /// The empty set.
    #[must_use]
    pub fn new() -> Moments {
        Moments { count: 0, weight: 0.0, mean: Vec3::zeros(), comoment: Matrix3::zeros() }
    }

    /// Statistics from a mean, a covariance and a total weight (`M = W Sigma`);
    /// `count` is the number of points represented.
    #[must_use]
    pub fn from_covariance(count: usize, weight: f64, mean: &Point3, covariance: &Matrix3<f64>) -> Moments {
        Moments { count, weight, mean: mean.coords, comoment: covariance * weight }
    }

    /// Batch statistics of unit-weight points (two-pass, centred; never `E(x^2) - E(x)^2`).
    ///
    /// ```
    /// use scallop_analysis::Moments;
    /// use scallop_geom::Point3;
    /// let m = Moments::of_points(&[Point3::new(1e6, 0.0, 0.0), Point3::new(1e6 + 2.0, 0.0, 0.0)]);
    /// assert_eq!(m.covariance()[(0, 0)], 1.0);
    /// ```
    #[must_use]
    pub fn of_points(points: &[Point3]) -> Moments {
        Self::of_weighted(points.len(), |i| (points[i], 1.0, None))
    }

    /// Batch statistics of `n` items given by `item(i) = (point, weight, spread)`:
    /// chunks of [`crate::tol::REDUCTION_CHUNK`] items are reduced two-pass, then merged
    /// in index order. `spread`, when given, is the item's own second central moment
    /// per unit weight `[xx, yy, zz, xy, xz, yz]` (a triangle's area distribution, for
    /// instance) and is added as `w * spread` to the co-moment.
    pub(crate) fn of_weighted(n: usize, item: impl Fn(usize) -> (Point3, f64, Option<[f64; 6]>) + Sync) -> Moments {
        use rayon::prelude::*;
        let chunk = crate::tol::REDUCTION_CHUNK;
        let chunks = n.div_ceil(chunk);
        let partial: Vec<Moments> = (0..chunks)
            .into_par_iter()
            .map(|c| {
                let range = c * chunk..((c + 1) * chunk).min(n);
                chunk_moments(range, &item)
            })
            .collect();
        let mut total = Moments::new();
        for p in &partial {
            total.merge(p);
        }
        total
    }

    /// Statistics from their parts: `count` points of total weight `weight`, mean
    /// `mean` and co-moment `comoment` (`M = W Sigma`).
    #[must_use]
    pub fn from_parts(count: usize, weight: f64, mean: &Point3, comoment: &Matrix3<f64>) -> Moments {
        Moments { count, weight, mean: mean.coords, comoment: *comoment }
    }

    /// Number of points in the set.
    #[must_use]
    pub fn count(&self) -> usize {
        self.count
    }

    /// Total weight `W` (the number of points for unit weights).
    #[must_use]
    pub fn weight(&self) -> f64 {
        self.weight
    }

    /// Weighted mean `E` (the origin for an empty set).
    #[must_use]
    pub fn mean(&self) -> Point3 {
        Point3::from(self.mean)
    }

    /// Co-moment `M = W Sigma`.
    #[must_use]
    pub fn comoment(&self) -> Matrix3<f64> {
        self.comoment
    }

    /// Population covariance `Sigma = M / W` (zero for an empty set).
    #[must_use]
    pub fn covariance(&self) -> Matrix3<f64> {
        if self.count == 0 || self.weight <= 0.0 { Matrix3::zeros() } else { self.comoment / self.weight }
    }

    /// Adds point `x` with weight `weight >= 0` (stable form, module docs). While the
    /// total weight is 0 the mean and covariance stay 0.
    pub fn add(&mut self, x: &Point3, weight: f64) {
        let d = x.coords - self.mean;
        let total = self.weight + weight;
        if total <= 0.0 {
            // Only zero weights so far: no mean is defined yet; count the point.
            self.count += 1;
            return;
        }
        self.mean += d * (weight / total);
        let scale = weight * (self.weight / total);
        add_outer(&mut self.comoment, &d, scale);
        self.weight = total;
        self.count += 1;
    }

    /// Removes a point `x` of weight `weight` that was added before (stable form).
    /// Removing the last point gives exactly the empty set.
    pub fn remove(&mut self, x: &Point3, weight: f64) {
        if self.count <= 1 {
            *self = Moments::new();
            return;
        }
        let d = x.coords - self.mean;
        let total = self.weight - weight;
        if total <= 0.0 {
            // The remaining points weigh nothing: statistics of an empty measure.
            *self = Moments { count: self.count - 1, ..Moments::new() };
            return;
        }
        self.mean -= d * (weight / total);
        let scale = weight * (self.weight / total);
        add_outer(&mut self.comoment, &d, -scale);
        self.weight = total;
        self.count -= 1;
    }

    /// Adds a point that carries its own second central moment `spread` per unit
    /// weight (`[xx, yy, zz, xy, xz, yz]`, e.g. a triangle's area distribution).
    pub fn add_with_spread(&mut self, x: &Point3, weight: f64, spread: &[f64; 6]) {
        self.add(x, weight);
        add_spread(&mut self.comoment, spread, weight);
    }

    /// Removes a point added by [`Moments::add_with_spread`].
    pub fn remove_with_spread(&mut self, x: &Point3, weight: f64, spread: &[f64; 6]) {
        let last = self.count <= 1;
        self.remove(x, weight);
        if !last {
            add_spread(&mut self.comoment, spread, -weight);
        }
    }

    /// Merges another set into this one (parallel-axis / Chan formula).
    pub fn merge(&mut self, other: &Moments) {
        if other.count == 0 {
            return;
        }
        if self.count == 0 || self.weight <= 0.0 {
            let count = self.count;
            *self = *other;
            self.count += count;
            return;
        }
        if other.weight <= 0.0 {
            self.count += other.count;
            return;
        }
        let total = self.weight + other.weight;
        let delta = other.mean - self.mean;
        self.mean += delta * (other.weight / total);
        self.comoment += other.comoment;
        add_outer(&mut self.comoment, &delta, self.weight * other.weight / total);
        self.weight = total;
        self.count += other.count;
    }
}

/// `m += scale * d d^T`, computed on the upper triangle and mirrored (exactly symmetric).
fn add_outer(m: &mut Matrix3<f64>, d: &Vec3, scale: f64) {
    for r in 0..3 {
        for c in r..3 {
            let v = m[(r, c)] + scale * d[r] * d[c];
            m[(r, c)] = v;
            m[(c, r)] = v;
        }
    }
}

/// `m += weight * spread` with `spread = [xx, yy, zz, xy, xz, yz]`.
fn add_spread(m: &mut Matrix3<f64>, spread: &[f64; 6], weight: f64) {
    let [xx, yy, zz, xy, xz, yz] = spread.map(|s| s * weight);
    m[(0, 0)] += xx;
    m[(1, 1)] += yy;
    m[(2, 2)] += zz;
    for (r, c, v) in [(0, 1, xy), (0, 2, xz), (1, 2, yz)] {
        m[(r, c)] += v;
        m[(c, r)] += v;
    }
}

/// Two-pass statistics of one chunk.
fn chunk_moments(range: std::ops::Range<usize>, item: &impl Fn(usize) -> (Point3, f64, Option<[f64; 6]>)) -> Moments {
    let mut weight = 0.0;
    let mut sum = Vec3::zeros();
    for i in range.clone() {
        let (p, w, _) = item(i);
        weight += w;
        sum += p.coords * w;
    }
    if range.is_empty() || weight <= 0.0 {
        return Moments::new();
    }
    let mean = sum / weight;
    let mut s = [0.0; 6];
    for i in range.clone() {
        let (p, w, spread) = item(i);
        add_comoments(&mut s, w, &(p.coords - mean), spread.as_ref());
    }
    Moments { count: range.len(), weight, mean, comoment: comoment_matrix(&s) }
}

/// Adds `w d d^T` (and `w spread`, a point's own second moments) to centred
/// co-moments kept as `[xx, yy, zz, xy, xz, yz]`.
pub(crate) fn add_comoments(s: &mut [f64; 6], w: f64, d: &Vec3, spread: Option<&[f64; 6]>) {
    s[0] += w * d.x * d.x;
    s[1] += w * d.y * d.y;
    s[2] += w * d.z * d.z;
    s[3] += w * d.x * d.y;
    s[4] += w * d.x * d.z;
    s[5] += w * d.y * d.z;
    if let Some(spread) = spread {
        for (acc, v) in s.iter_mut().zip(spread) {
            *acc += w * v;
        }
    }
}

/// The symmetric matrix of co-moments kept as `[xx, yy, zz, xy, xz, yz]`.
pub(crate) fn comoment_matrix(s: &[f64; 6]) -> Matrix3<f64> {
    Matrix3::new(s[0], s[3], s[4], s[3], s[1], s[5], s[4], s[5], s[2])
}
