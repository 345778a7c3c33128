//! Geometry shared by the planner and the verification: the feed frame, the
//! height of the part under a point, and the surface normal at a contact.

use scallop_cutter::{ClPoint, Contact, CutterShape};
use scallop_geom::{Aabb2, Point2, Point3, Vec2, Vec3, predicates};
use scallop_mesh::MeshIndex;

use crate::tol;

/// The feed frame of a direction angle `theta`: feed `f = (cos, sin)`, plane
/// normal `m = (-sin, cos)`. A point has feed coordinate `t = f . p` and plane
/// offset `d = m . p`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Frame {
    pub(crate) f: Vec2,
    pub(crate) m: Vec2,
}

impl Frame {
    pub(crate) fn new(direction: f64) -> Frame {
        let (s, c) = direction.sin_cos();
        Frame { f: Vec2::new(c, s), m: Vec2::new(-s, c) }
    }

    pub(crate) fn xy(&self, t: f64, d: f64) -> Point2 {
        Point2::from(self.f * t + self.m * d)
    }

    pub(crate) fn t(&self, p: &Point3) -> f64 {
        self.f.x * p.x + self.f.y * p.y
    }

    pub(crate) fn d(&self, p: &Point3) -> f64 {
        self.m.x * p.x + self.m.y * p.y
    }
}

/// The highest point of the part vertically under/over `xy` and its unit
/// normal (z >= 0), or `None` when `xy` is outside the part's XY projection.
/// Inclusion is the exact closed in-triangle test.
pub(crate) fn surface_at(index: &MeshIndex, xy: Point2, scratch: &mut Vec<u32>) -> Option<(f64, Vec3)> {
    scratch.clear();
    index.collect_box(&Aabb2::around(xy, 0.0), scratch);
    let mut best: Option<(f64, Vec3)> = None;
    for &slot in scratch.iter() {
        let slot = slot as usize;
        let c = index.corners(slot);
        let (a, b, cc) = (c[0].xy(), c[1].xy(), c[2].xy());
        if !predicates::in_triangle(&xy, &a, &b, &cc) {
            continue;
        }
        let area = predicates::orient2d(&a, &b, &cc);
        if area == 0.0 {
            continue; // vertical triangle: its neighbours give the height
        }
        // Barycentric interpolation of z.
        let (wa, wb, wc) = (
            predicates::orient2d(&b, &cc, &xy) / area,
            predicates::orient2d(&cc, &a, &xy) / area,
            predicates::orient2d(&a, &b, &xy) / area,
        );
        let z = wa * c[0].z + wb * c[1].z + wc * c[2].z;
        if best.is_none_or(|(bz, _)| z > bz) {
            best = Some((z, *index.normal(slot)));
        }
    }
    best
}

/// For each triangle number of the source mesh, its slot in the index.
pub(crate) fn slots_by_original(index: &MeshIndex) -> Vec<u32> {
    let n = (0..index.len()).map(|s| index.original_index(s) + 1).max().unwrap_or(0);
    let mut map = vec![0u32; n];
    for slot in 0..index.len() {
        map[index.original_index(slot)] = u32::try_from(slot).unwrap_or(u32::MAX);
    }
    map
}

/// Unit surface normal (z >= 0) at the contact of `cl`.
///
/// Where the cutter's own surface is smooth at the contact (a ball everywhere,
/// a bull-nose on its torus) the normal is the cutter's normal there: at a
/// tangent contact it equals the part's normal, and at an edge or vertex
/// contact it is the normal of the envelope the cutter actually leaves.
/// Elsewhere (flat bottoms, a flat cutter's rim) it is the normal of the contact
/// triangle. `Floor` gives +Z.
pub(crate) fn contact_normal(shape: &CutterShape, index: &MeshIndex, slots: &[u32], cl: &ClPoint) -> Vec3 {
    let (triangle, point) = match cl.contact {
        Contact::Floor => return Vec3::z(),
        Contact::Vertex { triangle, point }
        | Contact::Edge { triangle, point }
        | Contact::Facet { triangle, point } => (triangle, point),
    };
    let tip = cl.tip;
    let from_cutter = match *shape {
        CutterShape::Ball { radius } => Some(Point3::new(tip.x, tip.y, tip.z + radius) - point),
        CutterShape::Bull { radius, corner } if !on_flat_bottom(shape, cl) => {
            let radial = Vec2::new(point.x - tip.x, point.y - tip.y);
            let ring = radial * ((radius - corner) / radial.norm());
            Some(Point3::new(tip.x + ring.x, tip.y + ring.y, tip.z + corner) - point)
        }
        CutterShape::Bull { .. } | CutterShape::Flat { .. } | CutterShape::Cone { .. } => None,
    };
    if let Some(n) = from_cutter {
        let len = n.norm();
        if len > 0.0 {
            return n / len;
        }
    }
    slots.get(triangle).map_or_else(Vec3::z, |&slot| *index.normal(slot as usize))
}

