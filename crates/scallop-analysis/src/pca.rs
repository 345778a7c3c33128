//! PCA approximation of a surface by a plane rectangle (finishing.md 9, Annex B).

use std::f64::consts::{FRAC_PI_2, PI};

use scallop_geom::nalgebra::{Matrix3, SymmetricEigen};
use scallop_geom::{Point3, Vec3};

use crate::moments::Moments;
use crate::tol;

/// The PCA of a set of sample points: eigen-decomposition of their 3x3 covariance.
///
/// Canonical form (finishing.md 9.1 \[DECISION\]), so that results are deterministic:
/// eigenvalues sorted `lambda_I >= lambda_II >= lambda_III >= 0` (rounding negatives
/// clamped to 0); `S_I` unit with its largest-magnitude component positive (first
/// such component on ties); `S_III = S_I x S_II`; if `S_III . Z < 0`, `S_II` and
/// `S_III` are flipped (right-handed basis, upward normal). When
/// `|S_III . Z| <= tol::PCA_VERTICAL_NZ` (vertical plane) they are flipped instead so
/// that the largest-magnitude component of `S_III` is positive.
///
/// ```
/// use scallop_analysis::{Moments, Pca};
/// use scallop_geom::Point3;
/// // Four corners of a 4 x 2 horizontal rectangle.
/// let m = Moments::of_points(&[
///     Point3::new(0.0, 0.0, 0.0), Point3::new(4.0, 0.0, 0.0),
///     Point3::new(0.0, 2.0, 0.0), Point3::new(4.0, 2.0, 0.0),
/// ]);
/// let pca = Pca::from_moments(&m);
/// assert_eq!(pca.eigenvalues, [4.0, 1.0, 0.0]);
/// assert_eq!(pca.shape_factor(), 2.0);
/// assert_eq!(pca.slope(), 0.0);
/// assert_eq!(pca.axes[2], scallop_geom::Vec3::z());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pca {
    /// Weighted mean `E` of the samples (mm): the centre of the PCA rectangle.
    pub mean: Point3,
    /// `[lambda_I, lambda_II, lambda_III]` (mm^2), decreasing, `>= 0`.
    pub eigenvalues: [f64; 3],
    /// `[S_I, S_II, S_III]`: unit eigenvectors, a right-handed orthonormal basis;
    /// `S_I` is the principal direction, `S_III` the PCA normal.
    pub axes: [Vec3; 3],
}

/// The angle of the XY projection `(x, y)` of a direction, from X, folded into
/// `(-pi/2, pi/2]` (a direction modulo pi); 0 when the projection is shorter than
/// [`tol::HORIZONTAL_XY`] (finishing.md 4.4).
///
/// ```
/// use std::f64::consts::FRAC_PI_2;
/// use scallop_analysis::direction_angle_xy;
/// assert_eq!(direction_angle_xy(0.0, -1.0), FRAC_PI_2);
/// assert_eq!(direction_angle_xy(-1.0, 0.0), 0.0);
/// assert_eq!(direction_angle_xy(0.0, 0.0), 0.0);
/// ```
#[must_use]
pub fn direction_angle_xy(x: f64, y: f64) -> f64 {
    if x * x + y * y < tol::HORIZONTAL_XY * tol::HORIZONTAL_XY {
        return 0.0;
    }
    // atan(y/x) is already the angle modulo pi in (-pi/2, pi/2), and +-pi/2 when x = 0
    // (y/x = +-inf); fold -pi/2 to pi/2 and -0 to +0.
    let t = (y / x).atan();
    if t <= -FRAC_PI_2 { t + PI } else { t + 0.0 }
}

impl Pca {
    /// PCA of batch or incremental statistics.
    #[must_use]
    pub fn from_moments(moments: &Moments) -> Pca {
        Pca::from_covariance(&moments.mean(), &moments.covariance())
    }

