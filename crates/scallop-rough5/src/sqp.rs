//! A small dense SQP for linearly constrained problems (Jousselin 2020,
//! Ch. 3 §2.2, Eq. 3.20-3.23 after Han 1977 and Powell 1978): a damped-BFGS
//! approximation of the Hessian of the Lagrangian, an active-set QP for the
//! step, and a backtracking line search.
//!
//! The constraints of the reparameterisation (Eq. 3.17-3.19 as corrected in
//! docs/rough5.md) are linear in the polynomial coefficients, so the QP's
//! linearised constraints are the constraints themselves: from a feasible
//! start every iterate stays feasible (the QP step keeps the constraints,
//! and a shorter step along it too, the feasible set being convex). The
//! merit function of the line search is then the objective itself (an exact
//! penalty adds nothing on feasible points), and the Hessian of the
//! Lagrangian is that of the objective (linear constraints have none).
//! Gradients are central finite differences.

use scallop_geom::nalgebra::{DMatrix, DVector};

use crate::tol;

/// Linear constraints `eq_rows x = eq_rhs` and `rows x <= rhs`, on `N`
/// variables.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearConstraints<const N: usize> {
    /// Equality rows.
    pub eq_rows: Vec<[f64; N]>,
    /// Their right-hand sides.
    pub eq_rhs: Vec<f64>,
    /// Inequality rows (`row . x <= rhs`).
    pub rows: Vec<[f64; N]>,
    /// Their right-hand sides.
    pub rhs: Vec<f64>,
}

fn dot<const N: usize>(a: &[f64; N], x: &[f64; N]) -> f64 {
    a.iter().zip(x).map(|(a, x)| a * x).sum()
}

impl<const N: usize> LinearConstraints<N> {
    /// The largest violation at `x`: max of |eq residual| and of
    /// `row . x - rhs` (<= 0 when feasible).
    #[must_use]
    pub fn violation(&self, x: &[f64; N]) -> f64 {
        let eq = self.eq_rows.iter().zip(&self.eq_rhs).map(|(a, b)| (dot(a, x) - b).abs());
        let ineq = self.rows.iter().zip(&self.rhs).map(|(a, b)| dot(a, x) - b);
        eq.chain(ineq).fold(f64::NEG_INFINITY, f64::max)
    }
}

/// What the SQP reached.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SqpResult<const N: usize> {
    /// The last iterate (feasible when the start was).
    pub x: [f64; N],
    /// The objective there.
    pub value: f64,
    /// The objective at the start.
    pub start_value: f64,
    /// SQP iterations done.
    pub iterations: usize,
}

/// Central-difference gradient of `f` at `x`.
fn gradient<const N: usize>(f: &dyn Fn(&[f64; N]) -> f64, x: &[f64; N]) -> [f64; N] {
    let mut g = [0.0; N];
    for i in 0..N {
        let h = tol::SQP_FD_STEP * (1.0 + x[i].abs());
        let (mut a, mut b) = (*x, *x);
        a[i] += h;
        b[i] -= h;
        g[i] = (f(&a) - f(&b)) / (2.0 * h);
    }
    g
}

