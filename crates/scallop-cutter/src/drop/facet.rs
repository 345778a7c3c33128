//! Facet contact. For a plane with unit normal n (n_z > 0) the cutter first
//! touches it at its support point in direction -n. Relative to the tip, with
//! u = n_xy / |n_xy| the uphill direction reversed:
//!
//! ```text
//! ball  (R):      (-R n_x, -R n_y, R - R n_z)
//! flat  (R):      (-R u_x, -R u_y, 0)                       (tip itself if n_xy = 0)
//! bull  (R, r):   (-(R-r) u_x - r n_x, -(R-r) u_y - r n_y, r - r n_z)
//! cone  (R, a):   tip (0, 0, 0) while |n_xy| tan a < n_z (plane flatter than the flank),
//!                 else the rim (-R u_x, -R u_y, R / tan a)
//! ```
//!
//! The contact is valid when the support point's XY lies in the triangle
//! (exact predicate); the tip is then at plane_z(support_xy) - dz.

use scallop_geom::{Point2, Point3, Vec3, predicates::in_triangle};

use super::{ClPoint, Contact};
use crate::CutterShape;
use crate::shape::Profile;

/// The cutter resting on the triangle's whole plane: the support point `q`
/// (XY), the plane's height there and the tip height. `None` for a vertical
/// plane. No point of the plane within the cutter's reach can hold the tip
/// higher, so `tip` bounds every contact of the triangle.
#[derive(Debug, Clone, Copy)]
pub(super) struct PlaneContact {
    q: Point2,
    zq: f64,
    pub(super) tip: f64,
}

pub(super) fn plane_contact(profile: &Profile, corners: &[Point3; 3], n: &Vec3, c: Point2) -> Option<PlaneContact> {
    if n.z <= 0.0 {
        return None; // vertical facet: its edges and corners hold every contact
    }
    let nxy = (n.x * n.x + n.y * n.y).sqrt();
    let (ux, uy) = if nxy > 0.0 { (n.x / nxy, n.y / nxy) } else { (0.0, 0.0) };
    let (dx, dy, dz) = match profile.shape {
        CutterShape::Ball { radius } => (-radius * n.x, -radius * n.y, radius - radius * n.z),
        CutterShape::Flat { radius } => (-radius * ux, -radius * uy, 0.0),
        CutterShape::Bull { radius, corner } => {
            let a = radius - corner;
            (-a * ux - corner * n.x, -a * uy - corner * n.y, corner - corner * n.z)
        }
        CutterShape::Cone { radius, .. } => {
            if nxy * profile.tan < n.z {
                (0.0, 0.0, 0.0)
            } else {
                (-radius * ux, -radius * uy, radius * profile.cot)
            }
        }
    };
    let q = Point2::new(c.x + dx, c.y + dy);
    let a = &corners[0];
    // z of the plane at q: n . (p - a) = 0
    let zq = a.z - (n.x * (q.x - a.x) + n.y * (q.y - a.y)) / n.z;
    Some(PlaneContact { q, zq, tip: zq - dz })
}

/// Facet contact: the plane contact, when its support point lies in the triangle.
pub(super) fn drop_facet(plane: &PlaneContact, corners: &[Point3; 3], triangle: usize, best: &mut ClPoint) {
    let PlaneContact { q, zq, tip } = *plane;
    if tip <= best.tip.z {
        return;
    }
    let [a, b, cc] = corners;
    // Cheap rejection by the XY box before the exact test.
    if q.x < a.x.min(b.x).min(cc.x)
        || q.x > a.x.max(b.x).max(cc.x)
        || q.y < a.y.min(b.y).min(cc.y)
        || q.y > a.y.max(b.y).max(cc.y)
    {
        return;
    }
    if in_triangle(&q, &Point2::new(a.x, a.y), &Point2::new(b.x, b.y), &Point2::new(cc.x, cc.y)) {
        best.tip.z = tip;
        best.contact = Contact::Facet { triangle, point: Point3::new(q.x, q.y, zq) };
    }
}
