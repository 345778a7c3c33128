//! Prints ASCII maps of the clusters and zones of a built-in surface.
//!
//! `cargo run --release -p scallop-cluster --example zones -- [choi|rubio] [K] [N] [STEP] [OMEGA]`
//! (defaults: choi, K = 3, an N x N = 80 x 80 grid, every STEP = 2nd cell printed,
//! OMEGA = `1,1,1,1`). K-means, (weighted) Euclidean metric, wrapped theta. Rows go from v = 1 (top) to
//! v = 0, columns from u = 0 (left) to u = 1. Cluster map: digits; zone map:
//! letters (zone 0 = 'A').

use scallop_analysis::{GridOptions, sample_patch};
use scallop_cluster::{ClusterParams, Features, NO_LABEL, partition};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let name = args.get(1).map_or("choi", String::as_str);
    let k: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(3);
    let n: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(80);
    let step: usize = args.get(4).and_then(|s| s.parse().ok()).unwrap_or(2).max(1);
    let mut omega = [1.0; 4];
    if let Some(list) = args.get(5) {
        for (w, text) in omega.iter_mut().zip(list.split(',')) {
            *w = text.trim().parse().unwrap_or(f64::NAN);
        }
    }
    let Some(set) = scallop_surface::builtin(name) else {
        eprintln!("unknown surface {name}: use choi or rubio");
        std::process::exit(2);
    };
    let samples = match sample_patch(&set.patches()[0], &GridOptions { cells_u: n, cells_v: n }) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    let result =
        Features::from_samples(&samples).and_then(|f| partition(&f, &ClusterParams { k, omega, ..Default::default() }));
    let p = match result {
        Ok(p) => p,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(1);
        }
    };
    println!(
        "{name}: {n} x {n} cells, K-means Euclidean, K = {k}, omega = {omega:?}: {} clusters, {} zones, {} iterations (converged: {})",
        p.clusters,
        p.zone_count(),
        p.iterations,
        p.converged
    );
    let map = |labels: &[u32], glyph: &dyn Fn(u32) -> char| {
        for b in (0..n).rev().step_by(step) {
            let row: String = (0..n)
                .step_by(step)
                .map(|a| {
                    let l = labels[a * n + b];
                    if l == NO_LABEL { ' ' } else { glyph(l) }
                })
                .collect();
            println!("  {row}");
        }
    };
    println!("clusters (digit = cluster), v up, u right:");
    map(&p.cluster_of_cell, &|l| char::from_digit(l % 10, 10).unwrap_or('?'));
    println!("zones (letter = zone):");
    let letters: Vec<char> = ('A'..='Z').chain('a'..='z').collect();
    map(&p.zone_of_cell, &|l| letters[l as usize % letters.len()]);
    println!("zone cluster cells   u-range      v-range      mean s  mean theta  PCA dir  mu~");
    for (z, zone) in p.zones.iter().enumerate() {
        let (mut lo, mut hi) = ([n, n], [0, 0]);
        for &c in &zone.cells {
            let (a, b) = (c as usize / n, c as usize % n);
            lo = [lo[0].min(a), lo[1].min(b)];
            hi = [hi[0].max(a), hi[1].max(b)];
        }
        let range = |l: usize, h: usize| format!("{:.2}-{:.2}", l as f64 / n as f64, (h + 1) as f64 / n as f64);
        let (dir, mu) = zone
            .geometry
            .map_or((f64::NAN, f64::NAN), |g| (g.pca.principal_direction().to_degrees(), g.pca.shape_factor()));
        println!(
            "{:>4} {:>7} {:>5}   {:<11}  {:<11}  {:>5.1}°  {:>8.1}°  {:>6.1}°  {:.2}",
            letters[z % letters.len()],
            zone.cluster,
            zone.len(),
            range(lo[0], hi[0]),
            range(lo[1], hi[1]),
            zone.feature_mean.slope.to_degrees(),
            zone.feature_mean.slope_direction.to_degrees(),
            dir,
            mu
        );
    }
}
