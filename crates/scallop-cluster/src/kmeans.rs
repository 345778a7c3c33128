//! K-means (finishing.md 11.6, Alg. 1): circle initialisation, exact means,
//! incremental statistics, fixed-point stop, iteration cap.
//!
//! Two implementations of the same algorithm:
//! - the plain sweep (any metric): every cell against every centre;
//! - Hamerly's bounds (Hamerly 2010: one upper and one lower bound per cell) for
//!   the global diagonal metrics (weighted Euclidean, global standard deviation),
//!   the optimiser's hot path. (Elkan's per-centre bounds were tried: on 80 x 80
//!   with K = 10 they cost 2.5 times more instructions, the bound upkeep
//!   outweighing the distances saved.) With a
//!   diagonal form and theta wrapped or plain, `d = sqrt(d^2)` is a metric (a
//!   weighted L2 product of lines and, for theta, a circle of period pi), so the
//!   triangle inequality bounds let most cells skip the scan once centres settle.
//!   A cell skips only when its bounds prove its centre *strictly* nearest (with a
//!   relative slack `tol::HAMERLY_SLACK` for rounding), and scans compare `d^2` with
//!   the lowest index winning ties, so the labels, the statistics updates and the
//!   iteration count are those of the plain sweep, bit for bit (tested).
//!
//! The scan of a cell whose bounds fail starts from its centre `a` at distance
//! `u` and visits the other centres by increasing distance to `a` (sorted once
//! per sweep, `K^2` distances that the half gaps need anyway), stopping at the
//! first one farther than `2u (1 + slack) + tol::HAMERLY_ABSOLUTE`: by the
//! triangle inequality the rest are farther than `u` from the cell (the
//! lower bound takes `d(a, j) - u` for them), so the nearest, with the lowest
//! index on ties, is among the visited ones. The initial assignment uses the same
//! scan from the previous cell's centre (grid neighbours share centres).
//!
//! A sweep runs in three passes: (1) every cell's bounds after the centres'
//! moves, branch-free, listing the cells whose bounds fail; (2) for those, the
//! exact distance to their own centre, branch-free, listing the cells that still
//! fail; (3) the scans of these, in increasing cell order. The passes cost more
//! instructions than one loop with two `continue`s (61 M against 53 M per
//! Rubio K = 10 evaluation) but save the branch mispredictions of the
//! data-dependent skips at every cluster border: one evaluation's clustering
//! fell from 5.0 to 3.4 ms (`examples/evaluation.rs` of scallop-optim). The
//! scan's choice of the nearest centre uses selects, not branches, for the same
//! reason.
//!
//! Tried and dropped (more instructions on Choi and Rubio at K = 10): skipping
//! groups of 16 cells whose bounds all hold (cells near cluster borders spoil
//! almost every group), sleeping cells in per-cluster heaps keyed by the drift
//! their bounds can absorb (most cells skip by the half-gap test, whose margin
//! does not accumulate), an out-of-line slow path, and centres in padded SIMD
//! blocks. (A branch-free first pass was on that list too, judged by
//! instruction counts; by wall time it is the three passes above.) Tried and
//! dropped by wall time: sleeping cells woken by the accumulated largest shift
//! (half the cells of a Rubio K = 10 run have margins below two sweeps' drift,
//! so the full passes that re-sort them cost more than they save); a second
//! lower bound for the cell's second-nearest centre (22 % fewer scans, but the
//! first pass's extra gather costs more); the initial assignment against every
//! centre without the chained scan (no faster).

use std::f64::consts::{FRAC_PI_2, PI};

use crate::engine::{Frozen, Setup, Stats, circle_centres, compact, means, means_into};
use crate::features::ThetaMode;
#[cfg(doc)]
use crate::features::delta;
#[cfg(doc)]
use crate::metric::Quad;
use crate::metric::{Metric, Scope};
use crate::partition::Clustering;
use crate::tol;

/// K-means with `k` clusters and at most `max_iterations` assignment sweeps.
pub(crate) fn kmeans(setup: &Setup, k: usize, max_iterations: usize) -> Clustering {
    let diagonal_global = setup.metric.scope() == Scope::Global
        && !matches!(setup.metric, Metric::Pca { .. })
        && setup.global.is_diagonal();
    if diagonal_global { kmeans_bounded(setup, k, max_iterations) } else { kmeans_plain(setup, k, max_iterations) }
}

