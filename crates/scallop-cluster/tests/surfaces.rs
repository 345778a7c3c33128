//! Partitions of the Choi and Rubio surfaces (80 x 80, K-means, Euclidean, K = 3,
//! omega = 1; finishing.md 11, docs/validation.md): zones are exactly the
//! 4-connected components of the clusters, zone records match an independent
//! computation, K-means ends at a fixed point, and the mirror symmetry of the Choi
//! surface carries over to its zones.

mod common;

use std::collections::HashMap;

use scallop_analysis::{GridOptions, Moments, sample_patch};
use scallop_cluster::{ClusterParams, Features, Metric, NO_LABEL, Partition, ThetaMode, partition};

fn features(name: &str, n: usize) -> Features {
    let set = scallop_surface::builtin(name).expect("built-in surface");
    let samples = sample_patch(&set.patches()[0], &GridOptions { cells_u: n, cells_v: n }).expect("grid");
    Features::from_samples(&samples).expect("grid samples")
}

/// Zones are connected, cover the grid once, and two zones of one cluster never touch.
fn check_zones(p: &Partition) {
    let [nu, nv] = p.grid;
    let mut seen = vec![false; nu * nv];
    for (z, zone) in p.zones.iter().enumerate() {
        assert!(!zone.is_empty());
        assert_eq!(p.zone_cluster[z], zone.cluster);
        // Flood inside the zone from its first cell reaches all of its cells.
        let members: std::collections::HashSet<usize> = zone.cells.iter().map(|&c| c as usize).collect();
        let mut reached = std::collections::HashSet::from([zone.cells[0] as usize]);
        let mut stack = vec![zone.cells[0] as usize];
        while let Some(c) = stack.pop() {
            let (a, b) = (c / nv, c % nv);
            let mut next = vec![];
            if a > 0 {
                next.push(c - nv);
            }
            if a + 1 < nu {
                next.push(c + nv);
            }
            if b > 0 {
                next.push(c - 1);
            }
            if b + 1 < nv {
                next.push(c + 1);
            }
            for m in next {
                if members.contains(&m) && reached.insert(m) {
                    stack.push(m);
                }
            }
        }
        assert_eq!(reached.len(), zone.len(), "zone {z} is connected");
        for &c in &zone.cells {
            let c = c as usize;
            assert!(!seen[c]);
            seen[c] = true;
            assert_eq!(p.zone_of_cell[c] as usize, z);
            assert_eq!(p.cluster_of_cell[c], zone.cluster);
        }
    }
    for (c, &s) in seen.iter().enumerate() {
        assert_eq!(s, p.cluster_of_cell[c] != NO_LABEL, "cell {c}: in a zone exactly when not masked");
    }
    for c in 0..nu * nv {
        let (a, b) = (c / nv, c % nv);
        for m in [(a + 1 < nu).then(|| c + nv), (b + 1 < nv).then(|| c + 1)].into_iter().flatten() {
            if p.cluster_of_cell[c] != NO_LABEL && p.cluster_of_cell[m] == p.cluster_of_cell[c] {
                assert_eq!(p.zone_of_cell[m], p.zone_of_cell[c], "adjacent cells of one cluster share a zone");
            }
        }
    }
}

