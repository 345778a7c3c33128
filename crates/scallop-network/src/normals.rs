//! Exact unit normals at pass vertices (finishing.md 6.4: "n_i <- exact normal at
//! (u_i, v_i)"), cheap on network edges.
//!
//! A vertex on a u-edge has `v = b / N_v` fixed, so for a (rational) Bezier patch
//! with homogeneous control points `H_ij = w_ij [P_ij, 1]` the surface along the
//! edge is `A(u) = sum_i B_i(u) R_i(b)` with the row table `R_i(b) = sum_j
//! B_j(v_b) H_ij`, and `A_v(u) = sum_i B_i(u) R'_i(b)`, `R'_i(b) = sum_j B_j'(v_b)
//! H_ij`: a curve of degree `p` per derivative, precomputed per network row
//! (likewise per column for v-edges). With `A = [X, W]`:
//!
//! ```text
//! S_u ~ W X_u - W_u X,   S_v ~ W X_v - W_v X,   n = S_u x S_v / |S_u x S_v|
//! ```
//!
//! (the common factor `1 / W^2` drops out of the direction). Other points and
//! NURBS patches use the full evaluation; degenerate points `Patch::normal`'s
//! fallback.

use scallop_geom::Vec3;
use scallop_surface::Patch;

/// Largest Bezier degree tabulated (higher degrees use `Patch::normal`).
pub(crate) const MAX_DEGREE: usize = 15;

type Homogeneous = [f64; 4];

/// Per-row and per-column tables of a Bezier patch on a network.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct EdgeNormals {
    degree: [usize; 2],
    control: Vec<Homogeneous>,
    /// `rows[b * (p + 1) + i] = R_i(b)`, `rows_dv` the same with `B_j'`.
    rows: Vec<Homogeneous>,
    rows_dv: Vec<Homogeneous>,
    /// `columns[a * (q + 1) + j] = C_j(a)`, `columns_du` with `B_i'`.
    columns: Vec<Homogeneous>,
    columns_du: Vec<Homogeneous>,
}

/// Bernstein values and first derivatives of degree `n` at `t` into `values`, `derivatives`.
pub(crate) fn bernstein(n: usize, t: f64, values: &mut [f64; MAX_DEGREE + 1], derivatives: &mut [f64; MAX_DEGREE + 1]) {
    let s = 1.0 - t;
    // Closed forms of the common degrees (the general loop below is the same).
    match n {
        1 => {
            values[..2].copy_from_slice(&[s, t]);
            derivatives[..2].copy_from_slice(&[-1.0, 1.0]);
            return;
        }
        2 => {
            values[..3].copy_from_slice(&[s * s, 2.0 * s * t, t * t]);
            derivatives[..3].copy_from_slice(&[-2.0 * s, 2.0 * (s - t), 2.0 * t]);
            return;
        }
        3 => {
            let (s2, t2) = (s * s, t * t);
            values[..4].copy_from_slice(&[s2 * s, 3.0 * s2 * t, 3.0 * s * t2, t2 * t]);
            derivatives[..4].copy_from_slice(&[-3.0 * s2, 3.0 * s * (s - 2.0 * t), 3.0 * t * (2.0 * s - t), 3.0 * t2]);
            return;
        }
        _ => {}
    }
    *values = [0.0; MAX_DEGREE + 1];
    values[0] = 1.0;
    let step = |values: &mut [f64; MAX_DEGREE + 1], k: usize| {
        for i in (0..=k).rev() {
            let left = if i > 0 { values[i - 1] } else { 0.0 };
            values[i] = (1.0 - t) * values[i] + t * left;
        }
    };
    for k in 1..n {
        step(values, k);
    }
    // values holds degree n - 1: B_i^n' = n (B_{i-1}^{n-1} - B_i^{n-1}).
    for i in 0..=n {
        let left = if i > 0 { values[i - 1] } else { 0.0 };
        let right = if i < n { values[i] } else { 0.0 };
        derivatives[i] = n as f64 * (left - right);
    }
    if n > 0 {
        step(values, n);
    }
}

#[inline(always)]
fn axpy(acc: &mut Homogeneous, a: f64, x: &Homogeneous) {
    for k in 0..4 {
        acc[k] += a * x[k];
    }
}

