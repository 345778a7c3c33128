//! Path curves: iterated inward offsets of a curve on a support by Marching
//! Facets (Jousselin 2020, Ch. 2 §3.2.1, the scalar method). Each curve is
//! the iso-line at `a_e` of the signed distance to the previous one (one field
//! per curve: iso-levels of one field would drift apart by more than `a_e` on
//! curved supports), until no facet is crossed. Several loops at a step mean
//! the offset split (Ch. 2 §3.3, Fig. 2.39b).

use rayon::prelude::*;
use scallop_geom::Point3;
use scallop_mesh::PolylineFoot;

use crate::facets::{Isolines, march_facets};
use crate::field::CurveField;
use crate::support::{Curve, Support, VertexTree, check_curve};
use crate::{GuideError, tol};

/// One offset step.
#[derive(Clone, Debug, PartialEq)]
pub struct OffsetStep {
    /// The loops (or open chains) of this offset, inside on their left.
    pub curves: Vec<Curve>,
    /// Whether this step has more loops than the one before (a split).
    pub split: bool,
    /// Facets flagged as crossed by the medial axis.
    pub flagged: usize,
    /// Flagged facets whose segment got a repair point.
    pub repaired: usize,
}

/// The successive inward offsets of `limit` (inside on the left of each
/// curve, see [`Curve::inside_left`]) on `support`, `step` (the radial
/// engagement a_e, mm) apart, until they vanish. The first entry is the first
/// offset (C_n itself is not repeated). A loop narrower than
/// [`tol::SLIVER_WIDTH_FACETS`] facets (mean width `2 area / length`) counts
/// as vanished: it is the iso-line of a distance whose maximum barely passes
/// the step, below the mesh's resolution, and where the region is a strip of
/// about twice the step it breaks into a row of such slivers.
///
/// # Errors
/// [`GuideError::BadLength`] for a non-positive step, [`GuideError::BadCurve`]
/// for an unusable curve, [`GuideError::NotVanishing`] if the offsets do not
/// vanish within `diagonal / step + 2` steps.
pub fn offset_curves(support: &Support, limit: &[Curve], step: f64) -> Result<Vec<OffsetStep>, GuideError> {
    check_step(step)?;
    for (i, c) in limit.iter().enumerate() {
        check_curve(c, i)?;
    }
    iterate(support, limit, step, offset_once)
}

/// The loop of [`offset_curves`] with `once` as the single extraction.
fn iterate(
    support: &Support,
    limit: &[Curve],
    step: f64,
    once: impl Fn(&Support, &[Curve], f64) -> Isolines,
) -> Result<Vec<OffsetStep>, GuideError> {
    let guard = (support.mesh().bounds().diagonal() / step).ceil() as usize + tol::EXTRA_STEPS;
    let mut current: Vec<Curve> = limit.to_vec();
    let mut steps: Vec<OffsetStep> = Vec::new();
    while !current.is_empty() {
        if steps.len() >= guard {
            return Err(GuideError::NotVanishing { steps: steps.len() });
        }
        let mut iso = once(support, &current, step);
        let sliver = tol::SLIVER_WIDTH_FACETS * support.facet_size();
        iso.curves.retain(|c| !c.line.closed || 2.0 * c.signed_area().abs() >= sliver * c.line.length());
        if iso.curves.is_empty() {
            break;
        }
        let split = iso.curves.len() > current.len() && !steps.is_empty();
        current = iso.curves.clone();
        steps.push(OffsetStep { curves: iso.curves, split, flagged: iso.flagged, repaired: iso.repaired });
    }
    Ok(steps)
}

/// The single iso-line at `distance` inside `curves` (one Marching Facets
/// extraction over the whole support).
///
/// # Errors
/// [`GuideError::BadLength`] for a non-positive distance,
/// [`GuideError::BadCurve`] for an unusable curve.
pub fn offset_curve(support: &Support, curves: &[Curve], distance: f64) -> Result<Isolines, GuideError> {
    check_step(distance)?;
    for (i, c) in curves.iter().enumerate() {
        check_curve(c, i)?;
    }
    Ok(offset_once(support, curves, distance))
}

