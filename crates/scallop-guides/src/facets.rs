//! Marching Facets (Jousselin 2020, Ch. 2 §3.2.1, Fig. 2.31-2.33): the
//! iso-line of a scalar field on a triangle mesh. Per facet, the three vertex
//! states give a 3-bit code; a mixed facet holds one segment between its two
//! crossed edges. Crossings are located by root finding on the exact field
//! (not by linear interpolation of the vertex values), so each edge point is
//! on the iso-line within [`tol::ROOT_TOLERANCE`], also on facets crossed by
//! the medial axis; such facets are flagged and their segment gets the iso
//! point found across its middle (the repair). Segments chain by their edge
//! keys ([`scallop_mesh::chain_keys`]), and every chain keeps the positive
//! side on its left.

use rayon::prelude::*;
use scallop_geom::{Point3, Vec3};
use scallop_mesh::{FastMap, Polyline3, chain_keys};

use crate::support::{Curve, Support, barycentric};
use crate::tol;

/// The iso-lines of one extraction.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Isolines {
    /// Chained curves, positive side on the left.
    pub curves: Vec<Curve>,
    /// Mixed facets flagged as crossed by the medial axis.
    pub flagged: usize,
    /// Flagged facets whose segment got a repair point.
    pub repaired: usize,
}

struct Crossing {
    point: Point3,
    normal: Vec3,
}

struct Segment {
    ends: [u32; 2],
    mid: Option<Point3>,
}

/// The zero iso-line of `exact` (the field minus the iso-value) on `support`,
/// given its vertex values (`> 0` is the positive state; a non-finite value
/// stands for a vertex known to be far on its side). `medial(facet)` says
/// whether a facet is crossed by the medial axis.
pub(crate) fn march(
    support: &Support,
    values: &[f64],
    exact: &(impl Fn(&Point3) -> f64 + Sync),
    medial: &(impl Fn(usize) -> bool + Sync),
) -> Isolines {
    let facets = 0..support.mesh().triangles().len();
    march_facets(support, values, facets, &|p: &Point3, _| exact(p), &|_, _, _, _| None, medial)
}

/// As [`march`], looking only at `facets` (ascending): the caller vouches
/// that every facet with vertices of both states is among them. `exact(p, v)`
/// is told a vertex `v` near `p` (an end of the edge, a corner of the facet),
/// which it may use to search from, not to change the value.
/// `guess(a, b, ga, gb)` may give a first guess in `(0, 1)` of the root on
/// edge `(a, b)` (`ga`, `gb` the values of its ends): when the exact field is
/// within [`tol::ROOT_TOLERANCE`] of the iso-value there, one evaluation
/// settles the crossing; otherwise it narrows the bracket.
pub(crate) fn march_facets(
    support: &Support,
    values: &[f64],
    facets: impl Iterator<Item = usize>,
    exact: &(impl Fn(&Point3, u32) -> f64 + Sync),
    guess: &(impl Fn(u32, u32, f64, f64) -> Option<f64> + Sync),
    medial: &(impl Fn(usize) -> bool + Sync),
) -> Isolines {
    let mesh = support.mesh();
    let pos = |v: u32| values[v as usize] > 0.0;
    let mixed: Vec<usize> = facets
        .filter(|&f| {
            let n = mesh.triangles()[f].iter().filter(|&&v| pos(v)).count();
            n == 1 || n == 2
        })
        .collect();
    let mut edges: Vec<(u32, u32)> = Vec::with_capacity(2 * mixed.len());
    for &f in &mixed {
        let t = mesh.triangles()[f];
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if pos(a) != pos(b) {
                edges.push((a.min(b), a.max(b)));
            }
        }
    }
    edges.sort_unstable();
    edges.dedup();
    let crossings: Vec<Crossing> = edges
        .par_iter()
        .with_min_len(ITEMS_PER_TASK)
        .map(|&(a, b)| crossing(support, values, exact, guess, a, b))
        .collect();
    let mut index: FastMap<u64, u32> = FastMap::default();
    for (i, &(a, b)) in edges.iter().enumerate() {
        index.insert(u64::from(a) << 32 | u64::from(b), u32::try_from(i).unwrap_or(u32::MAX));
    }
    let built: Vec<(Segment, bool, bool)> = mixed
        .par_iter()
        .with_min_len(ITEMS_PER_TASK)
        .map(|&f| facet_segment(support, values, &index, &crossings, f, exact, medial))
        .collect();
    let flagged = built.iter().filter(|b| b.1).count();
    let repaired = built.iter().filter(|b| b.2).count();
    let segments: Vec<Segment> = built.into_iter().map(|b| b.0).collect();
    let curves = chain(&segments, &crossings, &edges);
    Isolines { curves, flagged, repaired }
}