/// Along an isoline with tables `curve` (degree `n`) and `cross` (its
/// derivative across): the homogeneous point, its derivative along `t` and
/// across.
fn along(n: usize, t: f64, curve: &[Homogeneous], cross: &[Homogeneous]) -> (Homogeneous, Homogeneous, Homogeneous) {
    // The common degrees with fixed-size tables (unrolled; the same operations
    // in the same order as the general loop).
    match n {
        1 => along_fixed::<2>(t, curve, cross),
        2 => along_fixed::<3>(t, curve, cross),
        3 => along_fixed::<4>(t, curve, cross),
        _ => along_general(n, t, curve, cross),
    }
}

/// [`along`] of degree `M - 1`.
#[inline(always)]
fn along_fixed<const M: usize>(
    t: f64,
    curve: &[Homogeneous],
    cross: &[Homogeneous],
) -> (Homogeneous, Homogeneous, Homogeneous) {
    let (Ok(curve), Ok(cross)) = (<&[Homogeneous; M]>::try_from(curve), <&[Homogeneous; M]>::try_from(cross)) else {
        return along_general(M - 1, t, curve, cross);
    };
    let (mut values, mut derivatives) = ([0.0; MAX_DEGREE + 1], [0.0; MAX_DEGREE + 1]);
    bernstein(M - 1, t, &mut values, &mut derivatives);
    let (mut a, mut a_along, mut a_across) = ([0.0; 4], [0.0; 4], [0.0; 4]);
    for i in 0..M {
        axpy(&mut a, values[i], &curve[i]);
        axpy(&mut a_along, derivatives[i], &curve[i]);
        axpy(&mut a_across, values[i], &cross[i]);
    }
    (a, a_along, a_across)
}

/// [`along`] of any degree.
fn along_general(
    n: usize,
    t: f64,
    curve: &[Homogeneous],
    cross: &[Homogeneous],
) -> (Homogeneous, Homogeneous, Homogeneous) {
    let (mut values, mut derivatives) = ([0.0; MAX_DEGREE + 1], [0.0; MAX_DEGREE + 1]);
    bernstein(n, t, &mut values, &mut derivatives);
    let (mut a, mut a_along, mut a_across) = ([0.0; 4], [0.0; 4], [0.0; 4]);
    for i in 0..=n {
        axpy(&mut a, values[i], &curve[i]);
        axpy(&mut a_along, derivatives[i], &curve[i]);
        axpy(&mut a_across, values[i], &cross[i]);
    }
    (a, a_along, a_across)
}

/// `W X_u - W_u X` as a vector from homogeneous `A` and its derivative.
fn tangent(a: &Homogeneous, da: &Homogeneous) -> Vec3 {
    Vec3::new(a[3] * da[0] - da[3] * a[0], a[3] * da[1] - da[3] * a[1], a[3] * da[2] - da[3] * a[2])
}

/// The control net collapsed along one parameter (of degree `n`) at the
/// `stations + 1` even values `k / stations`: for each station, then each of
/// the `lines + 1` control lines across it, the homogeneous point and its
/// derivative along the collapsed parameter. `at(line, m)` indexes `control`.
fn collapse(
    control: &[Homogeneous],
    n: usize,
    lines: usize,
    stations: usize,
    at: impl Fn(usize, usize) -> usize,
) -> (Vec<Homogeneous>, Vec<Homogeneous>) {
    let (mut values, mut derivatives) = ([0.0; MAX_DEGREE + 1], [0.0; MAX_DEGREE + 1]);
    let mut points = Vec::with_capacity((stations + 1) * (lines + 1));
    let mut slopes = Vec::with_capacity(points.capacity());
    for k in 0..=stations {
        bernstein(n, k as f64 / stations as f64, &mut values, &mut derivatives);
        for line in 0..=lines {
            let (mut c, mut dc) = ([0.0; 4], [0.0; 4]);
            for m in 0..=n {
                axpy(&mut c, values[m], &control[at(line, m)]);
                axpy(&mut dc, derivatives[m], &control[at(line, m)]);
            }
            points.push(c);
            slopes.push(dc);
        }
    }
    (points, slopes)
}

/// [`along`] on line `line` of collapsed tables (lines of `n + 1` entries, as
/// [`collapse`] lays them out).
#[inline]
fn along_line(
    n: usize,
    line: usize,
    t: f64,
    points: &[Homogeneous],
    slopes: &[Homogeneous],
) -> (Homogeneous, Homogeneous, Homogeneous) {
    let range = line * (n + 1)..(line + 1) * (n + 1);
    along(n, t, &points[range.clone()], &slopes[range])
}

