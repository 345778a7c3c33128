//! Univariate basis functions with their first two derivatives: Bernstein
//! polynomials (the Bezier fast path) and B-splines (Cox-de Boor, half-open spans).

/// The `degree + 1` basis functions that can be non-zero at one parameter, with
/// their first and second derivatives.
#[derive(Clone, Debug)]
pub(crate) struct BasisDerivatives {
    /// Index of the first of them (0 for Bernstein; `span - degree` for B-splines).
    pub first: usize,
    /// `values[k][r]` is the k-th derivative of basis function `first + r`.
    pub values: [Vec<f64>; 3],
}

/// Bernstein polynomials `B_i^n(t) = C(n,i) t^i (1-t)^(n-i)`, i = 0..=n, and derivatives:
///
/// ```text
/// d/dt  B_i^n = n (B_{i-1}^{n-1} - B_i^{n-1})
/// d2/dt2 B_i^n = n (n-1) (B_{i-2}^{n-2} - 2 B_{i-1}^{n-2} + B_i^{n-2})     (out-of-range terms are 0)
/// ```
///
/// The values come from the triangular recurrence `B_i^d = (1-t) B_i^{d-1} + t B_{i-1}^{d-1}`
/// (Piegl & Tiller, The NURBS Book, A1.3), which is stable on [0, 1].
pub(crate) fn bernstein(degree: usize, t: f64) -> BasisDerivatives {
    let n = degree;
    let s = 1.0 - t;
    let mut current = vec![1.0];
    let mut previous: Vec<f64> = Vec::new();
    let mut before_previous: Vec<f64> = Vec::new();
    for d in 1..=n {
        let mut next = vec![0.0; d + 1];
        for (k, slot) in next.iter_mut().enumerate() {
            let left = if k < d { s * current[k] } else { 0.0 };
            let right = if k > 0 { t * current[k - 1] } else { 0.0 };
            *slot = left + right;
        }
        before_previous = std::mem::replace(&mut previous, std::mem::replace(&mut current, next));
    }
    let at = |v: &[f64], i: isize| if i >= 0 { v.get(i.unsigned_abs()).copied().unwrap_or(0.0) } else { 0.0 };
    let nf = n as f64;
    let first_derivative: Vec<f64> = (0..=n as isize).map(|i| nf * (at(&previous, i - 1) - at(&previous, i))).collect();
    let second_derivative: Vec<f64> = (0..=n as isize)
        .map(|i| {
            if n < 2 {
                return 0.0;
            }
            let b = &before_previous;
            nf * (nf - 1.0) * (at(b, i - 2) - 2.0 * at(b, i - 1) + at(b, i))
        })
        .collect();
    BasisDerivatives { first: 0, values: [current, first_derivative, second_derivative] }
}

/// The knot span `s` with `knots[s] <= t < knots[s + 1]`, `degree <= s <= n`
/// (`n + 1` control points). At the domain end `t = knots[n + 1]` it is the last
/// non-empty span (spec finishing.md 4.1, half-open spans with the last knot special-cased).
/// `t` must lie in the domain `[knots[degree], knots[n + 1]]`.
pub(crate) fn find_span(knots: &[f64], degree: usize, n: usize, t: f64) -> usize {
    if t >= knots[n + 1] {
        let mut s = n;
        while s > degree && knots[s] >= knots[s + 1] {
            s -= 1;
        }
        return s;
    }
    // Binary search (The NURBS Book, A2.1) for knots[low] <= t < knots[high].
    let mut low = degree;
    let mut high = n + 1;
    while high - low > 1 {
        let mid = low + (high - low) / 2;
        if t < knots[mid] {
            high = mid;
        } else {
            low = mid;
        }
    }
    low
}

