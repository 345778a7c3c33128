//! Closest point on a patch and tight bounding boxes: a coarse grid seeds a
//! bound-constrained Newton method on the parameter domain.
//!
//! # Method
//! For the squared distance `f(u, v) = |S(u, v) - P|^2 / 2` with `r = S - P`:
//!
//! ```text
//! grad f = [Su . r, Sv . r]
//! Hess f = [[Su . Su + Suu . r, Su . Sv + Suv . r],
//!           [Su . Sv + Suv . r, Sv . Sv + Svv . r]]
//! ```
//!
//! The minimiser is a projected Newton method with an active set (Bertsekas 1982):
//! a coordinate sitting on a domain bound whose gradient pushes outward is frozen,
//! so a point beyond an edge is projected onto that edge (a 1D Newton along it) and
//! one beyond a corner lands on the corner. Where the (reduced) Hessian is not
//! positive definite, a scaled steepest-descent step is used instead; every step is
//! clamped into the domain and accepted by an Armijo line search, so the objective
//! never increases (up to rounding). Several of the best grid samples are polished
//! and the best result wins, which guards against local minima.

use scallop_geom::{Aabb3, Point3};

use crate::error::Direction;
use crate::patch::{Domain, Patch};
use crate::tol;

/// The result of [`Patch::closest_point`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosestPoint {
    /// Parameter u of the closest surface point.
    pub u: f64,
    /// Parameter v of the closest surface point.
    pub v: f64,
    /// The closest surface point `S(u, v)`.
    pub point: Point3,
    /// Distance from the query point to `point` (mm).
    pub distance: f64,
}

/// Knobs of [`Patch::closest_point_opt`] and [`Patch::bounds_opt`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ClosestPointOptions {
    /// Seed-grid intervals per knot span and degree in each direction (the grid has
    /// `max(min_grid, per_span_and_degree * degree * spans)` intervals per direction,
    /// capped at `max_grid`).
    pub per_span_and_degree: usize,
    /// Fewest seed-grid intervals per direction.
    pub min_grid: usize,
    /// Most seed-grid intervals per direction.
    pub max_grid: usize,
    /// How many of the best grid samples are refined by Newton.
    pub seeds: usize,
    /// Newton iterations per seed.
    pub max_iterations: usize,
}

impl Default for ClosestPointOptions {
    fn default() -> Self {
        ClosestPointOptions { per_span_and_degree: 4, min_grid: 8, max_grid: 64, seeds: 3, max_iterations: 100 }
    }
}

/// Value, gradient and Hessian of an objective on the parameter domain.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Objective {
    pub value: f64,
    pub gradient: [f64; 2],
    pub hessian: [[f64; 2]; 2],
    /// Rounding uncertainty of `value` (absolute): the line search does not demand
    /// a decrease below it, so Newton can finish on its accurate gradient.
    pub noise: f64,
}

