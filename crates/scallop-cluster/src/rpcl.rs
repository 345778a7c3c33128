//! RPCL, rival penalised competitive learning (finishing.md 11.7, Alg. 2 with the
//! \[CORR\] rival `argmin_{j != c}` and the project's \[DECISION\] settings).

use crate::engine::{Frozen, Setup, Stats, circle_centres, compact};
use crate::features::{ThetaMode, delta, fold_direction};
use crate::partition::{Clustering, RpclParams};
use crate::tol;
use scallop_geom::rng::SplitMix64;

/// RPCL with `k` centres, at most `max_sweeps` sweeps, the seeded permutation of
/// `seed`.
pub(crate) fn rpcl(setup: &Setup, k: usize, max_sweeps: usize, params: &RpclParams, seed: u64) -> Clustering {
    let f = setup.features;
    let n = f.len();
    let wrapped = setup.mode == ThetaMode::Wrapped;
    let start = Frozen::new(setup, circle_centres(f, k), None, false);
    let mut labels = Vec::new();
    start.assign(setup, None, &mut labels);
    let mut centres = start.centres;
    let mut stats = Stats::batch(setup, &labels, k);
    let mut wins = vec![1.0f64; k];
    let mut rng = SplitMix64::new(seed);
    #[allow(clippy::cast_possible_truncation)] // n < u32::MAX (checked by Features)
    let mut order: Vec<u32> = (0..n as u32).collect();
    let mut next = Vec::with_capacity(n);
    let (mut iterations, mut converged) = (0, false);
    let mut gamma_d = vec![0.0; k];
    for t in 0..max_sweeps {
        iterations = t + 1;
        let decay = 1.0 / (1.0 + t as f64);
        let (alpha_c, alpha_r) = (params.alpha_winner * decay, params.alpha_rival * decay);
        rng.shuffle(&mut order);
        // Competitive step on the base metric, per-cluster forms frozen for the sweep.
        let mut compete = Frozen::new(setup, centres, Some((&stats, &labels)), true);
        for &i in &order {
            let x = &f.x[i as usize];
            let total: f64 = wins.iter().sum();
            for (j, g) in gamma_d.iter_mut().enumerate() {
                *g = wins[j] / total * compete.base(x, j, wrapped);
            }
            let winner = argmin(&gamma_d, None);
            move_centre(&mut compete.centres[winner], x, alpha_c, wrapped);
            if k >= 2 {
                let rival = argmin(&gamma_d, Some(winner));
                move_centre(&mut compete.centres[rival], x, -alpha_r, wrapped);
            }
            wins[winner] += 1.0;
        }
        centres = compete.centres;
        // Step 3 (added by the thesis): assign every cell with the full metric.
        let full = Frozen::new(setup, centres, Some((&stats, &labels)), false);
        full.assign(setup, Some(&labels), &mut next);
        centres = full.centres;
        let mut changed = 0usize;
        for (i, (&old, &new)) in labels.iter().zip(&next).enumerate() {
            if old != new {
                changed += 1;
                stats.move_point(setup, i, old, new);
            }
        }
        std::mem::swap(&mut labels, &mut next);
        if iterations % tol::BATCH_REFRESH_EVERY == 0 {
            stats = Stats::batch(setup, &labels, k);
        }
        let rates_small = alpha_c < params.tol_alpha && alpha_r < params.tol_alpha;
        if rates_small || (changed as f64) < params.tol_move * n as f64 {
            converged = true;
            break;
        }
    }
    let (clusters, _) = compact(&mut labels, k);
    Clustering { labels, clusters, iterations, converged }
}

/// Index of the smallest value (lowest index on ties), skipping `skip`.
fn argmin(values: &[f64], skip: Option<usize>) -> usize {
    let mut best = (f64::INFINITY, usize::MAX);
    for (j, &v) in values.iter().enumerate() {
        if Some(j) != skip && (v < best.0 || best.1 == usize::MAX) {
            best = (v, j);
        }
    }
    best.1
}

/// `w <- w + alpha (x - w)` (theta difference per mode, folded back in Wrapped mode).
fn move_centre(w: &mut [f64; 4], x: &[f64; 4], alpha: f64, wrapped: bool) {
    let d = delta(x, w, wrapped);
    for k in 0..4 {
        w[k] += alpha * d[k];
    }
    if wrapped {
        w[3] = fold_direction(w[3]);
    }
}