/// One Marching Facets extraction, measuring only the vertices near the
/// iso-line (docs/guides-curves.md, "Only the vertices near the iso-line
/// are measured"). With `h` the facet size, the vertices nearer than
/// `distance - h` to the curves ([`Limits`]) are negative whatever their side
/// (`-inf`), those farther than `distance + h` take the side of a measured
/// neighbour (NaN here), the others are measured within the reach
/// `distance + 2h`. An edge is at most `h` long, so a facet with both states
/// has only measured corners but for far ones: only the facets of measured
/// vertices are marched, after their far corners get their side
/// ([`side_far_corners`]). The iso-line is the one of the full scan that
/// measures every vertex within the reach.
fn offset_once(support: &Support, curves: &[Curve], distance: f64) -> Isolines {
    let field = CurveField::new(curves);
    let h = support.facet_size() * (1.0 + tol::SELECTION_SLACK);
    let lim =
        Limits { distance, inner: distance - h, outer: distance + h, reach: distance + 2.0 * support.facet_size() };
    let (near, leaves) = select_nodes(support, &field, lim);
    let tree = support.vertex_tree();
    let verts = support.mesh().vertices();
    let measured: Vec<Vec<(u32, f64, Option<PolylineFoot>)>> = leaves
        .par_iter()
        .with_min_len(LEAVES_PER_TASK)
        .map(|&(l, dc)| measure_leaf(support, &field, l, dc, lim))
        .collect();
    let mut values = vec![f64::NAN; verts.len()];
    for &n in &near {
        for &v in tree.vertices(n as usize) {
            values[v as usize] = f64::NEG_INFINITY;
        }
    }
    let mut slot = vec![u32::MAX; verts.len()];
    let mut feet: Vec<PolylineFoot> = Vec::new();
    let mut marked = vec![false; support.mesh().triangles().len()];
    for (v, value, foot) in measured.into_iter().flatten() {
        values[v as usize] = value;
        if let Some(f) = foot {
            slot[v as usize] = u32::try_from(feet.len()).unwrap_or(u32::MAX);
            feet.push(f);
            for &f in support.vertex_facets(v as usize) {
                marked[f as usize] = true;
            }
        }
    }
    let facets: Vec<u32> = (0..marked.len()).filter(|&f| marked[f]).map(|f| f as u32).collect();
    side_far_corners(support, &facets, &mut values);
    let foot = |v: u32| feet.get(slot[v as usize] as usize);
    // Roots search from the foot of a nearby vertex: the same foot, found faster.
    let exact = |p: &Point3, v: u32| {
        let f = field.foot_near(p, f64::INFINITY, foot(v));
        f.map_or(f64::NEG_INFINITY, |f| field.signed_at(p, &f)) - distance
    };
    let medial = |f: usize| medial_facet(support, f, |v| foot(v).map(|f| f.point));
    march_facets(support, &values, facets.iter().map(|&f| f as usize), &exact, &medial)
}

/// The distances that sort the vertices of one extraction (mm): the offset,
/// the one below which a vertex is outside the new curve whatever its side,
/// the one beyond which it takes its side from a neighbour, and the bound of
/// a measurement.
#[derive(Clone, Copy)]
struct Limits {
    distance: f64,
    inner: f64,
    outer: f64,
    reach: f64,
}

/// The vertices of leaf `l`, whose centre is `dc` from the curves, with
/// their values and feet. A vertex whose distance bounds (triangle inequality
/// from the centre and from the last vertex measured) put it nearer than
/// `inner` gets `-inf`, farther than `outer` NaN; the others a bounded query
/// each, searching from the last foot found (the same foot, found faster).
fn measure_leaf(
    support: &Support,
    field: &CurveField,
    l: u32,
    dc: f64,
    lim: Limits,
) -> Vec<(u32, f64, Option<PolylineFoot>)> {
    let tree = support.vertex_tree();
    let verts = support.mesh().vertices();
    let c = tree.nodes[l as usize].center;
    let slack = tol::SELECTION_SLACK * lim.reach;
    let mut last: Option<(PolylineFoot, Point3)> = None;
    tree.vertices(l as usize)
        .iter()
        .map(|&v| {
            let p = verts[v as usize];
            let e = (p - c).norm();
            let (mut lo, mut hi) = (dc - e, dc + e);
            if let Some((f, q)) = &last {
                let e = (p - q).norm();
                (lo, hi) = (lo.max(f.distance - e), hi.min(f.distance + e));
            }
            if hi + slack < lim.inner {
                return (v, f64::NEG_INFINITY, None);
            }
            if lo - slack > lim.outer {
                return (v, f64::NAN, None);
            }
            match field.foot_near(&p, lim.reach, last.as_ref().map(|l| &l.0)) {
                Some(f) => {
                    last = Some((f, p));
                    (v, field.signed_at(&p, &f) - lim.distance, Some(f))
                }
                None => (v, f64::NAN, None),
            }
        })
        .collect()
}

