//! RPCL (finishing.md 11.7): seeded and deterministic; rivals are driven away.

mod common;

use common::grid;
use scallop_cluster::{ClusterParams, Method, RpclParams, cluster};

/// Two blobs and K = 3: the third centre is the rival of the winning one and is
/// pushed out; it ends with no cell (dropped), leaving exactly the two blobs.
#[test]
fn rival_is_driven_away() {
    let features = grid([30, 30], |u, v| {
        let noise = 0.02 * (37.0 * u * v).sin();
        if u < 0.5 { (0.2 + noise, 0.4 + noise) } else { (1.3 + noise, -1.1 + noise) }
    });
    let omega = [0.0, 0.0, 1.0, 1.0];
    let rpcl = cluster(&features, &ClusterParams { k: 3, omega, method: Method::Rpcl, ..Default::default() }).unwrap();
    assert_eq!(rpcl.clusters, 2, "RPCL keeps only the two blobs");
    for (i, &l) in rpcl.labels.iter().enumerate() {
        assert_eq!(l == rpcl.labels[0], i / 30 < 15, "cell {i}");
    }
    // Without the rival penalty (alpha_rival = 0) the extra centre is not expelled.
    let no_rival = ClusterParams {
        k: 3,
        omega,
        method: Method::Rpcl,
        rpcl: RpclParams { alpha_rival: 0.0, ..Default::default() },
        ..Default::default()
    };
    assert_eq!(cluster(&features, &no_rival).unwrap().clusters, 3);
}

/// Same seed, same labels; runs stop before the cap with the default tolerances.
#[test]
fn seeded_runs_repeat() {
    let features = common::random_grid([25, 25], 5);
    for seed in [0, 1, 99] {
        let params = ClusterParams { k: 6, method: Method::Rpcl, seed, ..Default::default() };
        let a = cluster(&features, &params).unwrap();
        let b = cluster(&features, &params).unwrap();
        assert_eq!(a, b);
        assert!(a.converged && a.iterations < params.max_iterations);
    }
}
