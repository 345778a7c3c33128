//! Connected-component labelling of a cluster-label grid (finishing.md 11.9,
//! Alg. 4 with the \[DECISION\] explicit stack): 4-connectivity, no recursion.

use crate::error::ClusterError;
use crate::features::NO_LABEL;

/// Splits the clusters of an `N_u x N_v` label grid into 4-connected components.
///
/// `labels[a * N_v + b]` is the cluster of cell `(a, b)` ([`NO_LABEL`] for a masked
/// cell). Returns the component of every cell (masked cells stay [`NO_LABEL`]) and
/// the number of components. Components are numbered from 0 in scan order (`a`,
/// then `b`) of their first cell. An explicit stack replaces the thesis's
/// recursion, so a 1000 x 1000 grid of one cluster needs no deep call stack.
///
/// ```
/// use scallop_cluster::{connected_components, NO_LABEL};
/// // 3 x 3 grid (rows a): cluster 1 in two pieces split by cluster 0 and a masked cell.
/// let labels = [0, 0, 0,
///               1, 0, 1,
///               1, NO_LABEL, 1];
/// let (zones, count) = connected_components([3, 3], &labels).unwrap();
/// assert_eq!(count, 3);
/// assert_eq!(zones, vec![0, 0, 0, 1, 0, 2, 1, NO_LABEL, 2]);
/// ```
///
/// # Errors
/// [`ClusterError::LengthMismatch`] when `labels.len() != N_u N_v`.
pub fn connected_components(grid: [usize; 2], labels: &[u32]) -> Result<(Vec<u32>, usize), ClusterError> {
    let [nu, nv] = grid;
    let total = nu.saturating_mul(nv);
    if labels.len() != total {
        return Err(ClusterError::LengthMismatch { what: "cluster labels", expected: total, got: labels.len() });
    }
    let mut zones = vec![NO_LABEL; total];
    let mut count = 0usize;
    let mut stack: Vec<usize> = Vec::new();
    for start in 0..total {
        if labels[start] == NO_LABEL || zones[start] != NO_LABEL {
            continue;
        }
        #[allow(clippy::cast_possible_truncation)] // count <= total < u32::MAX (checked by Features)
        let zone = count as u32;
        count += 1;
        let cluster = labels[start];
        zones[start] = zone;
        stack.push(start);
        while let Some(cell) = stack.pop() {
            let (a, b) = (cell / nv, cell % nv);
            let mut visit = |next: usize| {
                if zones[next] == NO_LABEL && labels[next] == cluster {
                    zones[next] = zone;
                    stack.push(next);
                }
            };
            if a > 0 {
                visit(cell - nv);
            }
            if b > 0 {
                visit(cell - 1);
            }
            if a + 1 < nu {
                visit(cell + nv);
            }
            if b + 1 < nv {
                visit(cell + 1);
            }
        }
    }
    Ok((zones, count))
}
