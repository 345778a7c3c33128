//! Tool placement along an arbitrary axis (module G of the spec; Jousselin
//! 2020, Ch. 2 §1.2.3, Fig. 2.12-2.13): the tool, on the line through a guide
//! point along its axis u, is moved along -u until it first touches the level
//! mesh. In the tool frame (origin the guide point, z = u) this is exactly the
//! 3-axis drop-cutter at (0, 0), so every triangle is dropped with
//! [`scallop_cutter::drop_triangle`] (vertex, edge and facet contacts, the
//! maximum over features). A bounding-volume hierarchy over the triangles'
//! boxes grown by the tool radius gives the triangles the tool's cylinder can
//! meet: a box grown by R contains every point within R of the triangle, so a
//! line that passes within R of a triangle meets its grown box.
//!
//! An allowance s is exact: the tool (R, r) on the offset of the mesh by s is
//! the tool (R + s, r + s) on the mesh, its tip s lower along the axis (a
//! Minkowski sum with a ball of radius s; a flat tool grows into a torus).
//!
//! C_L, the driven point of the thesis, is on the axis at the height of the
//! torus centre circle (tip + r u); the contact C_C and its normal n satisfy
//! Eq. 1.1, `C_L = C_C + r n + (R - r) (n - (n.u) u) / |n - (n.u) u|`, which the
//! tests check (the spec's [IMPL] note: C_L comes from the placed tool and
//! Eq. 1.1 is the consistency check).

use scallop_cutter::{ClPoint, Contact, Cutter, CutterShape, drop_triangle};
use scallop_geom::{Aabb3, Point2, Point3, Vec3};
use scallop_mesh::{Bvh, MeshQuery, TriMesh};

use crate::{Rough5Error, tol};

/// Which feature of the mesh the tool touches.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Feature {
    /// A triangle corner.
    Vertex,
    /// A triangle edge.
    Edge,
    /// The interior of a triangle.
    Facet,
}

/// A tool placed on the mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placement {
    /// The tool tip (lowest point of the tool on its axis), mm.
    pub tip: Point3,
    /// The unit tool axis (from the tip towards the spindle).
    pub axis: Vec3,
    /// C_L: the point of the axis at the height of the torus centre circle,
    /// `tip + r axis` (r = R for a ball, 0 for a flat tool).
    pub cl: Point3,
    /// C_C: the contact on the mesh offset by the allowance.
    pub contact: Point3,
    /// The unit normal at C_C, pointing towards the tool.
    pub normal: Vec3,
    /// The feature touched.
    pub feature: Feature,
    /// The triangle touched.
    pub triangle: usize,
    /// Distance from the guide point to the tip along the axis (negative
    /// when the tip is below the guide point).
    pub drop: f64,
}

/// A level mesh indexed for placing one tool along any axis.
#[derive(Debug, Clone)]
pub struct Placer {
    /// The triangles and their unit normals.
    query: MeshQuery,
    /// Over the triangles' boxes grown by the grown tool's radius.
    bvh: Bvh,
    /// The cutter grown by the allowance.
    grown: Cutter,
    allowance: f64,
    /// Corner radius r of the real tool (R for a ball, 0 for a flat tool).
    corner: f64,
    /// Bounding box of the mesh and its diagonal, for the line's extent.
    bounds: Aabb3,
}

/// The cutter grown by `s` (a Minkowski sum with a ball of radius s) and the
/// real tool's corner radius.
fn grow(cutter: &Cutter, s: f64) -> Result<(Cutter, f64), Rough5Error> {
    let (shape, corner) = match *cutter.shape() {
        CutterShape::Ball { radius } => (CutterShape::Ball { radius: radius + s }, radius),
        CutterShape::Bull { radius, corner } => (CutterShape::Bull { radius: radius + s, corner: corner + s }, corner),
        CutterShape::Flat { radius } if s > 0.0 => (CutterShape::Bull { radius: radius + s, corner: s }, 0.0),
        CutterShape::Flat { radius } => (CutterShape::Flat { radius }, 0.0),
        CutterShape::Cone { .. } => return Err(Rough5Error::UnsupportedCutter { what: "cone" }),
    };
    let grown = Cutter::new(shape, cutter.flute_length() + s)
        .map_err(|e| Rough5Error::BadAllowance { allowance: s, reason: e.to_string() })?;
    Ok((grown, corner))
}

/// An orthonormal frame (e1, e2, u) with e3 = u; the identity for u = +Z.
#[must_use]
pub fn tool_frame(u: &Vec3) -> (Vec3, Vec3) {
    let seed = if u.x.abs() < tol::FRAME_SWITCH { Vec3::x() } else { Vec3::y() };
    let e1 = (seed - u * seed.dot(u)).normalize();
    (e1, u.cross(&e1))
}