/// The nodes of the vertex tree whose vertices are all nearer than
/// `lim.inner` to the curves, and the leaves to look into with their
/// centre's distance, in tree order; the nodes left out hold only vertices
/// farther than `lim.outer`.
fn select_nodes(support: &Support, field: &CurveField, lim: Limits) -> (Vec<u32>, Vec<(u32, f64)>) {
    let mut out = (Vec::new(), Vec::new());
    if !support.vertex_tree().nodes.is_empty() {
        select_under(support.vertex_tree(), field, 0, None, lim, &mut out);
    }
    out
}

/// [`select_nodes`] below node `i`, appending to `out`; the query searches
/// from `hint`, the parent's foot. Subtrees of more than
/// [`PARALLEL_VERTICES`] vertices are searched in parallel, their lists
/// joined in tree order.
fn select_under(
    tree: &VertexTree,
    field: &CurveField,
    i: u32,
    hint: Option<&PolylineFoot>,
    lim: Limits,
    out: &mut (Vec<u32>, Vec<(u32, f64)>),
) {
    let n = &tree.nodes[i as usize];
    let r = n.radius * (1.0 + tol::SELECTION_SLACK) + tol::SELECTION_SLACK * lim.reach;
    let Some(f) = field.foot_near(&n.center, lim.outer + r, hint) else { return };
    if f.distance + r < lim.inner {
        out.0.push(i);
    } else if n.second == 0 {
        out.1.push((i, f.distance));
    } else if (n.end - n.start) as usize > PARALLEL_VERTICES {
        let sub = |j: u32| {
            let mut o = (Vec::new(), Vec::new());
            select_under(tree, field, j, Some(&f), lim, &mut o);
            o
        };
        let (a, b) = rayon::join(|| sub(i + 1), || sub(n.second));
        for (near, leaves) in [a, b] {
            out.0.extend(near);
            out.1.extend(leaves);
        }
    } else {
        select_under(tree, field, i + 1, Some(&f), lim, out);
        select_under(tree, field, n.second, Some(&f), lim, out);
    }
}

/// Subtrees of the vertex tree larger than this are searched in parallel.
/// Coarse parallel tasks: on a shared machine a thread may wait for a core,
/// and a join waits for it.
const PARALLEL_VERTICES: usize = 32_768;

/// Fewest leaves measured by one parallel task (same reason).
const LEAVES_PER_TASK: usize = 16;

/// Gives the far corners (NaN) of `facets` the side of their lowest-numbered
/// measured neighbour (the positive side gets `+inf`). This is what a flood
/// from the measured vertices, taken in order, gives them: a far vertex is
/// more than a facet from the curves, so no edge from it crosses the curves,
/// and a connected set of far vertices lies on one side. Every
/// facet of `facets` has a measured corner, which is a neighbour of the
/// others.
fn side_far_corners(support: &Support, facets: &[u32], values: &mut [f64]) {
    let tris = support.mesh().triangles();
    let mut far: Vec<u32> =
        facets.iter().flat_map(|&f| tris[f as usize]).filter(|&v| values[v as usize].is_nan()).collect();
    far.sort_unstable();
    far.dedup();
    let sides: Vec<f64> = far
        .iter()
        .map(|&v| {
            let measured = support.neighbours(v as usize).iter().find(|&&w| values[w as usize].is_finite());
            if measured.is_some_and(|&w| values[w as usize] > 0.0) { f64::INFINITY } else { f64::NEG_INFINITY }
        })
        .collect();
    for (&v, side) in far.iter().zip(sides) {
        values[v as usize] = side;
    }
}

/// Whether facet `f` is crossed by the medial axis: the feet of its corners
/// (`foot(v)`, `None` when not measured) are farther apart than
/// [`tol::MEDIAL_FOOT_FACTOR`] times its longest edge.
fn medial_facet(support: &Support, f: usize, foot: impl Fn(u32) -> Option<Point3>) -> bool {
    let mesh = support.mesh();
    let [Some(a), Some(b), Some(c)] = mesh.triangles()[f].map(foot) else { return false };
    let spread = (a - b).norm().max((b - c).norm()).max((c - a).norm());
    let tri = mesh.triangle(f);
    let size = (tri[1] - tri[0]).norm().max((tri[2] - tri[1]).norm()).max((tri[0] - tri[2]).norm());
    spread > tol::MEDIAL_FOOT_FACTOR * size
}

