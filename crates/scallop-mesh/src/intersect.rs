//! Mesh-mesh intersection into ordered polylines (the intersection service of
//! Jousselin 2020, Ch. 2 §1.3 and §3.2.1, used for the limit curves; cf.
//! Thirion & Gourdon 1996, "The 3D marching lines algorithm").
//!
//! Every segment end is where an edge of one mesh crosses a triangle of the
//! other, and is keyed by that (edge, triangle) pair: on manifold meshes each
//! key is shared by exactly two segments, so the segments chain by lookup,
//! without any distance tolerance. Exact degeneracies (a vertex on the other
//! mesh, coplanar pieces, shared vertices) are decided by a symbolic
//! perturbation (Edelsbrunner & Mücke 1990, "Simulation of Simplicity"): the
//! second mesh is translated by `(e, e^2, e^3)` for an infinitesimal `e`, so
//! every decision is that of one real, non-degenerate configuration and the
//! segments always chain. Signs of orientations are exact (`robust`); the
//! first-order terms use the rounded coordinate differences.

use scallop_geom::{Aabb3, Point3, Vec3};

use crate::query::triangle_box;
use crate::{Bvh, FastMap, Polyline3, TriMesh};

/// Result of [`intersect_meshes`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshIntersection {
    /// Chained polylines: closed loops, and open chains ending on a mesh
    /// boundary. In a deterministic order (by the first segment found).
    pub chains: Vec<Polyline3>,
    /// Number of intersection segments before chaining.
    pub segments: usize,
    /// Triangle pairs whose crossings were neither 0 nor 2 (possible only
    /// where the first-order terms were rounded); their segments are skipped.
    pub odd_pairs: usize,
    /// Segment ends shared by more than two segments (non-manifold edges).
    pub non_manifold_ends: usize,
}

/// Which edge crosses which triangle: `[side << 32 | triangle, lo << 32 | hi]`
/// with side 0 for an edge of the first mesh, 1 for one of the second.
type Key = [u64; 2];

/// The intersection of meshes `a` and `b` as chained polylines.
///
/// ```
/// use scallop_geom::Point3;
/// use scallop_mesh::{intersect_meshes, TriMesh};
/// let p = |x, y, z| Point3::new(x, y, z);
/// let square = |z: f64, vertical: bool| {
///     let q = |u: f64, v: f64| if vertical { p(u, 0.0, v + z) } else { p(u, v, z) };
///     TriMesh::from_soup(&[[q(-1., -1.), q(1., -1.), q(1., 1.)], [q(-1., -1.), q(1., 1.), q(-1., 1.)]]).unwrap().0
/// };
/// let x = intersect_meshes(&square(0.0, false), &square(0.0, true));
/// assert_eq!(x.chains.len(), 1);
/// assert!(!x.chains[0].closed);
/// ```
#[must_use]
pub fn intersect_meshes(a: &TriMesh, b: &TriMesh) -> MeshIntersection {
    let boxes: Vec<Aabb3> = (0..b.triangles().len()).map(|i| triangle_box(&b.triangle(i))).collect();
    let bvh = Bvh::build(&boxes);
    let mut segments: Vec<[(Key, Point3); 2]> = Vec::new();
    let mut odd_pairs = 0;
    let mut candidates = Vec::new();
    for ta in 0..a.triangles().len() {
        candidates.clear();
        bvh.visit_overlapping(&triangle_box(&a.triangle(ta)), |tb| candidates.push(tb));
        candidates.sort_unstable();
        for &tb in &candidates {
            let mut ends: Vec<(Key, Point3)> = Vec::with_capacity(2);
            crossings(a, ta, b, tb, 0, &mut ends);
            crossings(b, tb, a, ta, 1, &mut ends);
            match ends.len() {
                0 => {}
                2 => segments.push([ends[0], ends[1]]),
                _ => odd_pairs += 1,
            }
        }
    }
    let (chains, non_manifold_ends) = chain_segments(&segments);
    MeshIntersection { chains, segments: segments.len(), odd_pairs, non_manifold_ends }
}

