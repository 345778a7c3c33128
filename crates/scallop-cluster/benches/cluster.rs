//! Criterion benchmarks of surface partitioning on the Choi surface, all on one
//! thread (the optimiser runs its K values in parallel, one partition per thread):
//! K-means (K = 3 and 10, Euclidean, omega = 1; `cluster` alone and `partition`
//! with connected components and zone records), RPCL (K = 3), the PCA metric
//! (K = 3), Ward HAC (40 x 40 and 80 x 80) and connected components on a
//! 1000 x 1000 grid. Target: K-means 80 x 80 well under 2 ms (the black box has
//! 5 ms in all). Run: `cargo bench -p scallop-cluster --bench cluster`.

use criterion::{Criterion, criterion_group, criterion_main};
use scallop_analysis::{GridOptions, sample_patch};
use scallop_cluster::{
    ClusterParams, Features, HacCut, Method, Metric, PcaFactor, cluster, connected_components, partition,
};

fn features(n: usize) -> Features {
    let set = scallop_surface::builtin("choi").expect("built-in surface");
    let samples = sample_patch(&set.patches()[0], &GridOptions { cells_u: n, cells_v: n }).expect("grid");
    Features::from_samples(&samples).expect("features")
}

fn bench(c: &mut Criterion) {
    let single = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("pool");
    let f80 = features(80);
    let f40 = features(40);
    let mut group = c.benchmark_group("cluster_choi_80x80");
    for k in [3, 10] {
        let params = ClusterParams { k, ..Default::default() };
        group.bench_function(format!("kmeans_k{k}_cluster"), |b| {
            b.iter(|| single.install(|| cluster(&f80, &params).expect("valid")))
        });
        group.bench_function(format!("kmeans_k{k}_partition"), |b| {
            b.iter(|| single.install(|| partition(&f80, &params).expect("valid")))
        });
    }
    let rpcl = ClusterParams { method: Method::Rpcl, ..Default::default() };
    group.bench_function("rpcl_k3_partition", |b| b.iter(|| single.install(|| partition(&f80, &rpcl).expect("valid"))));
    group.sample_size(10);
    let pca = ClusterParams { metric: Metric::Pca { factor: PcaFactor::OneMinusRhoSquared }, ..Default::default() };
    group.bench_function("kmeans_pca_metric_k3_partition", |b| {
        b.iter(|| single.install(|| partition(&f80, &pca).expect("valid")))
    });
    let hac = ClusterParams { method: Method::Hac { cut: HacCut::default() }, ..Default::default() };
    group.bench_function("hac_ward_partition", |b| b.iter(|| single.install(|| partition(&f80, &hac).expect("valid"))));
    group.bench_function("hac_ward_40x40_partition", |b| {
        b.iter(|| single.install(|| partition(&f40, &hac).expect("valid")))
    });
    group.finish();

    // Connected components of a 1000 x 1000 grid of 8 x 8 checkerboard blocks plus a
    // one-cluster grid (one component of 10^6 cells: the deepest flood).
    let n = 1000;
    let checker: Vec<u32> = (0..n * n).map(|i| (((i / n) / 8 + (i % n) / 8) % 2) as u32).collect();
    let flat = vec![0u32; n * n];
    let mut group = c.benchmark_group("ccl_1000x1000");
    group.sample_size(20);
    group.bench_function("checkerboard_8", |b| b.iter(|| connected_components([n, n], &checker).expect("valid")));
    group.bench_function("one_cluster", |b| b.iter(|| connected_components([n, n], &flat).expect("valid")));
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
