//! Per-face metrics of spec 10.1 on the proof's tri-dexel stock: the
//! material left on each finished face (the bottom, the flanks) measured along
//! the face's normal, its deviation from the allowance (Tukey's five numbers,
//! the whole face) and the crest heights above the allowance (max, mean and
//! sigma, corners excluded).
//!
//! At a sample point p of a face with unit normal n (outward from the volume to
//! remove, into the finished part), the ray family whose axis e_k is closest to
//! n is read on the ray nearest to p. The face's plane meets that ray at
//! `c_f = n . (p - o) / n_k` (o the ray's origin); the material run that holds
//! `c_f` ends, on the pocket's side, at `c_f + s l` (s = -sign n_k); the
//! thickness along the normal is `l |n_k|` (a plane's distance, exact for a
//! planar face up to the ray's rounding), the run cut where the ray leaves the
//! volume to remove (material across the pocket is not left on this face).
//! Where no material holds `c_f` the stock was cut beyond the face: the
//! thickness is minus the distance to the nearest material on the part's
//! side. A sample whose ray does not enter the volume to remove within a ray
//! spacing of `c_f` (at a corner, the face's plane met below the next face) is
//! not measured.

use rayon::prelude::*;
use scallop_geom::{Point3, Vec3};
use scallop_mesh::{MeshQuery, TriMesh};
use scallop_sim::{DexelPart, DexelStock};

/// A finished face of the part to measure.
#[derive(Debug, Clone, Copy)]
pub struct ProofFace<'a> {
    /// How the report names it (`bottom`, `flanks`).
    pub name: &'static str,
    /// Its triangles, normals outward from the volume to remove.
    pub mesh: &'a TriMesh,
    /// The faces whose neighbourhood is a corner of this one (the flanks for
    /// the bottom, the bottom for the flanks).
    pub others: &'a TriMesh,
    /// The allowance left on it (mm).
    pub allowance: f64,
    /// Samples closer than this to `others` are corners (mm; the tool radius).
    pub corner: f64,
}

/// The metrics of one face.
#[derive(Debug, Clone, PartialEq)]
pub struct FaceMetrics {
    /// The face's name.
    pub name: &'static str,
    /// Its area (mm^2).
    pub area: f64,
    /// Samples measured (one per sub-triangle of at most the ray spacing).
    pub samples: usize,
    /// Of them, in corners (excluded from the crest heights).
    pub corner_samples: usize,
    /// Deviation of the thickness left from the allowance (mm): minimum, first
    /// quartile, median, third quartile, maximum, area-weighted.
    pub deviation_quartiles: [f64; 5],
    /// The same outside the corners: within a tool radius of the other face a
    /// ray along the normal may run through that face's allowance shell.
    pub deviation_quartiles_outside_corners: [f64; 5],
    /// Largest crest height above the allowance, corners excluded (mm).
    pub crest_max: f64,
    /// Area-weighted mean crest height (mm).
    pub crest_mean: f64,
    /// Its standard deviation (mm).
    pub crest_sigma: f64,
}

/// The thickness left at `p` on a face of normal `n` (mm), or `None` where the
/// rays say nothing (outside the grid, no material on either side).
fn thickness(dexels: &DexelStock, volume: &DexelPart, p: &Point3, n: &Vec3) -> Option<f64> {
    let k = (0..3).max_by(|a, b| n[*a].abs().total_cmp(&n[*b].abs())).unwrap_or(2);
    let (u, v) = ((k + 1) % 3, (k + 2) % 3);
    let stock = dexels.stock();
    let cell = dexels.cell_size();
    let index = |a: usize| ((p[a] - stock.min[a]) / cell[a]).floor();
    let (fu, fv) = (index(u), index(v));
    if fu < 0.0 || fv < 0.0 {
        return None;
    }
    // Non-negative and bounded by the grid (checked by `intervals`): exact casts.
    let (iu, iv) = (fu as usize, fv as usize);
    let o = dexels.ray_origin(k, iu, iv);
    let c = n.dot(&(p - o)) / n[k];
    // Coordinates along the pocket's side: increasing from the face.
    let s = -n[k].signum();
    let runs: Vec<[f64; 2]> =
        dexels.intervals(k, iu, iv).iter().map(|r| if s > 0.0 { [r[0], r[1]] } else { [-r[1], -r[0]] }).collect();
    let c = s * c;
    let eps = dexels.eps();
    let spacing = cell.iter().copied().fold(0.0, f64::max);
    let pocket = volume
        .intervals(&o, k)
        .iter()
        .map(|r| if s > 0.0 { [r.0, r.1] } else { [-r.1, -r.0] })
        .find(|r| r[0] <= c + spacing && r[1] > c)?;
    if let Some(r) = runs.iter().find(|r| r[0] <= c + eps && r[1] >= c - eps) {
        return Some((r[1].min(pocket[1]) - c).max(0.0) * n[k].abs());
    }
    // Cut beyond the face: the nearest material on the part's side.
    runs.iter()
        .filter(|r| r[1] < c)
        .map(|r| -(c - r[1]) * n[k].abs())
        .fold(None, |m, t| Some(m.map_or(t, |m: f64| m.max(t))))
}