/// Pushes the crossings of the edges of triangle `te` of `edges` with triangle
/// `tf` of `faces`. `side` 0: the edge mesh is the unshifted one.
fn crossings(edges: &TriMesh, te: usize, faces: &TriMesh, tf: usize, side: u64, out: &mut Vec<(Key, Point3)>) {
    let tri = edges.triangles()[te];
    let face = faces.triangle(tf);
    // The face mesh moves by +delta relative to the edge mesh for side 0, by
    // -delta for side 1.
    let dir = if side == 0 { -1.0 } else { 1.0 };
    for k in 0..3 {
        let (i, j) = (tri[k].min(tri[(k + 1) % 3]), tri[k].max(tri[(k + 1) % 3]));
        let (p, q) = (edges.vertices()[i as usize], edges.vertices()[j as usize]);
        if let Some(point) = edge_crosses(&p, &q, &face, dir) {
            let key = [side << 32 | tf as u64, u64::from(i) << 32 | u64::from(j)];
            out.push((key, point));
        }
    }
}

/// Where segment `[p, q]` crosses triangle `f` when `f` is shifted by
/// `-dir * delta` relative to the segment (`delta = (e, e^2, e^3)`).
fn edge_crosses(p: &Point3, q: &Point3, f: &[Point3; 3], dir: f64) -> Option<Point3> {
    // Plane side of a segment end x: s(x) = det[x - f0; f1 - f0; f2 - f0];
    // with the face moved by -dir delta it gains dir * delta . n.
    let n = normal_signs(f);
    let sp = perturbed_sign(-orient3d(&f[0], &f[1], &f[2], p), n, dir);
    let sq = perturbed_sign(-orient3d(&f[0], &f[1], &f[2], q), n, dir);
    if sp == sq {
        return None;
    }
    // The line p -> q passes inside iff the three sides see it turn the same
    // way: g = det[q - p; r - p; t - p], perturbed by -dir delta . ((t - r) x (q - p)).
    let mut first = 0;
    for k in 0..3 {
        let (r, t) = (&f[k], &f[(k + 1) % 3]);
        let m = cross_signs(&(t - r), &(q - p));
        let g = perturbed_sign(-orient3d(p, r, t, q), m, -dir);
        if k == 0 {
            first = g;
        } else if g != first {
            return None;
        }
    }
    let (dp, dq) = (plane_distance(p, f), plane_distance(q, f));
    let w = if dp - dq == 0.0 { 0.5 } else { (dp / (dp - dq)).clamp(0.0, 1.0) };
    Some(p + (q - p) * w)
}

fn plane_distance(x: &Point3, f: &[Point3; 3]) -> f64 {
    (x - f[0]).dot(&(f[1] - f[0]).cross(&(f[2] - f[0])))
}

fn orient3d(a: &Point3, b: &Point3, c: &Point3, d: &Point3) -> f64 {
    let co = |p: &Point3| robust::Coord3D { x: p.x, y: p.y, z: p.z };
    robust::orient3d(co(a), co(b), co(c), co(d))
}

fn orient2d(ax: f64, ay: f64, bx: f64, by: f64, cx: f64, cy: f64) -> f64 {
    robust::orient2d(robust::Coord { x: ax, y: ay }, robust::Coord { x: bx, y: by }, robust::Coord { x: cx, y: cy })
}

/// Exact signs of the components of the normal `(f1 - f0) x (f2 - f0)`.
fn normal_signs(f: &[Point3; 3]) -> [f64; 3] {
    [
        orient2d(f[0].y, f[0].z, f[1].y, f[1].z, f[2].y, f[2].z),
        orient2d(f[0].z, f[0].x, f[1].z, f[1].x, f[2].z, f[2].x),
        orient2d(f[0].x, f[0].y, f[1].x, f[1].y, f[2].x, f[2].y),
    ]
}

/// Signs of the components of `u x v` (exact for the given rounded vectors).
fn cross_signs(u: &Vec3, v: &Vec3) -> [f64; 3] {
    [
        orient2d(u.y, u.z, v.y, v.z, 0.0, 0.0),
        orient2d(u.z, u.x, v.z, v.x, 0.0, 0.0),
        orient2d(u.x, u.y, v.x, v.y, 0.0, 0.0),
    ]
}

