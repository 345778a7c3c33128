//! Hierarchical ascending clustering with Ward linkage (finishing.md 11.8, Alg. 3
//! with the \[CORR\] singleton distances and cut rule).
//!
//! Nearest-neighbour chain on centroids with the closed-form Ward distance
//! `D(a, b) = n_a n_b / (n_a + n_b) |c_a - c_b|^2` (the increase of the within-cluster
//! sum of squares, equal to the Lance-Williams recursion (3.1) started from
//! `1/2 |x_i - x_j|^2`): O(n) memory, O(n^2) time. Ward is reducible, so the chain
//! finds exactly the merges of the greedy algorithm (up to ties); heights are
//! sorted at the end (stable) and cluster ids relabelled by union-find.

use serde::{Deserialize, Serialize};

/// One merge of a dendrogram, in the convention of SciPy's linkage matrix:
/// points are clusters `0..n`, merge `m` (in increasing height) creates cluster
/// `n + m`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Merge {
    /// The smaller id of the two merged clusters.
    pub left: usize,
    /// The larger id.
    pub right: usize,
    /// Ward merge height `n_a n_b / (n_a + n_b) |c_a - c_b|^2` (the increase of the
    /// within-cluster sum of squares; SciPy reports `sqrt(2 height)`).
    pub height: f64,
    /// Number of points of the new cluster.
    pub size: usize,
}

/// Ward dendrogram of `points` (`n` points of `dim` coordinates, flat, point
/// after point), merges sorted by height (stable). Empty when `n <= 1` or `dim = 0`.
///
/// ```
/// // Two pairs far apart: the pairs merge first, at height 1/2 |x_i - x_j|^2.
/// let merges = scallop_cluster::ward_linkage(&[0.0, 1.0, 10.0, 11.0], 1);
/// assert_eq!(merges.len(), 3);
/// assert_eq!((merges[0].height, merges[1].height), (0.5, 0.5));
/// assert_eq!(merges[2].height, 100.0); // 2 * 2 / 4 * 10^2
/// ```
#[must_use]
pub fn ward_linkage(points: &[f64], dim: usize) -> Vec<Merge> {
    if dim == 0 {
        return Vec::new();
    }
    let n = points.len() / dim;
    if n <= 1 {
        return Vec::new();
    }
    let mut centroid = points[..n * dim].to_vec();
    let mut size = vec![1usize; n];
    // Current cluster id of each slot (point ids, then n + raw merge index).
    let mut id: Vec<usize> = (0..n).collect();
    // Active slots, increasing (ties go to the lowest slot).
    let mut active: Vec<usize> = (0..n).collect();
    let mut chain: Vec<usize> = Vec::with_capacity(n);
    // Raw merges (ids at the time of the merge) in creation order.
    let mut raw: Vec<(usize, usize, f64, usize)> = Vec::with_capacity(n - 1);
    let distance = |centroid: &[f64], size: &[usize], a: usize, b: usize| -> f64 {
        let (ca, cb) = (&centroid[a * dim..(a + 1) * dim], &centroid[b * dim..(b + 1) * dim]);
        let mut d2 = 0.0;
        for (x, y) in ca.iter().zip(cb) {
            d2 += (x - y) * (x - y);
        }
        let (na, nb) = (size[a] as f64, size[b] as f64);
        na * nb / (na + nb) * d2
    };
    while active.len() > 1 {
        if chain.is_empty() {
            chain.push(active[0]);
        }
        let a = chain[chain.len() - 1];
        let mut best = (f64::INFINITY, usize::MAX);
        for &c in &active {
            if c != a {
                let d = distance(&centroid, &size, a, c);
                if d < best.0 || best.1 == usize::MAX {
                    best = (d, c);
                }
            }
        }
        let mut b = best.1;
        if chain.len() >= 2 {
            let previous = chain[chain.len() - 2];
            if distance(&centroid, &size, a, previous) <= best.0 {
                b = previous;
            }
        }
        if chain.len() >= 2 && b == chain[chain.len() - 2] {
            chain.truncate(chain.len() - 2);
            let height = distance(&centroid, &size, a, b);
            let (keep, drop) = (a.min(b), a.max(b));
            let (nk, nd) = (size[keep] as f64, size[drop] as f64);
            for j in 0..dim {
                let merged = (nk * centroid[keep * dim + j] + nd * centroid[drop * dim + j]) / (nk + nd);
                centroid[keep * dim + j] = merged;
            }
            let new_size = size[keep] + size[drop];
            raw.push((id[keep], id[drop], height, new_size));
            size[keep] = new_size;
            id[keep] = n + raw.len() - 1;
            if let Ok(pos) = active.binary_search(&drop) {
                active.remove(pos);
            }
        } else {
            chain.push(b);
        }
    }
    relabel(n, raw)
}

