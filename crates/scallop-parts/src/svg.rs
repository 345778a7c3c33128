//! A shaded isometric SVG picture of a mesh (painter's algorithm), for docs.

use std::fmt::Write as _;

use scallop_geom::{Point3, Vec3};
use scallop_mesh::TriMesh;

/// An SVG of `mesh` seen from the -x, -y, +z octant, `width` pixels wide;
/// `colour(t)` gives triangle `t`'s base colour, `None` leaves it out. Only
/// triangles facing away from the eye are drawn: for a volume with outward
/// normals, a cut-away view of its inside (the near walls and the lid drop out).
/// Shading
/// is two-sided Lambert under a light from the eye. Triangles are drawn far to
/// near (ties by number), so the text depends only on the input.
#[must_use]
pub fn svg_view(mesh: &TriMesh, width: f64, colour: impl Fn(usize) -> Option<[u8; 3]>) -> String {
    svg_view_with_lines(mesh, width, colour, &[])
}

/// As [`svg_view`], with polylines `(points, closed, colour)` drawn over the
/// triangles in the same projection (curves on the part).
#[must_use]
pub fn svg_view_with_lines(
    mesh: &TriMesh,
    width: f64,
    colour: impl Fn(usize) -> Option<[u8; 3]>,
    lines: &[(Vec<Point3>, bool, [u8; 3])],
) -> String {
    let eye = Vec3::new(-1.0, -1.6, 1.3).normalize();
    let right = Vec3::z().cross(&eye).normalize();
    let up = eye.cross(&right);
    let light = (eye + Vec3::new(0.3, 0.0, 0.4)).normalize();
    let project = |p: &scallop_geom::Point3| (p.coords.dot(&right), -p.coords.dot(&up));
    let mut items: Vec<(f64, usize, [u8; 3])> = Vec::new();
    for t in 0..mesh.triangles().len() {
        let Some(c) = colour(t) else { continue };
        let [a, b, d] = mesh.triangle(t);
        let n = (b - a).cross(&(d - a)).try_normalize(0.0).unwrap_or_else(Vec3::z);
        if n.dot(&eye) > 0.0 {
            continue;
        }
        let shade = 0.3 + 0.7 * n.dot(&light).abs();
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "in 0..=255")]
        let rgb = c.map(|v| (f64::from(v) * shade).round().clamp(0.0, 255.0) as u8);
        items.push(((a.coords + b.coords + d.coords).dot(&eye), t, rgb));
    }
    items.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
    let (mut lo, mut hi) = ((f64::INFINITY, f64::INFINITY), (f64::NEG_INFINITY, f64::NEG_INFINITY));
    for v in mesh.vertices() {
        let (x, y) = project(v);
        lo = (lo.0.min(x), lo.1.min(y));
        hi = (hi.0.max(x), hi.1.max(y));
    }
    let scale = width / (hi.0 - lo.0).max(1e-9);
    let height = (hi.1 - lo.1) * scale;
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0}" height="{height:.0}" viewBox="-4 -4 {:.0} {:.0}">"#,
        width + 8.0,
        height + 8.0
    );
    for (_, t, [r, g, b]) in items {
        let pts: Vec<String> = mesh
            .triangle(t)
            .iter()
            .map(|p| {
                let (x, y) = project(p);
                format!("{:.1},{:.1}", (x - lo.0) * scale, (y - lo.1) * scale)
            })
            .collect();
        let _ = writeln!(
            s,
            r##"<polygon points="{}" fill="#{r:02x}{g:02x}{b:02x}" stroke="#{r:02x}{g:02x}{b:02x}" stroke-width="0.4"/>"##,
            pts.join(" ")
        );
    }
    for (points, closed, [r, g, b]) in lines {
        let pts: Vec<String> = points
            .iter()
            .map(|p| {
                let (x, y) = project(p);
                format!("{:.1},{:.1}", (x - lo.0) * scale, (y - lo.1) * scale)
            })
            .collect();
        let tag = if *closed { "polygon" } else { "polyline" };
        let _ = writeln!(
            s,
            r##"<{tag} points="{}" fill="none" stroke="#{r:02x}{g:02x}{b:02x}" stroke-width="1.2"/>"##,
            pts.join(" ")
        );
    }
    s.push_str("</svg>\n");
    s
}
