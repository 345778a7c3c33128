//! Top eigenpair of a symmetric 3x3 matrix, closed form (the PCA metric evaluates
//! one per candidate cell-cluster pair, finishing.md 11.3 item 6).

use std::f64::consts::PI;

use scallop_geom::Vec3;
use scallop_geom::nalgebra::{Matrix3, SymmetricEigen};

use crate::tol;

/// `(lambda_I, lambda_II, X_I)` of a symmetric positive semi-definite matrix,
/// eigenvalues decreasing; `X_I` unit (sign arbitrary).
pub(crate) fn top_two(m: &Matrix3<f64>) -> (f64, f64, Vec3) {
    let (a00, a11, a22) = (m[(0, 0)], m[(1, 1)], m[(2, 2)]);
    let (a01, a02, a12) = (m[(0, 1)], m[(0, 2)], m[(1, 2)]);
    let p1 = a01 * a01 + a02 * a02 + a12 * a12;
    let scale = a00 * a00 + a11 * a11 + a22 * a22 + 2.0 * p1;
    if scale == 0.0 {
        return (0.0, 0.0, Vec3::x());
    }
    if p1 == 0.0 {
        return iterative(m);
    }
    // Trigonometric solution (Smith 1961) of the characteristic polynomial.
    let q = (a00 + a11 + a22) / 3.0;
    let p2 = (a00 - q).powi(2) + (a11 - q).powi(2) + (a22 - q).powi(2) + 2.0 * p1;
    let p = (p2 / 6.0).sqrt();
    let b = (m - Matrix3::identity() * q) / p;
    let r = (0.5 * b.determinant()).clamp(-1.0, 1.0);
    let phi = r.acos() / 3.0;
    let l1 = q + 2.0 * p * phi.cos();
    let l3 = q + 2.0 * p * (phi + 2.0 * PI / 3.0).cos();
    let l2 = 3.0 * q - l1 - l3;
    let shifted = m - Matrix3::identity() * l1;
    let rows = [shifted.row(0).transpose(), shifted.row(1).transpose(), shifted.row(2).transpose()];
    let candidates = [rows[0].cross(&rows[1]), rows[0].cross(&rows[2]), rows[1].cross(&rows[2])];
    let mut best = candidates[0];
    for c in &candidates[1..] {
        if c.norm_squared() > best.norm_squared() {
            best = *c;
        }
    }
    let norm = best.norm();
    if norm <= tol::EIGEN_CROSS_REL * scale || !norm.is_finite() {
        // lambda_I (nearly) repeated: the direction is ill-conditioned; let the
        // iterative solver pick one.
        return iterative(m);
    }
    (l1, l2, best / norm)
}

fn iterative(m: &Matrix3<f64>) -> (f64, f64, Vec3) {
    let eigen = SymmetricEigen::new(*m);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| eigen.eigenvalues[b].total_cmp(&eigen.eigenvalues[a]));
    let v: Vec3 = eigen.eigenvectors.column(order[0]).into_owned();
    let n = v.norm();
    let v = if n > 0.0 && n.is_finite() { v / n } else { Vec3::x() };
    (eigen.eigenvalues[order[0]], eigen.eigenvalues[order[1]], v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_form_matches_nalgebra() {
        let mut seed = 0x1234_5678_u64;
        let mut next = || {
            seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        for _ in 0..500 {
            let a = Matrix3::from_fn(|_, _| next() * 10.0);
            let m = a * a.transpose();
            let (l1, l2, v) = top_two(&m);
            let (r1, r2, w) = iterative(&m);
            assert!((l1 - r1).abs() <= 1e-9 * r1.abs().max(1.0), "{l1} {r1}");
            assert!((l2 - r2).abs() <= 1e-8 * r1.abs().max(1.0), "{l2} {r2}");
            if r1 - r2 > 1e-6 * r1 {
                assert!(v.dot(&w).abs() > 1.0 - 1e-8);
            }
        }
    }
}