/// Sorts raw merges by height (stable) and renames cluster ids so that merge `m` of
/// the sorted list creates cluster `n + m`.
fn relabel(n: usize, raw: Vec<(usize, usize, f64, usize)>) -> Vec<Merge> {
    let mut order: Vec<usize> = (0..raw.len()).collect();
    order.sort_by(|&x, &y| raw[x].2.total_cmp(&raw[y].2));
    // Union-find over points: a raw cluster id -> one of its points.
    let mut representative: Vec<usize> = (0..n).collect();
    representative.extend(std::iter::repeat_n(0, raw.len()));
    for (m, r) in raw.iter().enumerate() {
        representative[n + m] = representative[r.0];
    }
    let mut uf = UnionFind::new(n);
    // Current public id of each union-find root.
    let mut public: Vec<usize> = (0..n).collect();
    order
        .iter()
        .enumerate()
        .map(|(m, &r)| {
            let (a, b, height, size) = raw[r];
            let (ra, rb) = (uf.find(representative[a]), uf.find(representative[b]));
            let (ia, ib) = (public[ra], public[rb]);
            let root = uf.union(ra, rb);
            public[root] = n + m;
            Merge { left: ia.min(ib), right: ia.max(ib), height, size }
        })
        .collect()
}

/// Flat clustering after the first `n - clusters` merges of a sorted dendrogram:
/// labels `0..clusters` numbered in order of first appearance (point order).
/// `clusters` is clamped to `[1, n]`.
#[must_use]
pub fn cut_dendrogram(n: usize, merges: &[Merge], clusters: usize) -> Vec<u32> {
    let clusters = clusters.clamp(1, n.max(1));
    let mut representative: Vec<usize> = (0..n).collect();
    let mut uf = UnionFind::new(n);
    for m in merges.iter().take(n.saturating_sub(clusters)) {
        let (a, b) = (representative[m.left], representative[m.right]);
        uf.union(a, b);
        representative.push(a);
    }
    let mut label_of_root = vec![u32::MAX; n];
    let mut next = 0u32;
    (0..n)
        .map(|i| {
            let r = uf.find(i);
            if label_of_root[r] == u32::MAX {
                label_of_root[r] = next;
                next += 1;
            }
            label_of_root[r]
        })
        .collect()
}

/// The cluster count chosen by the largest gap between successive merge heights
/// (finishing.md 11.8 \[CORR\]): merge `m` (1-based, sorted) has gap
/// `h_m - h_(m-1)`; the partition just before the merge with the largest gap has
/// `n - m + 1` clusters. Only counts in `[min_clusters, max_clusters]` (and
/// `m >= 2`) compete; first (most clusters) on ties. `min_clusters` when no merge
/// qualifies.
#[must_use]
pub fn largest_gap_clusters(n: usize, merges: &[Merge], min_clusters: usize, max_clusters: usize) -> usize {
    let mut best: Option<(f64, usize)> = None;
    for m in 2..=merges.len() {
        let clusters = n + 1 - m;
        if clusters < min_clusters || clusters > max_clusters {
            continue;
        }
        let gap = merges[m - 1].height - merges[m - 2].height;
        if best.is_none_or(|(g, _)| gap > g) {
            best = Some((gap, clusters));
        }
    }
    best.map_or(min_clusters.clamp(1, n.max(1)), |(_, c)| c)
}

/// Union-find with path halving and union by size.
struct UnionFind {
    parent: Vec<usize>,
    size: Vec<usize>,
}

impl UnionFind {
    fn new(n: usize) -> UnionFind {
        UnionFind { parent: (0..n).collect(), size: vec![1; n] }
    }

    fn find(&mut self, mut x: usize) -> usize {
        while self.parent[x] != x {
            self.parent[x] = self.parent[self.parent[x]];
            x = self.parent[x];
        }
        x
    }

    /// Joins the sets of roots-or-members `a`, `b`; returns the new root.
    fn union(&mut self, a: usize, b: usize) -> usize {
        let (mut ra, mut rb) = (self.find(a), self.find(b));
        if ra == rb {
            return ra;
        }
        if self.size[ra] < self.size[rb] {
            std::mem::swap(&mut ra, &mut rb);
        }
        self.parent[rb] = ra;
        self.size[ra] += self.size[rb];
        ra
    }
}
