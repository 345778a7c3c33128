//! An XY bounding-volume hierarchy over a mesh's triangles, with the highest
//! z of each subtree, for branch-and-bound drop-cutter queries: a subtree is
//! skipped when it lies outside the cutter's disk or when nothing in it is
//! higher than the best cutter location found so far.

use scallop_geom::{Aabb2, Point2, Point3, Vec3};

use crate::TriMesh;

const LEAF_SIZE: usize = 4;

#[derive(Clone, Copy, Debug)]
struct Node {
    min: [f64; 2],
    max: [f64; 2],
    zmax: f64,
    /// Leaf: first slot. Inner: index of the second child (the first is `self + 1`).
    first_or_right: u32,
    /// Leaf: number of slots (> 0). Inner: 0.
    count: u32,
}

/// Triangles of a [`TriMesh`] in an XY hierarchy, stored in leaf order
/// ("slots") with the data drop-cutter needs next to each other.
#[derive(Debug, Clone)]
pub struct MeshIndex {
    nodes: Vec<Node>,
    corners: Vec<[Point3; 3]>,
    normals: Vec<Vec3>,
    zmax: Vec<f64>,
    original: Vec<u32>,
    owned: Vec<u8>,
    /// Per slot, the outward lines of the triangle's XY edges (see
    /// [`MeshIndex::edge_lines`]).
    lines: Vec<[[f64; 3]; 3]>,
    bounds: scallop_geom::Aabb3,
    /// Added to every upper bound so that rounding in a contact computation can
    /// never make pruning skip a triangle that would win by a few ulps.
    slack: f64,
}

impl MeshIndex {
    /// Builds the hierarchy (median splits along the longer XY side).
    ///
    /// ```
    /// use scallop_geom::Point3;
    /// use scallop_mesh::{MeshIndex, TriMesh};
    /// let p = |x, y, z| Point3::new(x, y, z);
    /// let (mesh, _) = TriMesh::from_soup(&[[p(0., 0., 1.), p(1., 0., 1.), p(0., 1., 1.)]]).unwrap();
    /// let index = MeshIndex::build(&mesh);
    /// assert_eq!(index.len(), 1);
    /// ```
    #[must_use]
    pub fn build(mesh: &TriMesh) -> MeshIndex {
        let n = mesh.triangles().len();
        let tris: Vec<[Point3; 3]> = (0..n).map(|i| mesh.triangle(i)).collect();
        let centroid: Vec<[f64; 2]> =
            tris.iter().map(|t| [(t[0].x + t[1].x + t[2].x) / 3.0, (t[0].y + t[1].y + t[2].y) / 3.0]).collect();
        let mut order: Vec<u32> = (0..u32::try_from(n).unwrap_or(u32::MAX)).collect();
        let mut nodes = Vec::with_capacity(2 * n / LEAF_SIZE + 1);
        build_node(&mut nodes, &tris, &centroid, &mut order, 0);
        let corners: Vec<[Point3; 3]> = order.iter().map(|&i| tris[i as usize]).collect();
        let normals = corners
            .iter()
            .map(|t| {
                let n = (t[1] - t[0]).cross(&(t[2] - t[0]));
                let n = if n.z < 0.0 { -n } else { n };
                let len = n.norm();
                if len > 0.0 { n / len } else { Vec3::zeros() }
            })
            .collect();
        let zmax = corners.iter().map(|t| t[0].z.max(t[1].z).max(t[2].z)).collect();
        let slack = scallop_geom::tol::REL_PRUNE_SLACK * mesh.bounds().max_abs_coord().max(1.0);
        let owned = ownership(mesh, &order);
        let lines = corners.iter().map(edge_lines).collect();
        MeshIndex { nodes, corners, normals, zmax, original: order, owned, lines, bounds: mesh.bounds(), slack }
    }

    /// Number of triangles.
    #[must_use]
    pub fn len(&self) -> usize {
        self.corners.len()
    }