/// The plain algorithm (finishing.md 11.6, normative pseudo-code).
pub(crate) fn kmeans_plain(setup: &Setup, k: usize, max_iterations: usize) -> Clustering {
    let initial = circle_centres(setup.features, k);
    // Initial assignment: no cluster statistics yet (the PCA term is 0).
    let frozen = Frozen::new(setup, initial, None, false);
    let mut labels = Vec::new();
    frozen.assign(setup, None, &mut labels);
    let mut centres = frozen.centres;
    let mut stats = Stats::batch(setup, &labels, k);
    let mut next = Vec::with_capacity(labels.len());
    let (mut iterations, mut converged) = (0, false);
    for it in 1..=max_iterations {
        iterations = it;
        centres = means(&stats, &centres, setup.mode);
        let frozen = Frozen::new(setup, centres, Some((&stats, &labels)), false);
        frozen.assign(setup, Some(&labels), &mut next);
        centres = frozen.centres;
        let mut moved = false;
        for (i, (&old, &new)) in labels.iter().zip(&next).enumerate() {
            if old != new {
                moved = true;
                stats.move_point(setup, i, old, new);
            }
        }
        if !moved {
            converged = true;
            break;
        }
        std::mem::swap(&mut labels, &mut next);
        if it % tol::BATCH_REFRESH_EVERY == 0 {
            stats = Stats::batch(setup, &labels, k);
        }
    }
    let (clusters, _) = compact(&mut labels, k);
    Clustering { labels, clusters, iterations, converged }
}

/// `d^2` of a diagonal form with weights `w` (theta wrapped when `WRAPPED`): the
/// same operations, in the same order, as [`Quad::eval_diagonal`] of
/// [`delta`] for a theta difference in `(-pi, pi]` (folded features and centres),
/// so both paths give identical bits. Written on arrays (differences, then
/// products, then the sum in the scalar order) so that the compiler pairs the
/// lanes in SSE2 registers: 6 % off the clustering of an evaluation, same bits.
#[inline(always)]
fn distance2<const WRAPPED: bool>(x: &[f64; 4], c: &[f64; 4], w: &[f64; 4]) -> f64 {
    let mut d = [x[0] - c[0], x[1] - c[1], x[2] - c[2], x[3] - c[3]];
    if WRAPPED {
        let t = d[3];
        let up = if t >= FRAC_PI_2 { PI } else { 0.0 };
        let down = if t < -FRAC_PI_2 { PI } else { 0.0 };
        d[3] = t - up + down;
    }
    let p = [w[0] * d[0] * d[0], w[1] * d[1] * d[1], w[2] * d[2] * d[2], w[3] * d[3] * d[3]];
    p[0] + p[1] + p[2] + p[3]
}

/// K-means with Hamerly's bounds (global diagonal metrics only; module docs).
pub(crate) fn kmeans_bounded(setup: &Setup, k: usize, max_iterations: usize) -> Clustering {
    if setup.mode == ThetaMode::Wrapped {
        bounded::<true>(setup, k, max_iterations)
    } else {
        bounded::<false>(setup, k, max_iterations)
    }
}

/// What one sweep's bound upkeep needs of a centre.
#[derive(Clone, Copy, Default)]
#[repr(align(32))] // a power-of-two stride: the record of a label is one shift away
struct Drift {
    /// How far the centre moved.
    shift: f64,
    /// How far any other centre moved at most (the decrement of the lower bounds
    /// of its cells).
    others: f64,
    /// Half the distance to the nearest other centre.
    half_gap: f64,
}

/// Every centre's others by increasing distance into `near` (`k - 1` entries per
/// centre; ties by index), and half the distance to the nearest into `drift`.
fn sort_neighbours(
    centres: &[[f64; 4]],
    near: &mut [(f64, u32)],
    drift: &mut [Drift],
    distance: impl Fn(&[f64; 4], &[f64; 4]) -> f64,
) {
    let k = centres.len();
    if k == 1 {
        drift[0].half_gap = f64::INFINITY;
        return;
    }
    for (c, list) in near.chunks_exact_mut(k - 1).enumerate() {
        let others = (0..k).filter(|&j| j != c);
        for (slot, j) in list.iter_mut().zip(others) {
            #[allow(clippy::cast_possible_truncation)] // k <= cells < u32::MAX
            {
                *slot = (distance(&centres[c], &centres[j]), j as u32);
            }
        }
        list.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        drift[c].half_gap = 0.5 * list[0].0;
    }
}