/// Fewest edges or facets per parallel task of [`march_facets`]: a crossing
/// costs a few distance queries, too little to share finely.
const ITEMS_PER_TASK: usize = 64;

fn edge_key(a: u32, b: u32) -> u64 {
    u64::from(a.min(b)) << 32 | u64::from(a.max(b))
}

/// The crossing on edge `(a, b)` (states differ) by root finding, from the
/// first guess of `guess` if any (see [`march_facets`]).
fn crossing(
    support: &Support,
    values: &[f64],
    exact: &(impl Fn(&Point3, u32) -> f64 + Sync),
    guess: &(impl Fn(u32, u32, f64, f64) -> Option<f64> + Sync),
    a: u32,
    b: u32,
) -> Crossing {
    let (pa, pb) = (support.mesh().vertices()[a as usize], support.mesh().vertices()[b as usize]);
    let g = |t: f64| exact(&(pa + (pb - pa) * t), a);
    let (ga, gb, len) = (values[a as usize], values[b as usize], (pb - pa).norm());
    let t = match guess(a, b, ga, gb).filter(|&t| t > 0.0 && t < 1.0) {
        None => edge_root(g, ga, gb, len),
        Some(t0) => {
            let g0 = g(t0);
            if g0.abs() <= tol::ROOT_TOLERANCE {
                t0
            } else if (g0 > 0.0) == (gb > 0.0) {
                root_between(g, (0.0, ga), (t0, g0), len)
            } else {
                root_between(g, (t0, g0), (1.0, gb), len)
            }
        }
    };
    let n = support.vertex_normal(a as usize) * (1.0 - t) + support.vertex_normal(b as usize) * t;
    let len = n.norm();
    Crossing { point: pa + (pb - pa) * t, normal: if len > 0.0 { n / len } else { support.vertex_normal(a as usize) } }
}

/// A root in `[0, 1]` of `g` with `g(0) = ga`, `g(1) = gb` of different
/// states (`> 0` or not): Illinois false position, bisection where a value
/// is not finite; stops within [`tol::ROOT_TOLERANCE`] of the root value or
/// of bracket length (`len` is the edge length in mm).
pub(crate) fn edge_root(g: impl Fn(f64) -> f64, ga: f64, gb: f64, len: f64) -> f64 {
    root_between(g, (0.0, ga), (1.0, gb), len)
}

/// As [`edge_root`] within the bracket `[lo.0, hi.0]` of `[0, 1]`, where
/// `g` has the values `lo.1` and `hi.1` of different states.
fn root_between(g: impl Fn(f64) -> f64, lo: (f64, f64), hi: (f64, f64), len: f64) -> f64 {
    let ((mut a, mut fa), (mut b, mut fb)) = (lo, hi);
    let mut last_side = 0i8;
    for _ in 0..tol::MAX_ROOT_ITERATIONS {
        if (b - a) * len <= tol::ROOT_TOLERANCE {
            break;
        }
        let mut t =
            if fa.is_finite() && fb.is_finite() && fb - fa != 0.0 { (a * fb - b * fa) / (fb - fa) } else { f64::NAN };
        if t.is_nan() || t <= a || t >= b {
            t = 0.5 * (a + b);
        }
        let ft = g(t);
        if ft.abs() <= tol::ROOT_TOLERANCE {
            return t;
        }
        if (ft > 0.0) == (fb > 0.0) {
            b = t;
            fb = ft;
            if last_side == 1 {
                fa *= 0.5;
            }
            last_side = 1;
        } else {
            a = t;
            fa = ft;
            if last_side == -1 {
                fb *= 0.5;
            }
            last_side = -1;
        }
    }
    0.5 * (a + b)
}