/// Minimises `f` over the box `domain` from `start` (projected Newton with an active
/// set and an Armijo line search; see the module docs). Returns the last point.
pub(crate) fn minimize(
    domain: &Domain,
    start: [f64; 2],
    max_iterations: usize,
    f: impl Fn([f64; 2]) -> Objective,
) -> ([f64; 2], Objective) {
    let lo = [domain.u[0], domain.v[0]];
    let hi = [domain.u[1], domain.v[1]];
    let width = [hi[0] - lo[0], hi[1] - lo[1]];
    let clamp = |x: [f64; 2]| [x[0].clamp(lo[0], hi[0]), x[1].clamp(lo[1], hi[1])];
    let mut x = clamp(start);
    let mut fx = f(x);
    for _ in 0..max_iterations {
        let g = fx.gradient;
        let h = fx.hessian;
        if !(g[0].is_finite() && g[1].is_finite()) {
            break;
        }
        // Active set: on a bound with the descent direction -g pointing outside.
        let free = [0, 1].map(|k| !((x[k] <= lo[k] && g[k] > 0.0) || (x[k] >= hi[k] && g[k] < 0.0)));
        let steepest = || {
            let norm = ((0..2).filter(|&k| free[k]).map(|k| g[k] * g[k]).sum::<f64>()).sqrt();
            let mut d = [0.0; 2];
            if norm > 0.0 {
                for k in 0..2 {
                    if free[k] {
                        d[k] = -g[k] / norm * tol::STEEPEST_FIRST_STEP * width[k];
                    }
                }
            }
            d
        };
        let direction = match free {
            [false, false] => break,
            [true, true] => {
                let det = h[0][0] * h[1][1] - h[0][1] * h[1][0];
                if h[0][0] > 0.0 && det > 0.0 {
                    [-(h[1][1] * g[0] - h[0][1] * g[1]) / det, -(h[0][0] * g[1] - h[1][0] * g[0]) / det]
                } else {
                    steepest()
                }
            }
            [true, false] => {
                if h[0][0] > 0.0 {
                    [-g[0] / h[0][0], 0.0]
                } else {
                    steepest()
                }
            }
            [false, true] => {
                if h[1][1] > 0.0 {
                    [0.0, -g[1] / h[1][1]]
                } else {
                    steepest()
                }
            }
        };
        if g[0] * direction[0] + g[1] * direction[1] >= 0.0 {
            break; // no descent direction left: a stationary point.
        }
        // Armijo backtracking along the projected path.
        let mut t = 1.0;
        let mut accepted = None;
        for _ in 0..tol::LINE_SEARCH_HALVINGS {
            let candidate = clamp([x[0] + t * direction[0], x[1] + t * direction[1]]);
            let step = [candidate[0] - x[0], candidate[1] - x[1]];
            if step == [0.0, 0.0] {
                break;
            }
            let fc = f(candidate);
            let predicted = g[0] * step[0] + g[1] * step[1];
            let slack = fx.noise.max(fc.noise);
            if fc.value <= fx.value + tol::ARMIJO * predicted + slack {
                accepted = Some((candidate, fc, step));
                break;
            }
            t *= 0.5;
        }
        let Some((candidate, fc, step)) = accepted else { break };
        x = candidate;
        fx = fc;
        let moved = (step[0] / width[0]).abs().max((step[1] / width[1]).abs());
        if moved <= tol::PARAM_STEP_REL {
            break;
        }
    }
    (x, fx)
}

impl Patch {
    /// Seed grid: parameter values per direction (span breaks subdivided evenly).
    pub(crate) fn seed_grid(&self, options: &ClosestPointOptions) -> [Vec<f64>; 2] {
        Direction::BOTH.map(|direction| {
            let breaks = self.span_breaks(direction);
            let spans = breaks.len() - 1;
            let wanted = (options.per_span_and_degree * self.degree()[direction.index()] * spans)
                .max(options.min_grid)
                .min(options.max_grid)
                .max(spans);
            let per_span = wanted.div_ceil(spans).max(1);
            subdivide(&breaks, |_| per_span)
        })
    }

    /// The point of the patch nearest to `query`, with default [`ClosestPointOptions`].
    ///
    /// ```
    /// use scallop_geom::Point3;
    /// let set = scallop_surface::builtin("rubio").unwrap();
    /// let rubio = &set.patches()[0];
    /// let on = rubio.point(0.3, 0.6) + rubio.normal(0.3, 0.6) * 2.0;
    /// let c = rubio.closest_point(&on);
    /// assert!((c.u - 0.3).abs() < 1e-9 && (c.v - 0.6).abs() < 1e-9);
    /// assert!((c.distance - 2.0).abs() < 1e-9);
    /// ```
    #[must_use]
    pub fn closest_point(&self, query: &Point3) -> ClosestPoint {
        self.closest_point_opt(query, &ClosestPointOptions::default())
    }

    /// The point of the patch nearest to `query`: the best `options.seeds` samples of
    /// a seed grid are refined by the bound-constrained Newton method of the
    /// [module docs](crate::closest), and the nearest result is returned (ties: the
    /// first in grid order). A non-finite query gives a non-finite distance.
    /// The answer is a local minimum of the distance that is at least as near as
    /// every grid sample; it is the global one whenever the grid resolves the
    /// basins of attraction (always for points nearer than the minimum radius of
    /// curvature, on patches that do not fold back on themselves).
    #[must_use]
    pub fn closest_point_opt(&self, query: &Point3, options: &ClosestPointOptions) -> ClosestPoint {
        let objective = |x: [f64; 2]| {
            let d = self.derivatives(x[0], x[1]);
            let r = d.point - query;
            let cross = d.du.dot(&d.dv) + d.duv.dot(&r);
            // |r|^2 / 2 with r = S - P: each coordinate of r errs by rounding of S and P.
            let noise =
                tol::OBJECTIVE_ROUNDING_REL * r.norm() * (r.norm() + d.point.coords.norm() + query.coords.norm());
            Objective {
                noise,
                value: 0.5 * r.norm_squared(),
                gradient: [d.du.dot(&r), d.dv.dot(&r)],
                hessian: [[d.du.norm_squared() + d.duu.dot(&r), cross], [cross, d.dv.norm_squared() + d.dvv.dot(&r)]],
            }
        };
        let seeds = self.best_samples(options, options.seeds, |p| (p - query).norm_squared());
        let mut best: Option<ClosestPoint> = None;
        for seed in seeds {
            let (x, _) = minimize(&self.domain(), seed, options.max_iterations, objective);
            let point = self.point(x[0], x[1]);
            let distance = (point - query).norm();
            if best.is_none_or(|b| distance < b.distance) {
                best = Some(ClosestPoint { u: x[0], v: x[1], point, distance });
            }
        }
        // INVARIANT: the seed grid is never empty, so neither is `seeds`.
        best.unwrap_or_else(|| {
            let (u, v) = self.domain().center();
            let point = self.point(u, v);
            ClosestPoint { u, v, point, distance: (point - query).norm() }
        })
    }