impl EdgeNormals {
    /// Tables for `patch` on a network of `quads` quads, `None` for NURBS or
    /// degrees above the tabulated limit.
    pub(crate) fn new(patch: &Patch, quads: [usize; 2]) -> Option<EdgeNormals> {
        let [p, q] = patch.degree();
        if !patch.is_bezier() || p > MAX_DEGREE || q > MAX_DEGREE {
            return None;
        }
        let mut control = Vec::with_capacity((p + 1) * (q + 1));
        for i in 0..=p {
            for j in 0..=q {
                let w = patch.weights().map_or(1.0, |w| w[i * (q + 1) + j]);
                let c = patch.control_point(i, j);
                control.push([c.x * w, c.y * w, c.z * w, w]);
            }
        }
        let (rows, rows_dv) = collapse(&control, q, p, quads[1], |i, j| i * (q + 1) + j);
        let (columns, columns_du) = collapse(&control, p, q, quads[0], |j, i| i * (q + 1) + j);
        Some(EdgeNormals { degree: [p, q], control, rows, rows_dv, columns, columns_du })
    }

    /// `(S_u, S_v)` up to a common positive factor on the u-edge row `b` at `u`.
    #[inline]
    pub(crate) fn on_row(&self, b: usize, u: f64) -> (Vec3, Vec3) {
        let (a, a_u, a_v) = along_line(self.degree[0], b, u, &self.rows, &self.rows_dv);
        (tangent(&a, &a_u), tangent(&a, &a_v))
    }

    /// `(S_u, S_v)` up to a common positive factor on the v-edge column `a` at `v`.
    #[inline]
    pub(crate) fn on_column(&self, column: usize, v: f64) -> (Vec3, Vec3) {
        let (a, a_v, a_u) = along_line(self.degree[1], column, v, &self.columns, &self.columns_du);
        (tangent(&a, &a_u), tangent(&a, &a_v))
    }

    /// `(S_u, S_v)` up to a common positive factor anywhere.
    pub(crate) fn at(&self, u: f64, v: f64) -> (Vec3, Vec3) {
        let [p, q] = self.degree;
        let (mut bu, mut dbu) = ([0.0; MAX_DEGREE + 1], [0.0; MAX_DEGREE + 1]);
        let (mut bv, mut dbv) = ([0.0; MAX_DEGREE + 1], [0.0; MAX_DEGREE + 1]);
        bernstein(p, u, &mut bu, &mut dbu);
        bernstein(q, v, &mut bv, &mut dbv);
        let (mut a, mut a_u, mut a_v) = ([0.0; 4], [0.0; 4], [0.0; 4]);
        for i in 0..=p {
            for j in 0..=q {
                let h = &self.control[i * (q + 1) + j];
                axpy(&mut a, bu[i] * bv[j], h);
                axpy(&mut a_u, dbu[i] * bv[j], h);
                axpy(&mut a_v, bu[i] * dbv[j], h);
            }
        }
        (tangent(&a, &a_u), tangent(&a, &a_v))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closed forms and the general recursion give `C(n, i) t^i (1 - t)^(n - i)`
    /// and its derivative.
    #[test]
    fn bernstein_values_and_derivatives() {
        for n in 1..=6usize {
            for &t in &[0.0, 0.2, 0.5, 0.93, 1.0] {
                let (mut values, mut derivatives) = ([0.0; MAX_DEGREE + 1], [0.0; MAX_DEGREE + 1]);
                bernstein(n, t, &mut values, &mut derivatives);
                let binomial = |n: usize, i: usize| (1..=i).fold(1.0, |c, k| c * (n + 1 - k) as f64 / k as f64);
                let b = |n: usize, i: usize| binomial(n, i) * t.powi(i as i32) * (1.0 - t).powi((n - i) as i32);
                for i in 0..=n {
                    assert!((values[i] - b(n, i)).abs() < 1e-14, "n {n} i {i} t {t}");
                    let left = if i > 0 { b(n - 1, i - 1) } else { 0.0 };
                    let right = if i < n { b(n - 1, i) } else { 0.0 };
                    assert!((derivatives[i] - n as f64 * (left - right)).abs() < 1e-13, "n {n} i {i} t {t}");
                }
            }
        }
    }
}