#[test]
fn choi_and_rubio_zones() {
    for name in ["choi", "rubio"] {
        let f = features(name, 80);
        let params = ClusterParams { k: 3, omega: [1.0; 4], metric: Metric::Euclidean, ..Default::default() };
        let p = partition(&f, &params).unwrap();
        assert!(p.converged && p.iterations < params.max_iterations, "{name}");
        assert_eq!(p.clusters, 3, "{name}");
        check_zones(&p);
        // K-means fixed point on the real surface (cells = points on a full grid).
        common::assert_fixed_point(&f, &p.cluster_of_cell, p.clusters, ThetaMode::Wrapped, &{
            let mut m = [[0.0; 4]; 4];
            (0..4).for_each(|k| m[k][k] = 1.0);
            m
        });
        // Cluster means (the optimiser's initial Theta_k) against an independent computation.
        let independent = common::means(&f, &p.cluster_of_cell, p.clusters, ThetaMode::Wrapped);
        for (m, e) in p.cluster_means.iter().zip(&independent) {
            for (a, b) in [m.u, m.v, m.slope, m.slope_direction].iter().zip(e) {
                assert!((a - b).abs() < 1e-12, "{name}: cluster mean {a} vs {b}");
            }
        }
        // Zone records against an independent computation.
        let (points, normals) = f.geometry().unwrap();
        for zone in &p.zones {
            let cells: Vec<usize> = zone.cells.iter().map(|&c| c as usize).collect();
            let labels: Vec<u32> = (0..f.len()).map(|i| u32::from(!cells.contains(&i))).collect();
            let mean = common::means(&f, &labels, 2, ThetaMode::Wrapped)[0];
            let fm = zone.feature_mean;
            for (a, b) in [fm.u, fm.v, fm.slope, fm.slope_direction].iter().zip(mean) {
                assert!((a - b).abs() < 1e-12, "{name}: zone mean {a} vs {b}");
            }
            let g = zone.geometry.unwrap();
            let batch = Moments::of_points(&cells.iter().map(|&i| points[i]).collect::<Vec<_>>());
            assert_eq!(g.moments.count(), zone.len());
            assert!((g.moments.mean() - batch.mean()).norm() < 1e-9);
            assert!((g.moments.covariance() - batch.covariance()).norm() < 1e-9 * (1.0 + batch.covariance().norm()));
            let d: [f64; 2] = [0, 1].map(|k| cells.iter().map(|&i| normals[i][k]).sum::<f64>() / cells.len() as f64);
            assert!((g.mean_slope_vector[0] - d[0]).abs() < 1e-12 && (g.mean_slope_vector[1] - d[1]).abs() < 1e-12);
            let l = g.pca.eigenvalues;
            assert!(l[0] >= l[1] && l[1] >= l[2] && l[2] >= 0.0);
        }
    }
}

/// The Choi surface is symmetric under `v -> 1 - v` (its control net is mirrored
/// in y), and so is the circle initialisation for K = 3: the cluster map must be
/// mirrored too, up to a relabelling (a handful of cells on a boundary may differ
/// by rounding).
#[test]
fn choi_partition_is_mirror_symmetric() {
    let f = features("choi", 80);
    let p = partition(&f, &ClusterParams::default()).unwrap();
    let n = 80;
    let mut votes: HashMap<(u32, u32), usize> = HashMap::new();
    for a in 0..n {
        for b in 0..n {
            let (x, y) = (p.cluster_of_cell[a * n + b], p.cluster_of_cell[a * n + n - 1 - b]);
            assert_ne!(x, NO_LABEL);
            *votes.entry((x, y)).or_default() += 1;
        }
    }
    // The majority partner of each cluster defines the relabelling.
    let mut agree = 0;
    for c in 0..p.clusters as u32 {
        agree += votes.iter().filter(|((x, _), _)| *x == c).map(|(_, &v)| v).max().unwrap_or(0);
    }
    assert!(n * n - agree <= n * n / 200, "{} of {} cells break the mirror symmetry", n * n - agree, n * n);
}

/// A masked stripe `35 <= a < 45` across the Choi grid: masked cells get no
/// label, and no zone crosses the stripe (a cluster on both sides is two zones).
#[test]
fn masked_stripe_splits_zones() {
    let set = scallop_surface::builtin("choi").unwrap();
    let grid = GridOptions { cells_u: 80, cells_v: 80 };
    let samples =
        scallop_analysis::sample_patch_masked(&set.patches()[0], &grid, |a, _| !(35..45).contains(&a)).unwrap();
    let f = Features::from_samples(&samples).unwrap();
    assert_eq!((f.len(), f.cell_count()), (5600, 6400));
    let p = partition(&f, &ClusterParams { k: 2, ..Default::default() }).unwrap();
    for a in 0..80 {
        for b in 0..80 {
            let masked = (35..45).contains(&a);
            assert_eq!(p.cluster_of_cell[a * 80 + b] == NO_LABEL, masked);
            assert_eq!(p.zone_of_cell[a * 80 + b] == NO_LABEL, masked);
        }
    }
    for zone in &p.zones {
        let left = zone.cells.iter().filter(|&&c| (c as usize / 80) < 35).count();
        assert!(left == 0 || left == zone.len(), "a zone crosses the masked stripe");
    }
    assert_eq!(p.zones.iter().map(|z| z.len()).sum::<usize>(), 5600);
    check_zones(&p);
    let pairs: std::collections::HashSet<(u32, bool)> =
        p.zones.iter().map(|z| (z.cluster, (z.cells[0] as usize / 80) < 35)).collect();
    assert!(p.zone_count() >= pairs.len() && p.zone_count() >= 2, "{} zones", p.zone_count());
}
