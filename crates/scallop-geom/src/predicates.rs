//! Exact geometric predicates (Shewchuk's adaptive arithmetic via `robust`).
//! Decisions (side of a line, inside a triangle) use these, never an epsilon.

use crate::Point2;

fn coord(p: &Point2) -> robust::Coord<f64> {
    robust::Coord { x: p.x, y: p.y }
}

/// Twice the signed area of (a, b, c): > 0 counter-clockwise, < 0 clockwise,
/// exactly 0 when collinear. The sign is exact.
///
/// ```
/// use scallop_geom::{Point2, predicates::orient2d};
/// assert!(orient2d(&Point2::new(0.,0.), &Point2::new(1.,0.), &Point2::new(0.,1.)) > 0.0);
/// ```
#[must_use]
pub fn orient2d(a: &Point2, b: &Point2, c: &Point2) -> f64 {
    robust::orient2d(coord(a), coord(b), coord(c))
}

/// Whether `p` lies in the closed triangle (a, b, c) of either orientation.
/// Exact. A degenerate (collinear) triangle contains nothing.
///
/// ```
/// use scallop_geom::{Point2, predicates::in_triangle};
/// let (a, b, c) = (Point2::new(0.,0.), Point2::new(1.,0.), Point2::new(0.,1.));
/// assert!(in_triangle(&Point2::new(0.25, 0.25), &a, &b, &c));
/// assert!(!in_triangle(&Point2::new(1.0, 1.0), &a, &b, &c));
/// ```
#[must_use]
pub fn in_triangle(p: &Point2, a: &Point2, b: &Point2, c: &Point2) -> bool {
    // Inside (closed) iff the three sides see p on the same side or on the line;
    // all three zero means the triangle is degenerate and p on its line: not inside.
    let o1 = orient2d(a, b, p);
    let o2 = orient2d(b, c, p);
    if (o1 > 0.0 && o2 < 0.0) || (o1 < 0.0 && o2 > 0.0) {
        return false;
    }
    let o3 = orient2d(c, a, p);
    let (pos, neg) = (o1 > 0.0 || o2 > 0.0 || o3 > 0.0, o1 < 0.0 || o2 < 0.0 || o3 < 0.0);
    pos != neg || (!pos && !neg && orient2d(a, b, c) != 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The three-orientation shortcut agrees with the definition by the area sign.
    #[test]
    fn in_triangle_matches_area_sign_definition() {
        let reference = |p: &Point2, a: &Point2, b: &Point2, c: &Point2| {
            let area = orient2d(a, b, c);
            if area == 0.0 {
                return false;
            }
            let s = area.signum();
            orient2d(a, b, p) * s >= 0.0 && orient2d(b, c, p) * s >= 0.0 && orient2d(c, a, p) * s >= 0.0
        };
        // A small integer lattice hits every boundary, vertex and degenerate case.
        let pts: Vec<Point2> =
            (0..4).flat_map(|i| (0..4).map(move |j| Point2::new(f64::from(i), f64::from(j)))).collect();
        for a in &pts {
            for b in &pts {
                for c in &pts {
                    for p in &pts {
                        assert_eq!(in_triangle(p, a, b, c), reference(p, a, b, c), "{p} in {a} {b} {c}");
                    }
                }
            }
        }
    }
}