    /// Whether there is no triangle (never true for an index of a valid mesh).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.corners.is_empty()
    }

    /// Bounding box of the indexed mesh.
    #[must_use]
    pub fn bounds(&self) -> scallop_geom::Aabb3 {
        self.bounds
    }

    /// Corners of the triangle in `slot`.
    #[must_use]
    pub fn corners(&self, slot: usize) -> &[Point3; 3] {
        &self.corners[slot]
    }

    /// Unit normal of the triangle in `slot`, oriented with `z >= 0`.
    #[must_use]
    pub fn normal(&self, slot: usize) -> &Vec3 {
        &self.normals[slot]
    }

    /// Highest z of the triangle in `slot`.
    #[must_use]
    pub fn zmax(&self, slot: usize) -> f64 {
        self.zmax[slot]
    }

    /// The triangle number in the source mesh of `slot`.
    #[must_use]
    pub fn original_index(&self, slot: usize) -> usize {
        self.original[slot] as usize
    }

    /// Which corners and edges of the triangle in `slot` it owns: bit k
    /// (k = 0, 1, 2) for corner k, bit 3 + k for the edge from corner k to
    /// corner k + 1 (mod 3). Every vertex and edge of the mesh is owned by
    /// exactly one triangle that contains it (the first in slot order), so a
    /// search that tests only owned features tests each once; it stays exact
    /// because the owner's bounds cover the feature.
    #[must_use]
    pub fn owned_features(&self, slot: usize) -> u8 {
        self.owned[slot]
    }

    /// Appends to `out` every slot whose triangle's XY box meets `query`
    /// (closed test), in leaf order.
    pub fn collect_box(&self, query: &Aabb2, out: &mut Vec<u32>) {
        let mut stack: [u32; 64] = [0; 64];
        let mut top = 1usize;
        while top > 0 {
            top -= 1;
            let id = stack[top];
            let node = &self.nodes[id as usize];
            let b = Aabb2 { min: Point2::new(node.min[0], node.min[1]), max: Point2::new(node.max[0], node.max[1]) };
            if !b.overlaps(query) {
                continue;
            }
            if node.count > 0 {
                let first = node.first_or_right as usize;
                for slot in first..first + node.count as usize {
                    if self.xy_box(slot).overlaps(query) {
                        out.push(u32::try_from(slot).unwrap_or(u32::MAX));
                    }
                }
            } else {
                stack[top] = node.first_or_right;
                stack[top + 1] = id + 1;
                top += 2;
            }
        }
    }

    /// XY bounding box of the triangle in `slot`.
    #[must_use]
    pub fn xy_box(&self, slot: usize) -> Aabb2 {
        let t = &self.corners[slot];
        Aabb2 {
            min: Point2::new(t[0].x.min(t[1].x).min(t[2].x), t[0].y.min(t[1].y).min(t[2].y)),
            max: Point2::new(t[0].x.max(t[1].x).max(t[2].x), t[0].y.max(t[1].y).max(t[2].y)),
        }
    }

    /// The slack added to every upper bound by the searches (mm); callers that
    /// prune on their own use the same.
    #[must_use]
    pub fn slack(&self) -> f64 {
        self.slack
    }

    /// The lines of the XY edges of the triangle in `slot`, `[nx, ny, c]` with
    /// `(nx, ny)` the unit normal pointing away from the triangle, so that
    /// `nx x + ny y - c` is the signed distance of (x, y) to the edge's line;
    /// `[0, 0, inf]` (no bound) for a triangle whose XY projection has no area
    /// (a vertical wall). See [`MeshIndex::edge_distance`].
    #[must_use]
    pub fn edge_lines(&self, slot: usize) -> &[[f64; 3]; 3] {
        &self.lines[slot]
    }

    /// A lower bound of the XY distance from `p` to the triangle in `slot`,
    /// up to rounding: the largest signed distance to its edges' lines (a
    /// triangle lies inside each of its edges' half-planes). Not above 0
    /// where `p` is inside the triangle's XY projection, `-inf` for a
    /// triangle without XY area; tighter than its box's distance for a long
    /// thin triangle. Callers lower it by [`MeshIndex::slack`] before pruning.
    #[must_use]
    #[inline]
    pub fn edge_distance(&self, slot: usize, p: Point2) -> f64 {
        Self::line_distance(&self.lines[slot], p)
    }

    /// [`MeshIndex::edge_distance`] on a copy of [`MeshIndex::edge_lines`].
    #[must_use]
    #[inline]
    pub fn line_distance(lines: &[[f64; 3]; 3], p: Point2) -> f64 {
        let [l0, l1, l2] = lines;
        (l0[0] * p.x + l0[1] * p.y - l0[2])
            .max(l1[0] * p.x + l1[1] * p.y - l1[2])
            .max(l2[0] * p.x + l2[1] * p.y - l2[2])
    }

    /// Branch-and-bound search for the highest cutter location over the disk of
    /// `radius` around `center`. `lift(d2)` must be a lower bound of how far the
    /// cutter's profile rises above its tip at squared horizontal distance
    /// `>= d2` (non-decreasing; `|_| 0.0` is always valid). A subtree or triangle
    /// is visited only if its highest z minus `lift` of its squared distance to
    /// `center` exceeds `*bound`, i.e. only if it could raise the result; the
    /// more promising child is visited first. `visit(slot, bound)` may raise
    /// `*bound`, which prunes the rest of the search.
    pub fn visit_disk(
        &self,
        center: Point2,
        radius: f64,
        lift: impl Fn(f64) -> f64,
        bound: &mut f64,
        mut visit: impl FnMut(usize, &mut f64),
    ) {
        let r2 = radius * radius;
        let node_box = |n: &Node| Aabb2 { min: Point2::new(n.min[0], n.min[1]), max: Point2::new(n.max[0], n.max[1]) };
        // Upper bound of what a node can give, or None when it is out of reach.
        let reach = |n: &Node| {
            let d2 = node_box(n).distance_squared(&center);
            (d2 <= r2).then(|| n.zmax - lift(d2) + self.slack)
        };
        let mut stack: [(u32, f64); 64] = [(0, 0.0); 64];
        let mut top = 0usize;
        if let Some(ub) = reach(&self.nodes[0]) {
            stack[0] = (0, ub);
            top = 1;
        }
        while top > 0 {
            top -= 1;
            let (id, ub) = stack[top];
            if ub <= *bound {
                continue;
            }
            let node = &self.nodes[id as usize];
            if node.count > 0 {
                let first = node.first_or_right as usize;
                for slot in first..first + node.count as usize {
                    if self.zmax[slot] + self.slack <= *bound {
                        continue;
                    }
                    let d2 = self.xy_box(slot).distance_squared(&center);
                    if !(d2 <= r2 && self.zmax[slot] - lift(d2) + self.slack > *bound) {
                        continue;
                    }
                    // The distance to the triangle's edge lines, lowered by
                    // the slack (its rounding), where it says more than the box's.
                    let side = self.edge_distance(slot, center) - self.slack;
                    if side > 0.0 && side * side > d2 {
                        let d2 = side * side;
                        if !(d2 <= r2 && self.zmax[slot] - lift(d2) + self.slack > *bound) {
                            continue;
                        }
                    }
                    visit(slot, bound);
                }
            } else {
                let (left, right) = (id + 1, node.first_or_right);
                let a = reach(&self.nodes[left as usize]).map(|ub| (left, ub));
                let b = reach(&self.nodes[right as usize]).map(|ub| (right, ub));
                let (first, second) = match (a, b) {
                    (Some(a), Some(b)) if a.1 >= b.1 => (Some(b), Some(a)),
                    (a, b) => (a, b),
                };
                // Pushed so that the higher bound pops first. Depth is at most
                // log2(n / LEAF_SIZE) + 1 < 64 for any n that fits in memory.
                for entry in [first, second].into_iter().flatten() {
                    if entry.1 > *bound {
                        stack[top] = entry;
                        top += 1;
                    }
                }
            }
        }
    }
}

