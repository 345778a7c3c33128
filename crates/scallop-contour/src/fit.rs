//! Chords to arcs: greedy circle fitting through runs of points.

use crate::{P2, Vertex, tol};

/// Vertices with bulges for `points`: each run of at least three points that
/// a circle (through its first, middle and last points) passes within
/// `tolerance` of, chord midpoints included, turning less than a half turn in
/// one direction, becomes one arc.
pub(crate) fn fit_arcs(points: &[P2], closed: bool, tolerance: f64) -> Vec<Vertex> {
    let n = points.len();
    let mut out = Vec::with_capacity(n);
    let mut i = 0;
    let last = if closed { n } else { n.saturating_sub(1) };
    while i < last {
        let mut best = None;
        let mut j = i + 2;
        while j <= last && j - i <= tol::MAX_ARC_POINTS {
            match arc_through(points, i, j, n, tolerance) {
                Some(bulge) => best = Some((j, bulge)),
                None => break,
            }
            j += 1;
        }
        let p = points[i];
        match best {
            Some((j, bulge)) => {
                out.push(Vertex { x: p[0], y: p[1], bulge });
                i = j;
            }
            None => {
                out.push(Vertex { x: p[0], y: p[1], bulge: 0.0 });
                i += 1;
            }
        }
    }
    if !closed && n > 0 {
        let p = points[n - 1];
        out.push(Vertex { x: p[0], y: p[1], bulge: 0.0 });
    }
    out
}

/// The bulge of the arc through points `i..=j` (indices modulo `n`), if one fits.
fn arc_through(points: &[P2], i: usize, j: usize, n: usize, tolerance: f64) -> Option<f64> {
    let at = |k: usize| points[k % n];
    let (a, m, b) = (at(i), at((i + j) / 2), at(j));
    let (c, r) = circle(a, m, b)?;
    let angle = |p: P2| (p[1] - c[1]).atan2(p[0] - c[0]);
    let turn = |p: P2, q: P2| {
        let d = angle(q) - angle(p);
        (d + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
    };
    let mut sweep = 0.0;
    let mut ccw: Option<bool> = None;
    for k in i..j {
        let (p, q) = (at(k), at(k + 1));
        let t = turn(p, q);
        if t.abs() <= f64::EPSILON || ccw.is_some_and(|c| c != (t > 0.0)) {
            return None;
        }
        ccw = Some(t > 0.0);
        sweep += t;
        let mid = [(p[0] + q[0]) / 2.0, (p[1] + q[1]) / 2.0];
        // The chord midpoint lies inside the circle by the sagitta.
        let off = |x: P2| ((x[0] - c[0]).hypot(x[1] - c[1]) - r).abs();
        if off(p) > tolerance || off(mid) > tolerance {
            return None;
        }
    }
    if sweep.abs() >= 0.95 * std::f64::consts::PI {
        return None;
    }
    Some((sweep / 4.0).tan())
}

/// Centre and radius of the circle through three points.
fn circle(a: P2, b: P2, c: P2) -> Option<(P2, f64)> {
    let (bx, by) = (b[0] - a[0], b[1] - a[1]);
    let (cx, cy) = (c[0] - a[0], c[1] - a[1]);
    let d = 2.0 * (bx * cy - by * cx);
    let scale = (bx * bx + by * by).max(cx * cx + cy * cy);
    if d.abs() <= 1e-12 * scale.max(1e-300) {
        return None;
    }
    let (b2, c2) = (bx * bx + by * by, cx * cx + cy * cy);
    let ux = (cy * b2 - by * c2) / d;
    let uy = (bx * c2 - cx * b2) / d;
    Some(([a[0] + ux, a[1] + uy], ux.hypot(uy)))
}

/// The closed ring `points` with the points Douglas-Peucker drops at `eps`
/// (Douglas and Peucker, Cartographica 10(2), 1973): every dropped point is
/// within `eps` of the chord that replaces it.
pub(crate) fn simplify_ring(points: &[P2], eps: f64) -> Vec<P2> {
    let n = points.len();
    if n < 4 {
        return points.to_vec();
    }
    let far = (1..n).max_by(|&a, &b| d2(points[0], points[a]).total_cmp(&d2(points[0], points[b]))).unwrap_or(n / 2);
    let mut keep = vec![false; n];
    keep[0] = true;
    keep[far] = true;
    let mut stack = vec![(0, far), (far, n)];
    while let Some((a, b)) = stack.pop() {
        let (p, q) = (points[a], points[b % n]);
        let worst = (a + 1..b).map(|i| (off_chord(points[i], p, q), i)).max_by(|x, y| x.0.total_cmp(&y.0));
        if let Some((d, i)) = worst
            && d > eps
        {
            keep[i] = true;
            stack.push((a, i));
            stack.push((i, b));
        }
    }
    points.iter().zip(keep).filter(|(_, k)| *k).map(|(p, _)| *p).collect()
}

fn d2(a: P2, b: P2) -> f64 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)
}

/// Distance from `x` to the segment `p q`.
fn off_chord(x: P2, p: P2, q: P2) -> f64 {
    let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
    let l2 = dx * dx + dy * dy;
    let t = if l2 > 0.0 { (((x[0] - p[0]) * dx + (x[1] - p[1]) * dy) / l2).clamp(0.0, 1.0) } else { 0.0 };
    (x[0] - p[0] - t * dx).hypot(x[1] - p[1] - t * dy)
}