/// The nearest centre of `x` (lowest index on ties, as the plain sweep), given
/// `d2a = d^2(x, c_a)` and `u = sqrt(d2a)` for some centre `a`, with an upper bound (its distance)
/// and a lower bound of the distance to every other centre. Only the centres
/// closer to `a` than `2u` (plus slack), `u = d(x, c_a)`, can be nearer than `a`:
/// a farther centre j is at least `d(a, j) - u > u` away (triangle inequality);
/// `near` lists them by increasing distance to `a`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn nearest_from<const WRAPPED: bool>(
    x: &[f64; 4],
    a: usize,
    (d2a, u): (f64, f64),
    centres: &[[f64; 4]],
    near: &[(f64, u32)],
    w: &[f64; 4],
    slack: f64,
) -> (u32, f64, f64) {
    let k = centres.len();
    let limit = 2.0 * u * slack + tol::HAMERLY_ABSOLUTE;
    #[allow(clippy::cast_possible_truncation)] // k <= cells < u32::MAX
    let (mut best, mut d_best, mut d_second) = (a as u32, d2a, f64::INFINITY);
    let mut beyond = f64::INFINITY;
    for &(gap, j) in &near[a * (k - 1)..(a + 1) * (k - 1)] {
        if gap > limit {
            beyond = gap - u;
            break;
        }
        let dj = distance2::<WRAPPED>(x, &centres[j as usize], w);
        // The plain sweep's order: the lowest index wins an exact tie.
        #[allow(clippy::float_cmp)] // exact tie of the same arithmetic
        let wins = dj < d_best || (dj == d_best && j < best);
        // Selects, not branches: which centre wins is data-dependent.
        let other = if dj < d_second { dj } else { d_second };
        d_second = if wins { d_best } else { other };
        d_best = if wins { dj } else { d_best };
        best = if wins { j } else { best };
    }
    let second = d_second.sqrt();
    (best, d_best.sqrt(), if beyond < second { beyond } else { second })
}

