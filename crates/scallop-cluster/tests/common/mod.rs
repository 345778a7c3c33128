//! Helpers shared by the integration tests: synthetic feature grids and an
//! independent nearest-centre check.
#![allow(dead_code)]

use scallop_analysis::FeatureVector;
use scallop_cluster::{Features, ThetaMode, wrap_direction_difference};

/// A small deterministic generator (64-bit LCG, top bits) for test data.
pub struct Lcg(pub u64);

impl Lcg {
    pub fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A full grid whose `(s, theta)` come from `f(u, v)`.
pub fn grid(n: [usize; 2], f: impl Fn(f64, f64) -> (f64, f64)) -> Features {
    let mut features = Vec::new();
    for a in 0..n[0] {
        for b in 0..n[1] {
            let (u, v) = ((a as f64 + 0.5) / n[0] as f64, (b as f64 + 0.5) / n[1] as f64);
            let (slope, slope_direction) = f(u, v);
            features.push(FeatureVector { u, v, slope, slope_direction });
        }
    }
    Features::from_grid(n, &features).expect("valid grid")
}

/// A grid with random `s` in `[0, pi/2]` and `theta` in `(-pi/2, pi/2]`.
pub fn random_grid(n: [usize; 2], seed: u64) -> Features {
    let mut rng = Lcg(seed);
    let values: Vec<(f64, f64)> = (0..n[0] * n[1])
        .map(|_| (rng.next() * std::f64::consts::FRAC_PI_2, (rng.next() - 0.5) * std::f64::consts::PI))
        .collect();
    let mut features = Vec::new();
    for a in 0..n[0] {
        for b in 0..n[1] {
            let (u, v) = ((a as f64 + 0.5) / n[0] as f64, (b as f64 + 0.5) / n[1] as f64);
            let (slope, slope_direction) = values[a * n[1] + b];
            features.push(FeatureVector { u, v, slope, slope_direction });
        }
    }
    Features::from_grid(n, &features).expect("valid grid")
}

/// Cluster means computed independently (theta: doubled-angle mean or plain mean).
pub fn means(features: &Features, labels: &[u32], k: usize, mode: ThetaMode) -> Vec<[f64; 4]> {
    let mut sum = vec![[0.0f64; 6]; k];
    for (i, &l) in labels.iter().enumerate() {
        let f = features.feature(i);
        let s = &mut sum[l as usize];
        s[0] += f.u;
        s[1] += f.v;
        s[2] += f.slope;
        s[3] += f.slope_direction;
        s[4] += (2.0 * f.slope_direction).sin();
        s[5] += (2.0 * f.slope_direction).cos();
    }
    let counts = (0..k).map(|c| labels.iter().filter(|&&l| l as usize == c).count() as f64);
    sum.iter()
        .zip(counts)
        .map(|(s, n)| {
            let theta = match mode {
                ThetaMode::Wrapped => 0.5 * s[4].atan2(s[5]),
                ThetaMode::Plain => s[3] / n,
            };
            [s[0] / n, s[1] / n, s[2] / n, theta]
        })
        .collect()
}

/// `x_i - c` with theta per `mode`.
pub fn diff(features: &Features, i: usize, c: &[f64; 4], mode: ThetaMode) -> [f64; 4] {
    let f = features.feature(i);
    let t = f.slope_direction - c[3];
    let t = if mode == ThetaMode::Wrapped { wrap_direction_difference(t) } else { t };
    [f.u - c[0], f.v - c[1], f.slope - c[2], t]
}

/// `d^T A d`.
pub fn quad(a: &[[f64; 4]; 4], d: &[f64; 4]) -> f64 {
    let mut s = 0.0;
    for r in 0..4 {
        for c in 0..4 {
            s += d[r] * a[r][c] * d[c];
        }
    }
    s
}

/// Asserts that every point's cluster is (within rounding) its nearest mean under
/// the quadratic form `a`.
pub fn assert_fixed_point(features: &Features, labels: &[u32], k: usize, mode: ThetaMode, a: &[[f64; 4]; 4]) {
    let centres = means(features, labels, k, mode);
    for (i, &l) in labels.iter().enumerate() {
        let own = quad(a, &diff(features, i, &centres[l as usize], mode));
        for (c, centre) in centres.iter().enumerate() {
            let other = quad(a, &diff(features, i, centre, mode));
            assert!(own <= other + 1e-9 * (1.0 + other), "point {i}: cluster {l} at {own}, cluster {c} at {other}");
        }
    }
}

/// Canonical relabelling: labels renumbered in order of first appearance.
pub fn canonical(labels: &[u32]) -> Vec<u32> {
    let mut map = std::collections::HashMap::new();
    labels
        .iter()
        .map(|l| {
            let next = map.len() as u32;
            *map.entry(*l).or_insert(next)
        })
        .collect()
}