/// Minimises `f` from the feasible `x0` under `cons`, at most `max_iter`
/// iterations. Returns `None` when `x0` is not feasible (violation above
/// [`tol::SQP_FEASIBLE`]).
pub fn minimise<const N: usize>(
    f: &dyn Fn(&[f64; N]) -> f64,
    x0: &[f64; N],
    cons: &LinearConstraints<N>,
    max_iter: usize,
) -> Option<SqpResult<N>> {
    if cons.violation(x0) > tol::SQP_FEASIBLE {
        return None;
    }
    let mut x = *x0;
    let mut fx = f(&x);
    let start_value = fx;
    let mut g = gradient(f, &x);
    let scale = g.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    let mut hess = DMatrix::<f64>::identity(N, N) * scale;
    let mut first = true;
    let mut iterations = 0;
    for _ in 0..max_iter {
        iterations += 1;
        let d = qp_step(&hess, &g, &x, cons);
        let slope: f64 = g.iter().zip(&d).map(|(g, d)| g * d).sum();
        if d.iter().all(|v| v.abs() <= tol::SQP_STEP) || slope >= 0.0 {
            break;
        }
        let Some((xn, fxn)) = line_search(f, &x, &d, fx, slope) else { break };
        let gn = gradient(f, &xn);
        let s = DVector::from_fn(N, |i, _| xn[i] - x[i]);
        let y = DVector::from_fn(N, |i, _| gn[i] - g[i]);
        if first && s.dot(&y) > 0.0 {
            hess = DMatrix::identity(N, N) * (y.dot(&y) / s.dot(&y));
        }
        first = false;
        damped_bfgs(&mut hess, &s, &y);
        let done = (fx - fxn).abs() <= tol::SQP_REL_DECREASE * (1.0 + fx.abs());
        (x, fx, g) = (xn, fxn, gn);
        if done {
            break;
        }
    }
    Some(SqpResult { x, value: fx, start_value, iterations })
}

/// Backtracking (Armijo) along `d` from `x`; `None` when no decrease.
fn line_search<const N: usize>(
    f: &dyn Fn(&[f64; N]) -> f64,
    x: &[f64; N],
    d: &[f64; N],
    fx: f64,
    slope: f64,
) -> Option<([f64; N], f64)> {
    let mut alpha = 1.0;
    for _ in 0..60 {
        let mut xn = *x;
        for i in 0..N {
            xn[i] += alpha * d[i];
        }
        let fxn = f(&xn);
        if fxn <= fx + 1e-4 * alpha * slope {
            return Some((xn, fxn));
        }
        alpha *= 0.5;
    }
    None
}

/// Powell's damped BFGS update of `b` with the step `s` and the gradient
/// change `y`: keeps `b` positive definite.
fn damped_bfgs(b: &mut DMatrix<f64>, s: &DVector<f64>, y: &DVector<f64>) {
    let bs = &*b * s;
    let sbs = s.dot(&bs);
    if sbs <= 0.0 {
        return;
    }
    let sy = s.dot(y);
    let theta = if sy >= 0.2 * sbs { 1.0 } else { 0.8 * sbs / (sbs - sy) };
    let r = y * theta + &bs * (1.0 - theta);
    let sr = s.dot(&r);
    if sr <= 0.0 {
        return;
    }
    *b += &r * r.transpose() / sr - &bs * bs.transpose() / sbs;
}