/// The non-zero B-spline basis functions `N_{span-p..=span, p}(t)` and their first two
/// derivatives (The NURBS Book, A2.3 `DersBasisFuns` with n = 2). `span` comes from
/// [`find_span`], so every denominator is a positive knot difference.
pub(crate) fn bspline(knots: &[f64], degree: usize, span: usize, t: f64) -> BasisDerivatives {
    let p = degree;
    // ndu: upper triangle = basis functions of rising degree, lower triangle = knot differences.
    let mut ndu = vec![vec![0.0; p + 1]; p + 1];
    let mut left = vec![0.0; p + 1];
    let mut right = vec![0.0; p + 1];
    ndu[0][0] = 1.0;
    for j in 1..=p {
        left[j] = t - knots[span + 1 - j];
        right[j] = knots[span + j] - t;
        let mut saved = 0.0;
        for r in 0..j {
            ndu[j][r] = right[r + 1] + left[j - r];
            let temp = ndu[r][j - 1] / ndu[j][r];
            ndu[r][j] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        ndu[j][j] = saved;
    }
    let mut ders = [vec![0.0; p + 1], vec![0.0; p + 1], vec![0.0; p + 1]];
    for (j, value) in ders[0].iter_mut().enumerate() {
        *value = ndu[j][p];
    }
    let order = p.min(2);
    let pi = p as isize;
    let mut a = [vec![0.0; p + 1], vec![0.0; p + 1]];
    for r in 0..=p {
        let ri = r as isize;
        let (mut s1, mut s2) = (0usize, 1usize);
        a[0][0] = 1.0;
        for k in 1..=order {
            let ki = k as isize;
            let mut d = 0.0;
            let rk = ri - ki;
            let pk = p - k;
            if ri >= ki {
                let rku = rk.unsigned_abs();
                a[s2][0] = a[s1][0] / ndu[pk + 1][rku];
                d = a[s2][0] * ndu[rku][pk];
            }
            let j1: usize = if rk >= -1 { 1 } else { (-rk).unsigned_abs() };
            let j2: usize = if ri - 1 <= pi - ki { k - 1 } else { p - r };
            for j in j1..=j2 {
                let idx = (rk + j as isize).unsigned_abs();
                a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][idx];
                d += a[s2][j] * ndu[idx][pk];
            }
            if ri <= pi - ki {
                a[s2][k] = -a[s1][k - 1] / ndu[pk + 1][r];
                d += a[s2][k] * ndu[r][pk];
            }
            ders[k][r] = d;
            std::mem::swap(&mut s1, &mut s2);
        }
    }
    let mut factor = p as f64;
    for (k, row) in ders.iter_mut().enumerate().take(order + 1).skip(1) {
        for value in row.iter_mut() {
            *value *= factor;
        }
        factor *= (p - k) as f64;
    }
    BasisDerivatives { first: span - p, values: ders }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bspline_on_clamped_knots_equals_bernstein() {
        for degree in 1..=5 {
            let mut knots = vec![0.0; degree + 1];
            knots.extend(std::iter::repeat_n(1.0, degree + 1));
            for t in [0.0, 0.2, 0.5, 0.77, 1.0] {
                let span = find_span(&knots, degree, degree, t);
                let a = bspline(&knots, degree, span, t);
                let b = bernstein(degree, t);
                for k in 0..3 {
                    for r in 0..=degree {
                        let diff = (a.values[k][r] - b.values[k][r]).abs();
                        assert!(diff <= 1e-11, "degree {degree} t {t} k {k} r {r}: {diff}");
                    }
                }
            }
        }
    }

    #[test]
    fn span_search_handles_ends_and_repeats() {
        let knots = [0.0, 0.0, 0.0, 1.0, 1.0, 2.0, 3.0, 3.0, 3.0];
        // n = 5 (6 control points), degree 2.
        assert_eq!(find_span(&knots, 2, 5, 0.0), 2);
        assert_eq!(find_span(&knots, 2, 5, 0.5), 2);
        assert_eq!(find_span(&knots, 2, 5, 1.0), 4);
        assert_eq!(find_span(&knots, 2, 5, 2.5), 5);
        assert_eq!(find_span(&knots, 2, 5, 3.0), 5);
    }
}