    /// PCA of a mean and a symmetric covariance matrix (finishing.md 9.1).
    #[must_use]
    pub fn from_covariance(mean: &Point3, covariance: &Matrix3<f64>) -> Pca {
        let eigen = SymmetricEigen::new(*covariance);
        let mut order = [0usize, 1, 2];
        order.sort_by(|&a, &b| eigen.eigenvalues[b].total_cmp(&eigen.eigenvalues[a]));
        let eigenvalues = order.map(|k| eigen.eigenvalues[k].max(0.0));
        let column = |k: usize| -> Vec3 {
            let c: Vec3 = eigen.eigenvectors.column(k).into_owned();
            let n = c.norm();
            if n > 0.0 && n.is_finite() { c / n } else { Vec3::zeros() }
        };
        let (mut first, mut second) = (column(order[0]), column(order[1]));
        if first == Vec3::zeros() || second == Vec3::zeros() {
            // Unreachable for finite input (nalgebra returns an orthonormal basis);
            // keep a defined answer anyway.
            first = Vec3::x();
            second = Vec3::y();
        }
        if first[largest_component(&first)] < 0.0 {
            first = -first;
        }
        // Orthogonalise S_II against S_I (removes rounding), then S_III = S_I x S_II.
        second -= first * first.dot(&second);
        second = second.normalize();
        let mut third = first.cross(&second);
        let flip =
            if third.z.abs() <= tol::PCA_VERTICAL_NZ { third[largest_component(&third)] < 0.0 } else { third.z < 0.0 };
        if flip {
            second = -second;
            third = -third;
        }
        Pca { mean: *mean, eigenvalues, axes: [first, second, third] }
    }

    /// Shape factor `mu = sqrt(lambda_I / lambda_II) >= 1` (Eq. 2.13); `+inf` when
    /// `lambda_II = 0 < lambda_I` (points on a line), 1 when both are 0 (one point).
    #[must_use]
    pub fn shape_factor(&self) -> f64 {
        let [l1, l2, _] = self.eigenvalues;
        if l2 > 0.0 {
            (l1 / l2).sqrt()
        } else if l1 > 0.0 {
            f64::INFINITY
        } else {
            1.0
        }
    }

    /// Size `chi = 12 sqrt(lambda_I lambda_II)` (mm^2, Eq. 2.14): the area of the
    /// equivalent rectangle.
    #[must_use]
    pub fn size(&self) -> f64 {
        12.0 * (self.eigenvalues[0] * self.eigenvalues[1]).sqrt()
    }

    /// Width `w = sqrt(12 lambda_I)` (mm) of the equivalent rectangle, along `S_I`.
    #[must_use]
    pub fn width(&self) -> f64 {
        (12.0 * self.eigenvalues[0]).sqrt()
    }

    /// Height `h = sqrt(12 lambda_II)` (mm) of the equivalent rectangle, along `S_II`.
    #[must_use]
    pub fn height(&self) -> f64 {
        (12.0 * self.eigenvalues[1]).sqrt()
    }

    /// PCA slope `s~ = arccos(|S_III . Z|)` in `[0, pi/2]` (finishing.md 9.4
    /// \[CORR\]: the tilt of the PCA plane, not the printed Eq. 2.16).
    #[must_use]
    pub fn slope(&self) -> f64 {
        self.axes[2].z.abs().min(1.0).acos()
    }

    /// Steepest-slope direction of the PCA plane: the angle from X of the XY
    /// projection of `S_III`, in `(-pi/2, pi/2]`; 0 for a horizontal plane
    /// (undefined there, see [`direction_angle_xy`]).
    #[must_use]
    pub fn slope_direction(&self) -> f64 {
        direction_angle_xy(self.axes[2].x, self.axes[2].y)
    }

    /// Principal direction: the angle from X of the XY projection of `S_I`, in
    /// `(-pi/2, pi/2]`. When `S_I` is vertical (no XY projection) every vertical
    /// plane contains it; the answer is then the slope direction (the vertical planes
    /// across the PCA plane, which cut it along `S_I`).
    #[must_use]
    pub fn principal_direction(&self) -> f64 {
        let s1 = self.axes[0];
        if s1.x.hypot(s1.y) < tol::HORIZONTAL_XY { self.slope_direction() } else { direction_angle_xy(s1.x, s1.y) }
    }

    /// Whether the samples are degenerate (on a line or at a point), relative to the
    /// coordinate scale `scale` (mm, e.g. the largest |coordinate|):
    /// `lambda_II <= DEGENERATE_EIGEN_REL lambda_I` or
    /// `lambda_I <= DEGENERATE_EIGEN_REL scale^2` (see [`tol::DEGENERATE_EIGEN_REL`]).
    #[must_use]
    pub fn is_degenerate(&self, scale: f64) -> bool {
        let [l1, l2, _] = self.eigenvalues;
        l1 <= tol::DEGENERATE_EIGEN_REL * scale * scale || l2 <= tol::DEGENERATE_EIGEN_REL * l1
    }
}

/// Index of the largest |component| (first on ties).
fn largest_component(v: &Vec3) -> usize {
    let mut best = 0;
    for k in 1..3 {
        if v[k].abs() > v[best].abs() {
            best = k;
        }
    }
    best
}
