//! Shared fixtures of the analysis tests.
#![allow(dead_code, clippy::unwrap_used)]

use scallop_analysis::{GridOptions, Samples, sample_patch};
use scallop_geom::Point3;
use scallop_surface::Patch;

/// Asserts `|a - b| <= rel * |b|`.
pub fn assert_rel(a: f64, b: f64, rel: f64, what: &str) {
    assert!((a - b).abs() <= rel * b.abs(), "{what}: {a} vs {b} (relative {} > {rel})", ((a - b) / b).abs());
}

/// Asserts `|a - b| <= eps`.
pub fn assert_abs(a: f64, b: f64, eps: f64, what: &str) {
    assert!((a - b).abs() <= eps, "{what}: {a} vs {b} (|diff| {} > {eps})", (a - b).abs());
}

/// Difference of two directions (degrees, modulo 180), in [0, 90].
pub fn direction_diff_deg(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(180.0);
    d.min(180.0 - d)
}

/// A bilinear patch through four corners (`p00` at (0,0), `p10` at u = 1, ...).
pub fn bilinear(p00: Point3, p10: Point3, p01: Point3, p11: Point3) -> Patch {
    Patch::bezier("plane", [1, 1], &[vec![p00, p01], vec![p10, p11]], None).unwrap()
}

/// The inclined plane fixture 14.1: 56 x 28 mm at 60 degrees, u along Y.
pub fn plane_56x28() -> Patch {
    let (h, w, s) = (28.0, 56.0, 60f64.to_radians());
    let p = |u: f64, v: f64| Point3::new((v - 0.5) * h * s.cos(), (u - 0.5) * w, (v - 0.5) * h * s.sin());
    bilinear(p(0.0, 0.0), p(1.0, 0.0), p(0.0, 1.0), p(1.0, 1.0))
}

/// A built-in surface sampled at `n x n` cell centres.
pub fn builtin_samples(name: &str, n: usize) -> Samples {
    let set = scallop_surface::builtin(name).unwrap();
    sample_patch(&set.patches()[0], &GridOptions { cells_u: n, cells_v: n }).unwrap()
}
