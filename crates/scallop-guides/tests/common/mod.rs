//! Test geometry made here: planes, a cylinder, a sphere, a drafted pocket
//! flank, circles and a dumbbell contour; and checks shared by the tests.

#![allow(dead_code, clippy::unwrap_used, reason = "shared by several test files; a panic is the failure report")]

use std::f64::consts::{PI, TAU};

use scallop_geom::{Point3, Vec3};
use scallop_guides::{Curve, Support};
use scallop_mesh::{Polyline3, PolylineQuery, TriMesh};

pub fn p(x: f64, y: f64, z: f64) -> Point3 {
    Point3::new(x, y, z)
}

/// A surface over a `(u, v)` grid of `nu x nv` cells, `at(u, v)` with `u, v`
/// in `[0, 1]`; triangles wound counter-clockwise in `(u, v)`.
pub fn grid_surface(nu: usize, nv: usize, at: impl Fn(f64, f64) -> Point3) -> TriMesh {
    let mut v = Vec::with_capacity((nu + 1) * (nv + 1));
    for j in 0..=nv {
        for i in 0..=nu {
            v.push(at(i as f64 / nu as f64, j as f64 / nv as f64));
        }
    }
    let mut t = Vec::with_capacity(2 * nu * nv);
    for j in 0..nv {
        for i in 0..nu {
            let a = j * (nu + 1) + i;
            t.push([a, a + 1, a + nu + 2]);
            t.push([a, a + nu + 2, a + nu + 1]);
        }
    }
    TriMesh::from_indexed(&v, &t).unwrap().0
}

/// The plane through `origin` spanned by unit `e1`, `e2`, square of `half`
/// around it, cells of about `step`; normal `e1 x e2`.
pub fn plane(origin: Point3, e1: Vec3, e2: Vec3, half: f64, step: f64) -> Support {
    let n = (2.0 * half / step).round() as usize;
    Support::new(grid_surface(n, n, |u, v| origin + e1 * (2.0 * half * u - half) + e2 * (2.0 * half * v - half)))
}

/// The plane z = `z` over `[-half, half]^2`.
pub fn flat(z: f64, half: f64, step: f64) -> Support {
    plane(p(0.0, 0.0, z), Vec3::x(), Vec3::y(), half, step)
}

/// The cylinder of radius `r` about the z axis for angles `[a0, a1]` and
/// heights `[0, h]`, outward normals, cells of about `step`.
pub fn cylinder(r: f64, a0: f64, a1: f64, h: f64, step: f64) -> Support {
    let nu = ((a1 - a0) * r / step).ceil() as usize;
    let nv = (h / step).ceil() as usize;
    Support::new(grid_surface(nu, nv, |u, v| {
        let a = a0 + (a1 - a0) * u;
        p(r * a.cos(), r * a.sin(), h * v)
    }))
}

/// The sphere cap of radius `r` about the origin above polar angle `cap`
/// (from +z), outward normals, cells of about `step`.
pub fn sphere_cap(r: f64, cap: f64, step: f64) -> Support {
    let nu = (TAU * r * cap.sin() / step).ceil() as usize;
    let nv = (cap * r / step).ceil() as usize;
    // v = 0 is the rim, v = 1 the pole; degenerate triangles at the pole are dropped.
    Support::new(grid_surface(nu, nv, |u, v| {
        let (th, ph) = (TAU * u, cap * (1.0 - v));
        let u_wrap = if u >= 1.0 { 0.0 } else { th };
        p(r * ph.sin() * u_wrap.cos(), r * ph.sin() * u_wrap.sin(), r * ph.cos())
    }))
}

/// A counter-clockwise circle about `c` in the plane `z = c.z`, `n` points.
pub fn circle(c: Point3, r: f64, n: usize) -> Polyline3 {
    Polyline3::new(
        (0..n)
            .map(|i| c + Vec3::new(r * (TAU * i as f64 / n as f64).cos(), r * (TAU * i as f64 / n as f64).sin(), 0.0))
            .collect(),
        true,
    )
}