/// The segment of mixed facet `f`, oriented with the positive side on its
/// left, whether the facet is flagged, and whether it was repaired.
fn facet_segment(
    support: &Support,
    values: &[f64],
    index: &FastMap<u64, u32>,
    crossings: &[Crossing],
    f: usize,
    exact: &(impl Fn(&Point3, u32) -> f64 + Sync),
    medial: &(impl Fn(usize) -> bool + Sync),
) -> (Segment, bool, bool) {
    let t = support.mesh().triangles()[f];
    let mut ends = [0u32; 2];
    let mut n = 0;
    let mut positive = t[0];
    for k in 0..3 {
        let (a, b) = (t[k], t[(k + 1) % 3]);
        if values[a as usize] > 0.0 {
            positive = a;
        }
        if (values[a as usize] > 0.0) != (values[b as usize] > 0.0) && n < 2 {
            ends[n] = index[&edge_key(a, b)];
            n += 1;
        }
    }
    let normal = support.query().normal(f);
    let (p, q) = (crossings[ends[0] as usize].point, crossings[ends[1] as usize].point);
    let vp = support.mesh().vertices()[positive as usize];
    if (vp - p).dot(&normal.cross(&(q - p))) < 0.0 {
        ends.swap(0, 1);
    }
    let flagged = medial(f);
    let mid = if flagged {
        repair(support, f, &crossings[ends[0] as usize].point, &crossings[ends[1] as usize].point, &|p: &Point3| {
            exact(p, t[0])
        })
    } else {
        None
    };
    let repaired = mid.is_some();
    (Segment { ends, mid }, flagged, repaired)
}

/// The iso point across the middle of segment `[p, q]` within facet `f`, if
/// the field changes state along the facet's in-plane normal to the segment
/// and the point stays in the facet.
fn repair(support: &Support, f: usize, p: &Point3, q: &Point3, exact: &impl Fn(&Point3) -> f64) -> Option<Point3> {
    let normal = support.query().normal(f);
    let w = normal.cross(&(q - p));
    let len = w.norm();
    if len.is_nan() || len <= 0.0 {
        return None;
    }
    let w = w / len;
    let m = nalgebra_center(p, q);
    let gm = exact(&m);
    let h = support.facet_size();
    // The positive side is along +w: a positive middle means the line bulges back.
    let dir = if gm > 0.0 { -w } else { w };
    let far = m + dir * h;
    let gf = exact(&far);
    if (gf > 0.0) == (gm > 0.0) {
        return None;
    }
    let s = edge_root(|s| exact(&(m + dir * (h * s))), gm, gf, h);
    let x = m + dir * (h * s);
    let tri = support.mesh().triangle(f);
    let b = barycentric(&x, &tri);
    let back = tri[0] + (tri[1] - tri[0]) * b[1] + (tri[2] - tri[0]) * b[2];
    ((back - x).norm() <= tol::ROOT_TOLERANCE.max(1e-9 * h)).then_some(x)
}

fn nalgebra_center(p: &Point3, q: &Point3) -> Point3 {
    Point3::from((p.coords + q.coords) * 0.5)
}

/// Chains the segments into curves, each travelled with most of its
/// segments forward (the positive side on its left).
fn chain(segments: &[Segment], crossings: &[Crossing], edges: &[(u32, u32)]) -> Vec<Curve> {
    let keys: Vec<[[u64; 2]; 2]> =
        segments.iter().map(|s| s.ends.map(|e| [0, edge_key(edges[e as usize].0, edges[e as usize].1)])).collect();
    let (chains, _) = chain_keys(&keys);
    chains
        .into_iter()
        .map(|c| {
            let forward = c.steps.iter().filter(|s| !s.1).count();
            let flip = 2 * forward < c.steps.len();
            let mut pts: Vec<Point3> = Vec::with_capacity(2 * c.steps.len() + 1);
            let mut normals: Vec<Vec3> = Vec::with_capacity(pts.capacity());
            let mut push = |p: Point3, n: Vec3| {
                if pts.last() != Some(&p) {
                    pts.push(p);
                    normals.push(n);
                }
            };
            for (k, &(s, reversed)) in c.steps.iter().enumerate() {
                let seg = &segments[s];
                let (a, b) = if reversed { (seg.ends[1], seg.ends[0]) } else { (seg.ends[0], seg.ends[1]) };
                let (ca, cb) = (&crossings[a as usize], &crossings[b as usize]);
                if k == 0 {
                    push(ca.point, ca.normal);
                }
                if let Some(m) = seg.mid {
                    let n = (ca.normal + cb.normal).normalize();
                    push(m, n);
                }
                push(cb.point, cb.normal);
            }
            if c.closed && pts.len() > 1 && pts.first() == pts.last() {
                pts.pop();
                normals.pop();
            }
            let curve = Curve { line: Polyline3::new(pts, c.closed), normals };
            if flip { curve.reversed() } else { curve }
        })
        .collect()
}