impl Placer {
    /// Indexes `mesh` for `cutter` with `allowance` (mm, >= 0) left on it.
    ///
    /// # Errors
    /// [`Rough5Error::BadSetting`] for a negative or non-finite allowance,
    /// [`Rough5Error::UnsupportedCutter`] for a cone,
    /// [`Rough5Error::BadAllowance`] when the grown cutter is invalid.
    pub fn new(mesh: &TriMesh, cutter: &Cutter, allowance: f64) -> Result<Placer, Rough5Error> {
        if !(allowance.is_finite() && allowance >= 0.0) {
            return Err(Rough5Error::BadSetting { name: "allowance", value: allowance });
        }
        let (grown, corner) = grow(cutter, allowance)?;
        let reach = grown.radius();
        let query = MeshQuery::new(mesh);
        let grow_box = |t: &[Point3; 3]| {
            let b = scallop_mesh::triangle_box(t);
            let r = Vec3::repeat(reach);
            Aabb3 { min: b.min - r, max: b.max + r }
        };
        let boxes: Vec<Aabb3> = (0..query.len()).map(|i| grow_box(query.triangle(i))).collect();
        let bounds =
            boxes.iter().skip(1).fold(boxes[0], |a, b| Aabb3 { min: a.min.inf(&b.min), max: a.max.sup(&b.max) });
        Ok(Placer { query, bvh: Bvh::build(&boxes), grown, allowance, corner, bounds })
    }

    /// The allowance left on the mesh (mm).
    #[must_use]
    pub fn allowance(&self) -> f64 {
        self.allowance
    }

    /// The tool on the line through `point` along `axis` (any length, not
    /// zero), moved along the axis to its first tangent contact with the
    /// mesh coming from +axis; `None` when the tool's cylinder misses the
    /// mesh.
    #[must_use]
    pub fn place(&self, point: &Point3, axis: &Vec3) -> Option<Placement> {
        let u = axis.normalize();
        if !u.iter().all(|c| c.is_finite()) {
            return None;
        }
        let (e1, e2) = tool_frame(&u);
        let local = |q: &Point3| {
            let d = q - point;
            Point3::new(d.dot(&e1), d.dot(&e2), d.dot(&u))
        };
        let centre = Point3::from((self.bounds.min.coords + self.bounds.max.coords) * 0.5);
        let extent = (self.bounds.max - self.bounds.min).norm() + (point - centre).norm() + 1.0;
        let mut best = ClPoint::floor(Point2::origin(), -2.0 * extent);
        self.bvh.visit_ray(point, &u, -extent, extent, |i| {
            let c = self.query.triangle(i).map(|q| local(&q));
            let n = self.query.normal(i);
            let mut nl = Vec3::new(n.dot(&e1), n.dot(&e2), n.dot(&u));
            if nl.z < 0.0 {
                nl = -nl;
            }
            drop_triangle(&self.grown, &c, &nl, i, &mut best);
            None
        });
        let (feature, triangle, q) = match best.contact {
            Contact::Floor => return None,
            Contact::Vertex { triangle, point } => (Feature::Vertex, triangle, point),
            Contact::Edge { triangle, point } => (Feature::Edge, triangle, point),
            Contact::Facet { triangle, point } => (Feature::Facet, triangle, point),
        };
        let nl = self.contact_normal(feature, triangle, &q, best.tip.z, (&e1, &e2, &u));
        let world = |v: &Vec3| e1 * v.x + e2 * v.y + u * v.z;
        let normal = world(&nl);
        let contact = point + world(&q.coords) + normal * self.allowance;
        let drop = best.tip.z + self.allowance;
        let tip = point + u * drop;
        Some(Placement { tip, axis: u, cl: tip + u * self.corner, contact, normal, feature, triangle, drop })
    }

    /// The unit normal (tool frame) at the contact `q` of the grown tool
    /// whose tip is at local height `tip`: the facet's normal on a facet,
    /// else from the nearest point of the grown tool's centre circle.
    fn contact_normal(
        &self,
        feature: Feature,
        triangle: usize,
        q: &Point3,
        tip: f64,
        f: (&Vec3, &Vec3, &Vec3),
    ) -> Vec3 {
        if feature == Feature::Facet {
            let n = self.query.normal(triangle);
            let nl = Vec3::new(n.dot(f.0), n.dot(f.1), n.dot(f.2));
            return if nl.z < 0.0 { -nl } else { nl };
        }
        let (radius, corner) = match *self.grown.shape() {
            CutterShape::Ball { radius } => (radius, radius),
            CutterShape::Bull { radius, corner } => (radius, corner),
            _ => (self.grown.radius(), 0.0),
        };
        if corner <= 0.0 {
            return Vec3::z();
        }
        let rho = q.x.hypot(q.y);
        let ring = radius - corner;
        let centre = if rho > tol::ON_AXIS {
            Point3::new(q.x / rho * ring, q.y / rho * ring, tip + corner)
        } else {
            Point3::new(0.0, 0.0, tip + corner)
        };
        let n = centre - q;
        let len = n.norm();
        if len > 0.0 { n / len } else { Vec3::z() }
    }
}