fn bounded<const WRAPPED: bool>(setup: &Setup, k: usize, max_iterations: usize) -> Clustering {
    let f = setup.features;
    let n = f.len();
    let q = setup.global.0;
    let w = [q[0], q[1], q[2], q[3]];
    let distance = |a: &[f64; 4], b: &[f64; 4]| distance2::<WRAPPED>(a, b, &w).sqrt();
    let slack = 1.0 + tol::HAMERLY_SLACK;
    let mut centres = circle_centres(f, k);
    let mut drift = vec![Drift::default(); k];
    let mut near = vec![(0.0, 0u32); k * k.saturating_sub(1)];
    sort_neighbours(&centres, &mut near, &mut drift, distance);
    // Initial assignment: the nearest centre of a cell is often its grid
    // predecessor's, which makes the pruned scan short.
    // Per cell: `[upper, lower]` bounds side by side (one address per cell).
    let (mut labels, mut bounds) = (vec![0u32; n], vec![[0.0f64; 2]; n]);
    let mut previous = 0u32;
    for (i, x) in f.x.iter().enumerate() {
        let a = previous as usize;
        let d2a = distance2::<WRAPPED>(x, &centres[a], &w);
        let (best, u, l) = nearest_from::<WRAPPED>(x, a, (d2a, d2a.sqrt()), &centres, &near, &w, slack);
        labels[i] = best;
        bounds[i] = [u, l];
        previous = best;
    }
    let mut stats = Stats::batch(setup, &labels, k);
    let mut moved_centres = centres.clone();
    let mut check = vec![0u32; n];
    let mut scan = vec![(0u32, 0.0f64, 0.0f64); n];
    let (mut iterations, mut converged) = (0, false);
    for it in 1..=max_iterations {
        iterations = it;
        means_into(&stats, &centres, setup.mode, &mut moved_centres);
        for c in 0..k {
            drift[c].shift = distance(&centres[c], &moved_centres[c]);
        }
        std::mem::swap(&mut centres, &mut moved_centres);
        sort_neighbours(&centres, &mut near, &mut drift, distance);
        // Largest and second-largest centre shifts.
        let (mut top, mut top_index, mut second) = (0.0f64, usize::MAX, 0.0f64);
        for (c, d) in drift.iter().enumerate() {
            let s = d.shift;
            if s > top {
                second = top;
                top = s;
                top_index = c;
            } else if s > second {
                second = s;
            }
        }
        for (c, d) in drift.iter_mut().enumerate() {
            d.others = if c == top_index { second } else { top };
        }
        let mut moved = false;
        let (xs, labels, bounds) = (&f.x[..n], &mut labels[..n], &mut bounds[..n]);
        // Pass 1, branch-free: every cell's bounds after the centres' moves, and
        // the list of the cells whose bounds fail (a data-dependent branch here
        // would mispredict at every cluster border).
        let mut failing = 0usize;
        for i in 0..n {
            let a = labels[i] as usize;
            let Drift { shift, others, half_gap } = drift[a];
            let [upper, lower] = bounds[i];
            let u = upper + shift;
            let l = lower - others;
            // max(half_gap, l) without `f64::max`'s NaN handling (no NaN here).
            let bound = if half_gap > l { half_gap } else { l };
            bounds[i] = [u, l];
            #[allow(clippy::cast_possible_truncation)] // n < u32::MAX
            {
                check[failing] = i as u32;
            }
            failing += usize::from(u * slack >= bound); // no NaN here
        }
        // Pass 2, branch-free: the exact distance to the own centre of every
        // failing cell tightens its upper bound; the cells still failing are
        // listed again (in increasing order) with that distance.
        let mut scans = 0usize;
        for &cell in &check[..failing] {
            let i = cell as usize;
            let a = labels[i] as usize;
            let l = bounds[i][1];
            let half_gap = drift[a].half_gap;
            let bound = if half_gap > l { half_gap } else { l };
            let d2a = distance2::<WRAPPED>(&xs[i], &centres[a], &w);
            let u = d2a.sqrt();
            bounds[i] = [u, l];
            scan[scans] = (cell, d2a, u);
            scans += usize::from(u * slack >= bound);
        }
        // Pass 3: the scans, in increasing cell order (the statistics see the
        // same sequence of moves as the plain sweep).
        for &(i, d2a, u) in &scan[..scans] {
            let i = i as usize;
            let a = labels[i] as usize;
            let (best, u, l) = nearest_from::<WRAPPED>(&xs[i], a, (d2a, u), &centres, &near, &w, slack);
            bounds[i] = [u, l];
            if best != labels[i] {
                moved = true;
                stats.move_point(setup, i, labels[i], best);
                labels[i] = best;
            }
        }
        if !moved {
            converged = true;
            break;
        }
        if it % tol::BATCH_REFRESH_EVERY == 0 {
            stats = Stats::batch(setup, labels, k);
        }
    }
    let (clusters, _) = compact(&mut labels, k);
    Clustering { labels, clusters, iterations, converged }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::features::Features;
    use scallop_analysis::FeatureVector;

    fn random_features(n: [usize; 2], mut seed: u64, clustered: bool, quantized: bool) -> Features {
        let mut next = || {
            seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut out = Vec::new();
        for a in 0..n[0] {
            for b in 0..n[1] {
                let (u, v) = ((a as f64 + 0.5) / n[0] as f64, (b as f64 + 0.5) / n[1] as f64);
                let (s, t) = if clustered {
                    // Smooth field plus noise: realistic, many near-ties at borders.
                    ((3.0 * u).sin().abs() + 0.05 * next(), (4.0 * v + u).sin() * 1.5 + 0.05 * next())
                } else {
                    (next() * 1.5, (next() - 0.5) * std::f64::consts::PI)
                };
                out.push(FeatureVector { u, v, slope: s, slope_direction: t });
                if quantized {
                    // Coarse values: many cells at exactly equal distances (ties).
                    let q = |x: f64| (x * 4.0).round() / 4.0;
                    let last = out.len() - 1;
                    out[last] = FeatureVector { u: q(u), v: q(v), slope: q(s), slope_direction: q(t) };
                }
            }
        }
        Features::from_grid(n, &out).unwrap()
    }

    #[test]
    fn bounded_equal_plain() {
        for seed in 0..40u64 {
            let features = random_features([17 + (seed as usize % 5), 23], seed, seed % 2 == 0, seed % 4 == 1);
            for mode in [ThetaMode::Wrapped, ThetaMode::Plain] {
                for k in [1, 2, 3, 5, 9] {
                    let omega = [1.0, 0.3 + 0.01 * seed as f64, 0.7, if seed % 3 == 0 { 0.0 } else { 1.0 }];
                    let setup = Setup::new(&features, omega, Metric::Euclidean, mode);
                    let a = kmeans_plain(&setup, k, 300);
                    let b = kmeans_bounded(&setup, k, 300);
                    assert_eq!(a, b, "Hamerly: seed {seed} k {k} {mode:?}");
                }
            }
        }
    }
}
