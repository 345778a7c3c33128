//! Curve offsets on a generated support surface at several mesh steps, scalar
//! (Marching Facets) and vectorial (Alg. 1-3): Jousselin 2020, Table 2.1.
//! `cargo bench -p scallop-guides --bench offsets`; the 0.1 mm step (about
//! 430k facets) only with `SCALLOP_BENCH_FINE=1`. Figures in docs/benchmarks.md.
//!
//! What is timed: `offsets/scalar` is one `offset_curves` call (every
//! extraction until the offsets vanish, the curve fields included);
//! `offsets/vectorial` is as many `vectorial_offset` calls (their curve
//! indexes and resampling included). Both start from the same support and
//! limit curve, built outside the timed closures; `support/new` times that
//! set-up apart (`Support::new` on the welded mesh: the triangle BVH both
//! methods query, and the vertex adjacency and incidence the scalar method
//! walks over).

#![allow(clippy::unwrap_used, missing_docs, reason = "a bench: a panic is the failure report")]

#[path = "../tests/common/mod.rs"]
mod common;

use std::hint::black_box;

use common::{grid_surface, p};
use criterion::{BatchSize, BenchmarkId, Criterion, criterion_group, criterion_main};
use scallop_guides::{Curve, Support, VectorialOptions, offset_curves, vectorial_offset};
use scallop_mesh::Polyline3;

const SIDE: f64 = 46.5;
const A_E: f64 = 4.5;

fn height(x: f64, y: f64) -> f64 {
    3.0 * (x / 12.0).sin() * (y / 15.0).sin()
}

/// The support: `z = height(x, y)` over a square of side 46.5 mm in cells of `step`.
fn support(step: f64) -> Support {
    let n = (SIDE / step).round() as usize;
    Support::new(grid_surface(n, n, |u, v| {
        let (x, y) = (SIDE * (u - 0.5), SIDE * (v - 0.5));
        p(x, y, height(x, y))
    }))
}

/// The fixed curve: a loop of radius 21 mm (840 points) lifted onto the surface.
fn limit(s: &Support) -> Curve {
    let pts = (0..840)
        .map(|i| {
            let t = std::f64::consts::TAU * f64::from(i) / 840.0;
            let (x, y) = (21.0 * t.cos(), 21.0 * t.sin());
            s.query().closest_point(&p(x, y, height(x, y))).point
        })
        .collect();
    s.curve(Polyline3::new(pts, true)).unwrap().inside_left()
}

/// The vectorial method iterated `count` times (the scalar method's count).
fn vectorial(s: &Support, c: &Curve, count: usize, step: f64) -> usize {
    let opts = VectorialOptions { d_tol: 0.01, k_max: 20, spacing: step };
    let mut cur = c.clone();
    let mut done = 0;
    for _ in 0..count {
        match vectorial_offset(s, &cur, A_E, &opts) {
            Ok(v) => cur = v.curve,
            Err(_) => break,
        }
        done += 1;
    }
    done
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("offsets");
    group.sample_size(10);
    for step in steps_to_run() {
        let s = support(step);
        let lim = limit(&s);
        let facets = s.mesh().triangles().len();
        let count = offset_curves(&s, std::slice::from_ref(&lim), A_E).unwrap().len();
        group.bench_with_input(BenchmarkId::new("scalar", facets), &step, |b, _| {
            b.iter(|| offset_curves(black_box(&s), std::slice::from_ref(&lim), A_E).unwrap().len());
        });
        group.bench_with_input(BenchmarkId::new("vectorial", facets), &step, |b, &h| {
            b.iter(|| vectorial(black_box(&s), &lim, count, h));
        });
    }
    group.finish();
    let mut group = c.benchmark_group("support");
    group.sample_size(10);
    for step in steps_to_run() {
        let mesh = support(step).mesh().clone();
        group.bench_with_input(BenchmarkId::new("new", mesh.triangles().len()), &mesh, |b, m| {
            b.iter_batched(|| m.clone(), Support::new, BatchSize::LargeInput);
        });
    }
    group.finish();
}

/// The mesh steps (mm): 1, 0.5 and 0.25, and 0.1 with `SCALLOP_BENCH_FINE`.
fn steps_to_run() -> Vec<f64> {
    let mut steps = vec![1.0, 0.5, 0.25];
    if std::env::var_os("SCALLOP_BENCH_FINE").is_some() {
        steps.push(0.1);
    }
    steps
}

criterion_group!(benches, bench);
criterion_main!(benches);