/// Ownership masks, see [`MeshIndex::owned_features`].
fn ownership(mesh: &TriMesh, order: &[u32]) -> Vec<u8> {
    let mut vertex_owned = vec![false; mesh.vertices().len()];
    let mut edges: std::collections::BTreeSet<(u32, u32)> = std::collections::BTreeSet::new();
    order
        .iter()
        .map(|&t| {
            let tri = mesh.triangles()[t as usize];
            let mut mask = 0u8;
            for k in 0..3 {
                let v = tri[k] as usize;
                if !vertex_owned[v] {
                    vertex_owned[v] = true;
                    mask |= 1 << k;
                }
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                if edges.insert((a.min(b), a.max(b))) {
                    mask |= 1 << (3 + k);
                }
            }
            mask
        })
        .collect()
}

fn build_node(
    nodes: &mut Vec<Node>,
    tris: &[[Point3; 3]],
    centroid: &[[f64; 2]],
    order: &mut [u32],
    offset: usize,
) -> usize {
    let mut min = [f64::INFINITY; 2];
    let mut max = [f64::NEG_INFINITY; 2];
    let mut zmax = f64::NEG_INFINITY;
    for &i in order.iter() {
        for p in &tris[i as usize] {
            min[0] = min[0].min(p.x);
            min[1] = min[1].min(p.y);
            max[0] = max[0].max(p.x);
            max[1] = max[1].max(p.y);
            zmax = zmax.max(p.z);
        }
    }
    let me = nodes.len();
    let to_u32 = |v: usize| u32::try_from(v).unwrap_or(u32::MAX);
    if order.len() <= LEAF_SIZE {
        nodes.push(Node { min, max, zmax, first_or_right: to_u32(offset), count: to_u32(order.len()) });
        return me;
    }
    nodes.push(Node { min, max, zmax, first_or_right: 0, count: 0 });
    let axis = usize::from(max[1] - min[1] > max[0] - min[0]);
    let mid = order.len() / 2;
    order.select_nth_unstable_by(mid, |&a, &b| {
        centroid[a as usize][axis].total_cmp(&centroid[b as usize][axis]).then(a.cmp(&b))
    });
    let (left, right) = order.split_at_mut(mid);
    build_node(nodes, tris, centroid, left, offset);
    let r = build_node(nodes, tris, centroid, right, offset + mid);
    nodes[me].first_or_right = to_u32(r);
    me
}