/// The QP step (Eq. 3.22): min g.d + d.B.d / 2 subject to the constraints at
/// `x + d`, by a primal active-set method from the feasible d = 0
/// (Nocedal & Wright 2006, Alg. 16.3).
fn qp_step<const N: usize>(b: &DMatrix<f64>, g: &[f64; N], x: &[f64; N], cons: &LinearConstraints<N>) -> [f64; N] {
    // Room left by each inequality at x (clamped: x is feasible to rounding).
    let room: Vec<f64> = cons.rows.iter().zip(&cons.rhs).map(|(a, r)| (r - dot(a, x)).max(0.0)).collect();
    let eq_res: Vec<f64> = cons.eq_rows.iter().zip(&cons.eq_rhs).map(|(a, r)| r - dot(a, x)).collect();
    let g = DVector::from_column_slice(g);
    let mut d = DVector::<f64>::zeros(N);
    let mut work: Vec<usize> = Vec::new();
    let me = cons.eq_rows.len();
    for _ in 0..tol::QP_MAX_ITER {
        let m = me + work.len();
        let mut kkt = DMatrix::<f64>::zeros(N + m, N + m);
        kkt.view_mut((0, 0), (N, N)).copy_from(b);
        let mut rhs = DVector::<f64>::zeros(N + m);
        rhs.rows_mut(0, N).copy_from(&-(b * &d + &g));
        let rows = cons.eq_rows.iter().zip(&eq_res).chain(work.iter().map(|&i| (&cons.rows[i], &room[i])));
        for (k, (a, target)) in rows.enumerate() {
            let a_d: f64 = (0..N).map(|j| a[j] * d[j]).sum();
            for j in 0..N {
                kkt[(N + k, j)] = a[j];
                kkt[(j, N + k)] = a[j];
            }
            rhs[N + k] = target - a_d;
        }
        let Some(sol) = kkt.lu().solve(&rhs) else { break };
        let p = sol.rows(0, N).into_owned();
        if p.amax() <= tol::SQP_STEP * 1e-3 {
            // Stationary on the working set: drop the most negative multiplier.
            let worst = (0..work.len()).map(|k| (k, sol[N + me + k])).min_by(|a, b| a.1.total_cmp(&b.1));
            match worst {
                Some((k, l)) if l < -tol::QP_MULTIPLIER => {
                    work.remove(k);
                }
                _ => break,
            }
            continue;
        }
        let mut alpha = 1.0;
        let mut blocking = None;
        for (i, a) in cons.rows.iter().enumerate() {
            if work.contains(&i) {
                continue;
            }
            let ap: f64 = (0..N).map(|j| a[j] * p[j]).sum();
            if ap > 0.0 {
                let ad: f64 = (0..N).map(|j| a[j] * d[j]).sum();
                let t = ((room[i] - ad) / ap).max(0.0);
                if t < alpha {
                    alpha = t;
                    blocking = Some(i);
                }
            }
        }
        d += p * alpha;
        if let Some(i) = blocking {
            work.push(i);
        }
    }
    let mut out = [0.0; N];
    out.copy_from_slice(d.as_slice());
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A convex quadratic under linear constraints with a known solution:
    /// min (x0 - 2)^2 + (x1 - 2)^2 s.t. x0 + x1 <= 2 -> (1, 1); with x0 = 0.2
    /// as an equality -> (0.2, 1.8).
    #[test]
    fn quadratic_with_an_active_constraint() {
        let f = |x: &[f64; 2]| (x[0] - 2.0).powi(2) + (x[1] - 2.0).powi(2);
        let mut cons = LinearConstraints { eq_rows: vec![], eq_rhs: vec![], rows: vec![[1.0, 1.0]], rhs: vec![2.0] };
        let r = minimise(&f, &[0.0, 0.0], &cons, 50).unwrap();
        assert!((r.x[0] - 1.0).abs() < 1e-6 && (r.x[1] - 1.0).abs() < 1e-6, "{:?}", r.x);
        assert!(cons.violation(&r.x) <= 1e-12);
        cons.eq_rows.push([1.0, 0.0]);
        cons.eq_rhs.push(0.2);
        let r = minimise(&f, &[0.2, 0.0], &cons, 50).unwrap();
        assert!((r.x[0] - 0.2).abs() < 1e-9 && (r.x[1] - 1.8).abs() < 1e-6, "{:?}", r.x);
        // An infeasible start is refused.
        assert!(minimise(&f, &[3.0, 0.0], &cons, 50).is_none());
    }

    /// Rosenbrock inside the disc-approximating box x <= 0.5: the solution is
    /// (0.5, 0.25), found from (-1, 1) without leaving the feasible set.
    #[test]
    fn rosenbrock_on_a_bound() {
        let f = |x: &[f64; 2]| 100.0 * (x[1] - x[0] * x[0]).powi(2) + (1.0 - x[0]).powi(2);
        let cons = LinearConstraints { eq_rows: vec![], eq_rhs: vec![], rows: vec![[1.0, 0.0]], rhs: vec![0.5] };
        let r = minimise(&f, &[-1.0, 1.0], &cons, 500).unwrap();
        assert!((r.x[0] - 0.5).abs() < 1e-4 && (r.x[1] - 0.25).abs() < 1e-4, "{:?}", r);
        assert!(cons.violation(&r.x) <= 1e-12);
        assert!(r.value < r.start_value);
    }
}
