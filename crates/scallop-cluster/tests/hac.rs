//! Ward hierarchical clustering (finishing.md 11.8): the nearest-neighbour chain
//! equals a brute-force O(n^3) Lance-Williams Ward on small random sets.

mod common;

use common::canonical;
use proptest::prelude::*;
use scallop_cluster::{ClusterParams, HacCut, Method, cluster, cut_dendrogram, largest_gap_clusters, ward_linkage};

/// Brute force: full matrix initialised with `1/2 |x_i - x_j|^2`, merge the closest
/// pair, update by the Lance-Williams formula (3.1). Returns the merge heights in
/// merge order and the partition (labels) after each number of merges.
fn brute_force(points: &[Vec<f64>]) -> (Vec<f64>, Vec<Vec<usize>>) {
    let n = points.len();
    let mut d = vec![vec![f64::INFINITY; n]; n];
    for i in 0..n {
        for j in 0..n {
            if i != j {
                d[i][j] = 0.5 * points[i].iter().zip(&points[j]).map(|(a, b)| (a - b) * (a - b)).sum::<f64>();
            }
        }
    }
    let mut size = vec![1usize; n];
    let mut alive = vec![true; n];
    let mut label: Vec<usize> = (0..n).collect();
    let (mut heights, mut partitions) = (Vec::new(), vec![label.clone()]);
    for _ in 1..n {
        let mut best = (f64::INFINITY, 0, 0);
        for i in 0..n {
            for j in i + 1..n {
                if alive[i] && alive[j] && d[i][j] < best.0 {
                    best = (d[i][j], i, j);
                }
            }
        }
        let (h, i, j) = best;
        heights.push(h);
        for k in 0..n {
            if alive[k] && k != i && k != j {
                let (ni, nj, nk) = (size[i] as f64, size[j] as f64, size[k] as f64);
                let v = ((ni + nk) * d[i][k] + (nj + nk) * d[j][k] - nk * d[i][j]) / (ni + nj + nk);
                d[i][k] = v;
                d[k][i] = v;
            }
        }
        alive[j] = false;
        size[i] += size[j];
        for l in label.iter_mut() {
            if *l == j {
                *l = i;
            }
        }
        partitions.push(label.clone());
    }
    (heights, partitions)
}

fn canonical_usize(labels: &[usize]) -> Vec<u32> {
    canonical(&labels.iter().map(|&l| l as u32).collect::<Vec<_>>())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn chain_equals_brute_force(points in prop::collection::vec(prop::collection::vec(-10.0f64..10.0, 3), 2..40)) {
        let n = points.len();
        let flat: Vec<f64> = points.iter().flatten().copied().collect();
        let merges = ward_linkage(&flat, 3);
        prop_assert_eq!(merges.len(), n - 1);
        let (mut heights, partitions) = brute_force(&points);
        // Both are non-decreasing for Ward (reducible); compare sorted to be safe.
        heights.sort_by(f64::total_cmp);
        for (m, h) in merges.iter().zip(&heights) {
            prop_assert!((m.height - h).abs() <= 1e-9 * (1.0 + h.abs()), "{} vs {}", m.height, h);
        }
        prop_assert_eq!(merges.last().unwrap().size, n);
        // Same flat partitions at every level (random reals: no ties).
        for clusters in 1..=n {
            let ours = cut_dendrogram(n, &merges, clusters);
            prop_assert_eq!(ours.iter().max().map(|&l| l as usize + 1), Some(clusters));
            prop_assert_eq!(canonical(&ours), canonical_usize(&partitions[n - clusters]));
        }
    }
}

/// Three tight groups at the corners of an equilateral triangle: the largest gap
/// between merge heights is the first merge across groups, so the cut keeps the
/// three groups (Ward heights: 5 D^2 for both cross merges of 10-point groups).
#[test]
fn largest_gap_finds_separated_groups() {
    let corners = [[0.0, 0.0], [100.0, 0.0], [50.0, 50.0 * 3f64.sqrt()]];
    let mut flat = Vec::new();
    for (g, c) in corners.iter().enumerate() {
        for i in 0..10 {
            flat.extend_from_slice(&[c[0] + 0.1 * i as f64, c[1] + 0.01 * (g * i) as f64]);
        }
    }
    let merges = ward_linkage(&flat, 2);
    assert_eq!(largest_gap_clusters(30, &merges, 2, usize::MAX), 3);
    assert_eq!(largest_gap_clusters(30, &merges, 2, 2), 2);
    let labels = cut_dendrogram(30, &merges, 3);
    for (i, &l) in labels.iter().enumerate() {
        assert_eq!(l as usize, i / 10);
    }
}

/// HAC through the public entry point, exact cluster count and gap cut.
#[test]
fn hac_method_on_features() {
    let features = common::grid([12, 12], |u, _| if u < 0.5 { (0.1, 0.2) } else { (1.4, -1.2) });
    let exact = cluster(
        &features,
        &ClusterParams { k: 4, method: Method::Hac { cut: HacCut::Clusters }, ..Default::default() },
    )
    .unwrap();
    assert_eq!(exact.clusters, 4);
    let gap =
        cluster(&features, &ClusterParams { method: Method::Hac { cut: HacCut::default() }, ..Default::default() })
            .unwrap();
    assert_eq!(gap.clusters, 2);
    for (i, &l) in gap.labels.iter().enumerate() {
        assert_eq!(l, u32::from(i / 12 >= 6));
    }
}