/// The sign (1 or -1; 0 only when everything vanishes) of
/// `value + scale * (c_x e + c_y e^2 + c_z e^3)` for an infinitesimal `e > 0`.
fn perturbed_sign(value: f64, c: [f64; 3], scale: f64) -> i8 {
    let sign = |x: f64| if x > 0.0 { 1 } else { -1 };
    if value != 0.0 {
        return sign(value);
    }
    c.iter().find(|x| **x != 0.0).map_or(0, |x| sign(x * scale))
}

/// Chains keyed segments into polylines; returns them and the number of keys
/// shared by more than two segments.
fn chain_segments(segments: &[[(Key, Point3); 2]]) -> (Vec<Polyline3>, usize) {
    let keys: Vec<[Key; 2]> = segments.iter().map(|s| [s[0].0, s[1].0]).collect();
    let (chains, non_manifold) = chain_keys(&keys);
    let lines = chains
        .iter()
        .map(|c| {
            let mut points: Vec<Point3> = Vec::with_capacity(c.steps.len() + 1);
            for (k, &(s, reversed)) in c.steps.iter().enumerate() {
                let (a, b) = if reversed { (1, 0) } else { (0, 1) };
                if k == 0 {
                    points.push(segments[s][a].1);
                }
                if points.last() != Some(&segments[s][b].1) {
                    points.push(segments[s][b].1);
                }
            }
            if c.closed && points.len() > 1 && points.first() == points.last() {
                points.pop();
            }
            Polyline3::new(points, c.closed)
        })
        .collect();
    (lines, non_manifold)
}

/// One chain of [`chain_keys`]: the segments in travel order, each with
/// whether it is travelled from its second end to its first.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct KeyChain {
    /// `(segment, reversed)` in travel order.
    pub steps: Vec<(usize, bool)>,
    /// Whether the last segment leads back to the first.
    pub closed: bool,
}

/// Chains segments whose ends carry keys: two segments join where they share
/// a key. Open chains (from an end no other segment shares) come first, then
/// closed ones, each started at its lowest segment number; deterministic.
/// Returns the chains and the number of keys shared by more than two segments
/// (those join the lowest unused segment).
///
/// ```
/// let keys = [[[0, 1], [0, 2]], [[0, 3], [0, 2]], [[0, 3], [0, 1]]];
/// let (chains, odd) = scallop_mesh::chain_keys(&keys);
/// assert_eq!((chains.len(), odd), (1, 0));
/// assert!(chains[0].closed);
/// assert_eq!(chains[0].steps, vec![(0, false), (1, true), (2, false)]);
/// ```
#[must_use]
pub fn chain_keys(keys: &[[[u64; 2]; 2]]) -> (Vec<KeyChain>, usize) {
    let mut at: FastMap<Key, Vec<u32>> = FastMap::default();
    for (s, seg) in keys.iter().enumerate() {
        for key in seg {
            at.entry(*key).or_default().push(u32::try_from(s).unwrap_or(u32::MAX));
        }
    }
    let non_manifold = at.values().filter(|v| v.len() > 2).count();
    let mut used = vec![false; keys.len()];
    let mut chains = Vec::new();
    for pass in 0..2 {
        for s in 0..keys.len() {
            if used[s] {
                continue;
            }
            let start_end = if pass == 0 {
                match (0..2).find(|&e| at[&keys[s][e]].len() == 1) {
                    Some(e) => e,
                    None => continue,
                }
            } else {
                0
            };
            let mut steps = Vec::new();
            let (mut seg, mut enter) = (s, start_end);
            loop {
                used[seg] = true;
                steps.push((seg, enter == 1));
                let key = keys[seg][1 - enter];
                let Some(n) = at[&key].iter().map(|&x| x as usize).find(|&x| !used[x]) else { break };
                enter = usize::from(keys[n][0] != key);
                seg = n;
            }
            chains.push(KeyChain { steps, closed: pass == 1 });
        }
    }
    (chains, non_manifold)
}
