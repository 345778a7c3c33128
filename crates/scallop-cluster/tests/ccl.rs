//! Connected components (finishing.md 11.9, acceptance A13): equal to an
//! independent labelling on random grids, same label order as the scan, and no
//! stack overflow on a 1000 x 1000 grid.

use std::collections::VecDeque;

use proptest::prelude::*;
use scallop_cluster::{NO_LABEL, connected_components};

/// Independent labelling: breadth-first search with a queue, started from each
/// unlabelled cell in scan order.
fn bfs_labels(grid: [usize; 2], labels: &[u32]) -> (Vec<u32>, usize) {
    let [nu, nv] = grid;
    let mut out = vec![NO_LABEL; nu * nv];
    let mut count = 0u32;
    for a in 0..nu {
        for b in 0..nv {
            if labels[a * nv + b] == NO_LABEL || out[a * nv + b] != NO_LABEL {
                continue;
            }
            let mut queue = VecDeque::from([(a, b)]);
            out[a * nv + b] = count;
            while let Some((x, y)) = queue.pop_front() {
                let neighbours = [(x.wrapping_sub(1), y), (x + 1, y), (x, y.wrapping_sub(1)), (x, y + 1)];
                for (p, q) in neighbours {
                    if p < nu && q < nv && out[p * nv + q] == NO_LABEL && labels[p * nv + q] == labels[x * nv + y] {
                        out[p * nv + q] = count;
                        queue.push_back((p, q));
                    }
                }
            }
            count += 1;
        }
    }
    (out, count as usize)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn equals_bfs(nu in 1usize..30, nv in 1usize..30, clusters in 1u32..5, masked in 0u32..3,
                  seed in any::<u64>()) {
        let mut state = seed;
        let labels: Vec<u32> = (0..nu * nv)
            .map(|_| {
                state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
                let r = ((state >> 33) % u64::from(clusters + masked)) as u32;
                if r >= clusters { NO_LABEL } else { r }
            })
            .collect();
        let (zones, count) = connected_components([nu, nv], &labels).unwrap();
        let (expected, expected_count) = bfs_labels([nu, nv], &labels);
        prop_assert_eq!(count, expected_count);
        prop_assert_eq!(zones, expected);
    }
}

/// One cluster over 10^6 cells (the deepest flood fill) and a serpentine corridor
/// (a single component 500,000 cells long), on a thread with a 64 KiB stack: a
/// recursive labelling would overflow it.
#[test]
fn million_cells_without_recursion() {
    let worker = std::thread::Builder::new().stack_size(64 * 1024).spawn(|| {
        let n = 1000;
        let (zones, count) = connected_components([n, n], &vec![0u32; n * n]).unwrap();
        assert_eq!(count, 1);
        assert!(zones.iter().all(|&z| z == 0));
        // Rows of cluster 1 open at alternate ends: one long corridor of cluster 0.
        let serpentine: Vec<u32> = (0..n * n)
            .map(|i| {
                let (a, b) = (i / n, i % n);
                let wall = a % 2 == 1 && if a % 4 == 1 { b != n - 1 } else { b != 0 };
                u32::from(wall)
            })
            .collect();
        let (zones, count) = connected_components([n, n], &serpentine).unwrap();
        let (expected, expected_count) = bfs_labels([n, n], &serpentine);
        assert_eq!(count, expected_count);
        assert_eq!(zones, expected);
        // The corridor is one zone; each wall row is its own zone.
        assert_eq!(count, 1 + n / 2);
    });
    worker.unwrap().join().unwrap();
}

#[test]
fn wrong_length_is_an_error() {
    let err = connected_components([3, 3], &[0; 8]).unwrap_err();
    assert!(err.to_string().contains("expected 9"), "{err}");
}