    /// The `count` grid samples with the lowest `score`, best first (ties in grid order).
    fn best_samples(
        &self,
        options: &ClosestPointOptions,
        count: usize,
        score: impl Fn(&Point3) -> f64,
    ) -> Vec<[f64; 2]> {
        let [us, vs] = self.seed_grid(options);
        let mut samples: Vec<(f64, usize, [f64; 2])> = Vec::with_capacity(us.len() * vs.len());
        for &u in &us {
            for &v in &vs {
                let s = score(&self.point(u, v));
                samples.push((s, samples.len(), [u, v]));
            }
        }
        samples.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        samples.into_iter().take(count.max(1)).map(|s| s.2).collect()
    }

    /// A tight axis-aligned box around the surface, with default options (see
    /// [`Patch::bounds_opt`]).
    ///
    /// ```
    /// let set = scallop_surface::builtin("choi").unwrap();
    /// let choi = &set.patches()[0];
    /// let b = choi.bounds();
    /// assert!((b.min.x - 6.7275).abs() < 1e-9); // interior of the edge u = 0
    /// ```
    #[must_use]
    pub fn bounds(&self) -> Aabb3 {
        self.bounds_opt(&ClosestPointOptions::default())
    }

    /// A tight axis-aligned box around the surface: each of the six coordinate
    /// extremes is minimised by the Newton method of the [module docs](crate::closest) from the best
    /// seed-grid samples. Exact (to rounding) when the grid resolves each extreme's
    /// basin; [`Patch::control_bounds`] is the looser box that is always guaranteed.
    #[must_use]
    pub fn bounds_opt(&self, options: &ClosestPointOptions) -> Aabb3 {
        let mut min = [0.0; 3];
        let mut max = [0.0; 3];
        for axis in 0..3 {
            for sign in [1.0, -1.0] {
                let objective = |x: [f64; 2]| {
                    let d = self.derivatives(x[0], x[1]);
                    Objective {
                        noise: tol::OBJECTIVE_ROUNDING_REL * d.point.coords.norm(),
                        value: sign * d.point[axis],
                        gradient: [sign * d.du[axis], sign * d.dv[axis]],
                        hessian: [[sign * d.duu[axis], sign * d.duv[axis]], [sign * d.duv[axis], sign * d.dvv[axis]]],
                    }
                };
                let seeds = self.best_samples(options, options.seeds, |p| sign * p[axis]);
                let mut best = f64::INFINITY;
                for seed in seeds {
                    let start = objective(seed).value;
                    let (_, reached) = minimize(&self.domain(), seed, options.max_iterations, objective);
                    best = best.min(start).min(reached.value);
                }
                if sign > 0.0 {
                    min[axis] = best;
                } else {
                    max[axis] = -best;
                }
            }
        }
        Aabb3 { min: Point3::from(min), max: Point3::from(max) }
    }
}

/// The parameter values of `breaks` with span `s` split into `count(s)` equal
/// intervals; the breaks themselves are kept exactly.
pub(crate) fn subdivide(breaks: &[f64], count: impl Fn(usize) -> usize) -> Vec<f64> {
    let mut values = vec![breaks[0]];
    for (s, pair) in breaks.windows(2).enumerate() {
        let n = count(s).max(1);
        for k in 1..n {
            #[allow(clippy::cast_precision_loss)]
            let fraction = k as f64 / n as f64;
            values.push(pair[0] + fraction * (pair[1] - pair[0]));
        }
        values.push(pair[1]);
    }
    values
}