pub(crate) fn check_step(step: f64) -> Result<(), GuideError> {
    if step.is_finite() && step > 0.0 { Ok(()) } else { Err(GuideError::BadLength { name: "a_e", value: step }) }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, reason = "a test: a panic is the failure report")]

    use proptest::prelude::*;
    use scallop_mesh::{Polyline3, TriMesh};

    use super::*;
    use crate::facets::march;

    /// The brute-force oracle of [`offset_once`]: every vertex within the
    /// reach measured, the others given their side by a flood over the vertex
    /// adjacency from the measured ones (taken in order), every facet marched.
    fn offset_once_scan(support: &Support, curves: &[Curve], distance: f64) -> Isolines {
        let field = CurveField::new(curves);
        let reach = distance + 2.0 * support.facet_size();
        let verts = support.mesh().vertices();
        let feet: Vec<Option<PolylineFoot>> = verts.iter().map(|p| field.foot_within(p, reach)).collect();
        let mut values: Vec<f64> =
            verts.iter().zip(&feet).map(|(p, f)| f.map_or(f64::NAN, |f| field.signed_at(p, &f) - distance)).collect();
        let mut queue: std::collections::VecDeque<usize> = (0..verts.len()).filter(|&v| feet[v].is_some()).collect();
        loop {
            while let Some(u) = queue.pop_front() {
                let side = if values[u] > 0.0 { f64::INFINITY } else { f64::NEG_INFINITY };
                for &w in support.neighbours(u) {
                    if values[w as usize].is_nan() {
                        values[w as usize] = side;
                        queue.push_back(w as usize);
                    }
                }
            }
            let Some(v) = values.iter().position(|x| x.is_nan()) else { break };
            values[v] = if field.signed(&verts[v]) > 0.0 { f64::INFINITY } else { f64::NEG_INFINITY };
            queue.push_back(v);
        }
        let exact = |p: &Point3| field.signed(p) - distance;
        let medial = |f: usize| medial_facet(support, f, |v| feet[v as usize].map(|f| f.point));
        march(support, &values, &exact, &medial)
    }

    /// `z = height(x, y)` over `[-half, half]^2` in `n x n` cells.
    fn terrain(n: usize, half: f64, height: impl Fn(f64, f64) -> f64) -> Support {
        let mut v = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                let (x, y) = (2.0 * half * i as f64 / n as f64 - half, 2.0 * half * j as f64 / n as f64 - half);
                v.push(Point3::new(x, y, height(x, y)));
            }
        }
        let t: Vec<[usize; 3]> = (0..n)
            .flat_map(|j| {
                (0..n).flat_map(move |i| {
                    let a = j * (n + 1) + i;
                    [[a, a + 1, a + n + 2], [a, a + n + 2, a + n + 1]]
                })
            })
            .collect();
        Support::new(TriMesh::from_indexed(&v, &t).unwrap().0)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        /// The vertices picked by the tree give the offsets of the full scan
        /// on random terrains and random star-shaped loops (peanuts split).
        #[test]
        fn tree_selection_gives_the_full_scan_offsets(
            n in 24usize..64, amp in 0.0..6.0f64, wx in 6.0..30.0f64, wy in 6.0..30.0f64,
            r0 in 8.0..17.0f64, wobble in 0.0..0.45f64, lobes in 1u32..5, phase in 0.0..6.3f64,
            cx in -3.0..3.0f64, a_e in 1.0..6.0f64,
        ) {
            let height = move |x: f64, y: f64| amp * (x / wx).sin() * (y / wy).cos();
            let support = terrain(n, 20.0, height);
            let pts: Vec<Point3> = (0..200)
                .map(|i| {
                    let t = std::f64::consts::TAU * f64::from(i) / 200.0;
                    let r = r0 * (1.0 + wobble * (f64::from(lobes) * t + phase).sin());
                    let (x, y) = (cx + r * t.cos(), r * t.sin());
                    support.query().closest_point(&Point3::new(x, y, height(x, y))).point
                })
                .collect();
            let limit = support.curve(Polyline3::new(pts, true)).unwrap().inside_left();
            let fast = iterate(&support, std::slice::from_ref(&limit), a_e, offset_once).unwrap();
            let scan = iterate(&support, std::slice::from_ref(&limit), a_e, offset_once_scan).unwrap();
            prop_assert!(!fast.is_empty());
            prop_assert_eq!(fast, scan);
        }
    }
}