/// Whether the contact of `cl` lies under the flat bottom of a bull-nose
/// (within `tol::TORUS_CONTACT_REL` of the radius from the torus), where the
/// cutter's own normal is +Z. `false` for every other shape and for `Floor`.
pub(crate) fn on_flat_bottom(shape: &CutterShape, cl: &ClPoint) -> bool {
    let (CutterShape::Bull { radius, corner }, Some(point)) = (*shape, contact_point(cl)) else { return false };
    let rho = Vec2::new(point.x - cl.tip.x, point.y - cl.tip.y).norm();
    rho <= radius - corner + tol::TORUS_CONTACT_REL * radius
}

fn contact_point(cl: &ClPoint) -> Option<Point3> {
    match cl.contact {
        Contact::Floor => None,
        Contact::Vertex { point, .. } | Contact::Edge { point, .. } | Contact::Facet { point, .. } => Some(point),
    }
}

/// Bit pattern of a point: welded meshes share exact vertex coordinates.
fn key(p: &Point3) -> [u64; 3] {
    [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()]
}

fn edge_key(a: &Point3, b: &Point3) -> ([u64; 3], [u64; 3]) {
    let (ka, kb) = (key(a), key(b));
    if ka <= kb { (ka, kb) } else { (kb, ka) }
}

/// The open boundary of the part: edges used by one triangle only, and their vertices.
pub(crate) struct PartBoundary {
    edges: std::collections::HashSet<([u64; 3], [u64; 3])>,
    vertices: std::collections::HashSet<[u64; 3]>,
}

impl PartBoundary {
    pub(crate) fn new(index: &MeshIndex) -> PartBoundary {
        let mut count: std::collections::HashMap<([u64; 3], [u64; 3]), u32> = std::collections::HashMap::new();
        for slot in 0..index.len() {
            let c = index.corners(slot);
            for k in 0..3 {
                *count.entry(edge_key(&c[k], &c[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        let edges: std::collections::HashSet<_> = count.into_iter().filter(|&(_, n)| n == 1).map(|(e, _)| e).collect();
        let vertices = edges.iter().flat_map(|(a, b)| [*a, *b]).collect();
        PartBoundary { edges, vertices }
    }

    /// Whether the contact of `cl` lies on the part away from its open boundary:
    /// a facet contact, or an edge or vertex contact on an interior edge or vertex.
    pub(crate) fn is_interior_contact(&self, index: &MeshIndex, slots: &[u32], cl: &ClPoint) -> bool {
        let (triangle, point, is_vertex) = match cl.contact {
            Contact::Floor => return false,
            Contact::Facet { .. } => return true,
            Contact::Edge { triangle, point } => (triangle, point, false),
            Contact::Vertex { triangle, point } => (triangle, point, true),
        };
        let Some(&slot) = slots.get(triangle) else { return false };
        let c = index.corners(slot as usize);
        // The contact is outside when it lies on a boundary vertex or edge (ties
        // at shared corners count against it: conservative).
        let scale = (c[1] - c[0]).norm().max((c[2] - c[1]).norm()).max((c[0] - c[2]).norm());
        let on = tol::ON_FEATURE_REL * scale;
        if c.iter().any(|v| (v - point).norm() <= on && self.vertices.contains(&key(v))) {
            return false;
        }
        if is_vertex {
            let nearest = c.iter().min_by(|a, b| (*a - point).norm_squared().total_cmp(&(*b - point).norm_squared()));
            return nearest.is_some_and(|v| !self.vertices.contains(&key(v)));
        }
        let mut best = f64::INFINITY;
        let mut boundary_near = false;
        for k in 0..3 {
            let (a, b) = (&c[k], &c[(k + 1) % 3]);
            let ab = b - a;
            let s = ((point - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
            let dist = (point - (a + ab * s)).norm();
            best = best.min(dist);
            if dist <= on && self.edges.contains(&edge_key(a, b)) {
                boundary_near = true;
            }
        }
        if boundary_near {
            return false;
        }
        // The edge the contact lies on is interior (or, off every edge by rounding, the nearest one is).
        (0..3).all(|k| {
            let (a, b) = (&c[k], &c[(k + 1) % 3]);
            let ab = b - a;
            let s = ((point - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
            let dist = (point - (a + ab * s)).norm();
            dist > best || !self.edges.contains(&edge_key(a, b))
        })
    }
}

/// From a contact point with upward unit normal `n` to the tip of the vertical
/// cutter touching the surface there: the corner circle's centre is `r n` from
/// the contact, the axis `(R - r)` from it along the horizontal part of `n`
/// (downhill: the cutter touches a slope with its uphill side), the tip `r`
/// below (ball `r = R`, flat and cone `r = 0`).
pub fn contact_to_tip(shape: &CutterShape, n: &Vec3) -> Vec3 {
    let (radius, corner) = match *shape {
        CutterShape::Ball { radius } => (radius, radius),
        CutterShape::Bull { radius, corner } => (radius, corner),
        CutterShape::Flat { radius } | CutterShape::Cone { radius, .. } => (radius, 0.0),
    };
    let side = n.xy().try_normalize(tol::HORIZONTAL_XY).map_or(Vec3::zeros(), |h| Vec3::new(h.x, h.y, 0.0));
    n * corner + side * (radius - corner) - Vec3::z() * corner
}