/// Weighted quantile `q` of sorted `(value, weight)` pairs.
fn quantile(sorted: &[(f64, f64)], total: f64, q: f64) -> f64 {
    let mut acc = 0.0;
    for (x, w) in sorted {
        acc += w;
        if acc >= q * total {
            return *x;
        }
    }
    sorted.last().map_or(0.0, |p| p.0)
}

/// Tukey's five numbers of `(value, weight)` pairs, weighted: minimum, first
/// quartile, median, third quartile, maximum (zeros when empty).
fn tukey(mut values: Vec<(f64, f64)>) -> [f64; 5] {
    values.sort_by(|x, y| x.0.total_cmp(&y.0));
    let total: f64 = values.iter().map(|s| s.1).sum();
    match (values.first(), values.last()) {
        (Some(first), Some(last)) => [
            first.0,
            quantile(&values, total, 0.25),
            quantile(&values, total, 0.5),
            quantile(&values, total, 0.75),
            last.0,
        ],
        _ => [0.0; 5],
    }
}

/// The metrics of `face` on `dexels`, the volume to remove being `volume`,
/// sampled at sub-triangles of at most `spacing` (the ray spacing).
#[must_use]
pub fn face_metrics(dexels: &DexelStock, volume: &DexelPart, face: &ProofFace<'_>, spacing: f64) -> FaceMetrics {
    let corners = MeshQuery::new(face.others);
    let vertices = face.mesh.vertices();
    // (deviation, weight, in a corner) per sample, triangle by triangle.
    let per_triangle: Vec<Vec<(f64, f64, bool)>> = face
        .mesh
        .triangles()
        .par_iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| vertices[i as usize]);
            let normal = (b - a).cross(&(c - a));
            let area = 0.5 * normal.norm();
            if area <= 0.0 {
                return Vec::new();
            }
            let n = normal / (2.0 * area);
            let longest = (b - a).norm().max((c - b).norm()).max((a - c).norm());
            // At most a few hundred subdivisions of one triangle: exact.
            let m = (longest / spacing).ceil().max(1.0) as usize;
            let w = area / (m * m) as f64;
            let mf = m as f64;
            let mut out = Vec::new();
            let mut sample = |x: f64, y: f64| {
                let p = a + (b - a) * (x / mf) + (c - a) * (y / mf);
                if let Some(t) = thickness(dexels, volume, &p, &n) {
                    let corner = (corners.closest_point(&p).point - p).norm() < face.corner;
                    out.push((t - face.allowance, w, corner));
                }
            };
            for i in 0..m {
                for j in 0..m - i {
                    let (x, y) = (i as f64, j as f64);
                    sample(x + 1.0 / 3.0, y + 1.0 / 3.0);
                    if i + j + 1 < m {
                        sample(x + 2.0 / 3.0, y + 2.0 / 3.0);
                    }
                }
            }
            out
        })
        .collect();
    let all: Vec<(f64, f64, bool)> = per_triangle.into_iter().flatten().collect();
    let deviation_quartiles = tukey(all.iter().map(|s| (s.0, s.1)).collect());
    let deviation_quartiles_outside_corners = tukey(all.iter().filter(|s| !s.2).map(|s| (s.0, s.1)).collect());
    let crests: Vec<(f64, f64)> = all.iter().filter(|s| !s.2).map(|s| (s.0.max(0.0), s.1)).collect();
    let weight: f64 = crests.iter().map(|s| s.1).sum();
    let mean = if weight > 0.0 { crests.iter().map(|s| s.0 * s.1).sum::<f64>() / weight } else { 0.0 };
    let var = if weight > 0.0 { crests.iter().map(|s| (s.0 - mean).powi(2) * s.1).sum::<f64>() / weight } else { 0.0 };
    FaceMetrics {
        name: face.name,
        area: face
            .mesh
            .triangles()
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| vertices[i as usize]);
                0.5 * (b - a).cross(&(c - a)).norm()
            })
            .sum(),
        samples: all.len(),
        corner_samples: all.iter().filter(|s| s.2).count(),
        deviation_quartiles,
        deviation_quartiles_outside_corners,
        crest_max: crests.iter().map(|s| s.0).fold(0.0, f64::max),
        crest_mean: mean,
        crest_sigma: var.sqrt(),
    }
}
