//! Vertex contact: a corner at horizontal distance rho <= R from the axis
//! touches the profile at height h(rho), so the tip is at `z - h(rho)`.

use scallop_geom::{Point2, Point3};

use super::{ClPoint, Contact};
use crate::shape::Profile;

pub(super) fn drop_vertices(
    profile: &Profile,
    corners: &[Point3; 3],
    features: u8,
    triangle: usize,
    c: Point2,
    best: &mut ClPoint,
) {
    let r2 = profile.radius * profile.radius;
    for (k, p) in corners.iter().enumerate() {
        if features & (1 << k) == 0 || p.z <= best.tip.z {
            continue;
        }
        let (dx, dy) = (p.x - c.x, p.y - c.y);
        let d2 = dx * dx + dy * dy;
        if d2 <= r2 {
            let z = p.z - profile.height(d2.sqrt());
            if z > best.tip.z {
                best.tip.z = z;
                best.contact = Contact::Vertex { triangle, point: *p };
            }
        }
    }
}