/// The outward edge lines of [`MeshIndex::edge_lines`]. The orientation
/// comes from the sign of the XY area, trusted only where the area is far
/// above its rounding (`SLIVER` times the square of the longest edge, that
/// edge far above the coordinates' rounding): a flipped sign would turn every
/// line inwards. A thinner triangle (a vertical wall, a sliver) gets the two
/// sides of its longest edge's line, each moved out by the third corner's
/// distance to it: `|n p - c| - h`, a lower bound of the distance to it.
fn edge_lines(corners: &[Point3; 3]) -> [[f64; 3]; 3] {
    const NONE: [[f64; 3]; 3] = [[0.0, 0.0, f64::INFINITY]; 3];
    /// Least XY area (twice it) per squared longest edge for oriented lines.
    const SLIVER: f64 = 1e-6;
    let [a, b, c] = corners;
    let area2 = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    let len = |k: usize| {
        let (p, q) = (&corners[k], &corners[(k + 1) % 3]);
        (q.x - p.x).hypot(q.y - p.y)
    };
    let lens = [len(0), len(1), len(2)];
    let k = (0..3).fold(0, |m, k| if lens[k] > lens[m] { k } else { m });
    let longest = lens[k];
    let scale = corners.iter().fold(1.0_f64, |m, p| m.max(p.x.abs()).max(p.y.abs()));
    if longest.is_nan() || longest <= 1e-6 * scale {
        return NONE; // every corner at one XY point, or not finite
    }
    let unit = |k: usize, sign: f64| {
        let (p, q) = (&corners[k], &corners[(k + 1) % 3]);
        let (nx, ny) = (sign * (q.y - p.y) / lens[k], -sign * (q.x - p.x) / lens[k]);
        [nx, ny, nx * p.x + ny * p.y]
    };
    if area2.abs() > SLIVER * longest * longest {
        // Counter-clockwise in XY, the outside of edge p -> q is on its right.
        let sign = area2.signum();
        return [unit(0, sign), unit(1, sign), unit(2, sign)];
    }
    let [nx, ny, d] = unit(k, 1.0);
    let far = &corners[(k + 2) % 3];
    let h = (nx * far.x + ny * far.y - d).abs();
    [[nx, ny, d + h], [-nx, -ny, -d + h], NONE[0]]
}