/// Two disks of radius `r` at `x = -+d` joined by a neck of half-width `w`,
/// counter-clockwise in the plane z = 0, points about `step` apart.
pub fn dumbbell(r: f64, d: f64, w: f64, step: f64) -> Polyline3 {
    let beta = (w / r).asin();
    let xn = d - (r * r - w * w).sqrt();
    let mut pts = Vec::new();
    let arc = |pts: &mut Vec<Point3>, cx: f64, a0: f64, a1: f64| {
        let n = ((a1 - a0) * r / step).ceil() as usize;
        for i in 0..n {
            let a = a0 + (a1 - a0) * i as f64 / n as f64;
            pts.push(p(cx + r * a.cos(), r * a.sin(), 0.0));
        }
    };
    let line = |pts: &mut Vec<Point3>, a: Point3, b: Point3| {
        let n = ((b - a).norm() / step).ceil() as usize;
        for i in 0..n {
            pts.push(a + (b - a) * (i as f64 / n as f64));
        }
    };
    arc(&mut pts, d, -PI + beta, PI - beta);
    line(&mut pts, p(xn, w, 0.0), p(-xn, w, 0.0));
    arc(&mut pts, -d, beta, TAU - beta);
    line(&mut pts, p(-xn, -w, 0.0), p(xn, -w, 0.0));
    Polyline3::new(pts, true)
}

/// `line` on `support`, inside on the left.
pub fn on(support: &Support, line: Polyline3) -> Curve {
    support.curve(line).unwrap().inside_left()
}

/// Largest distance from a point of `curves` to the polylines `to`.
pub fn max_distance(curves: &[Curve], to: &[Curve]) -> f64 {
    let q = PolylineQuery::new(to.iter().map(|c| c.line.clone()).collect());
    curves.iter().flat_map(|c| c.line.points.iter()).map(|x| q.distance(x)).fold(0.0, f64::max)
}

/// Smallest distance from a point of `curves` to the polylines `to`.
pub fn min_distance(curves: &[Curve], to: &[Curve]) -> f64 {
    let q = PolylineQuery::new(to.iter().map(|c| c.line.clone()).collect());
    curves.iter().flat_map(|c| c.line.points.iter()).map(|x| q.distance(x)).fold(f64::INFINITY, f64::min)
}

/// Whether two closed segments of the XY plane meet (exact orientations).
fn segments_meet(a: Point3, b: Point3, c: Point3, d: Point3) -> bool {
    use scallop_geom::{Point2, predicates::orient2d};
    let q = |x: Point3| Point2::new(x.x, x.y);
    let (a, b, c, d) = (q(a), q(b), q(c), q(d));
    let (o1, o2) = (orient2d(&a, &b, &c), orient2d(&a, &b, &d));
    let (o3, o4) = (orient2d(&c, &d, &a), orient2d(&c, &d, &b));
    o1 * o2 <= 0.0 && o3 * o4 <= 0.0 && !(o1 == 0.0 && o2 == 0.0)
}

/// Whether a planar (XY) polyline crosses itself: two non-adjacent segments meet.
pub fn self_intersects_xy(line: &Polyline3) -> bool {
    let n = line.segment_count();
    for i in 0..n {
        for j in i + 1..n {
            let adjacent = j == i + 1 || (line.closed && i == 0 && j == n - 1);
            if adjacent {
                continue;
            }
            let (a, b) = line.segment(i);
            let (c, d) = line.segment(j);
            if segments_meet(a, b, c, d) {
                return true;
            }
        }
    }
    false
}

/// Winding number of the XY polygon `line` about `x`.
pub fn winding_xy(line: &Polyline3, x: &Point3) -> i32 {
    let mut w = 0;
    for i in 0..line.segment_count() {
        let (a, b) = line.segment(i);
        let cross = (b.x - a.x) * (x.y - a.y) - (x.x - a.x) * (b.y - a.y);
        if a.y <= x.y && b.y > x.y && cross > 0.0 {
            w += 1;
        } else if a.y > x.y && b.y <= x.y && cross < 0.0 {
            w -= 1;
        }
    }
    w
}
