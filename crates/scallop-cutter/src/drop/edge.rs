//! Edge contact, in the edge's canonical frame: the tip's XY at the origin,
//! the edge along the x axis at perpendicular distance d, its height
//! `z(x) = z_a + m (x - x_a)`. The cutter meets the vertical plane of the edge
//! in the curve `h(sqrt(x^2 + d^2))` (OpenCAMLib's "dual geometry": an offset
//! ellipse for the bull-nose), so the tip height of a contact at x is
//!
//! ```text
//! f(x) = z(x) - h(rho(x)),   rho(x) = sqrt(x^2 + d^2),   |x| <= x_R = sqrt(R^2 - d^2)
//! ```
//!
//! Every profile h is convex and non-decreasing in rho and rho is convex in x,
//! so f is concave: its maximum over the edge's part inside the disk is the
//! unconstrained maximiser clamped to that interval. For m >= 0 the maximiser
//! solves `h'(rho) x / rho = m` (mirror x for m < 0):
//!
//! ```text
//! flat:  x = x_R if m > 0 (else any; 0)
//! ball:  x = m x_R / sqrt(1 + m^2)
//! cone:  k = m tan(a); x = x_R if k >= 1, else d k / sqrt(1 - k^2)
//! bull:  rho = (R - r) + r sin(phi), h' = tan(phi):
//!        G(phi) = sin(phi) x(phi) - m cos(phi) rho(phi) = 0, increasing in phi on
//!        [phi_0, pi/2], solved by Newton steps kept inside a shrinking bracket.
//! ```
//!
//! f is flat at its maximum, so a parameter error e moves the height by O(e^2).

use std::f64::consts::FRAC_PI_2;

use scallop_geom::{Point2, Point3};

use super::{ClPoint, Contact};
use crate::CutterShape;

/// Iteration cap of the bull-nose root finder; the bracket halves at least
/// every other step, so 200 is far beyond what f64 resolution needs.
const MAX_ITERATIONS: usize = 200;

pub(super) fn drop_edge(
    shape: &CutterShape,
    radius: f64,
    a: &Point3,
    b: &Point3,
    triangle: usize,
    c: Point2,
    best: &mut ClPoint,
) {
    let (ex, ey) = (b.x - a.x, b.y - a.y);
    let len = ex.hypot(ey);
    if len == 0.0 {
        return; // vertical edge: its upper corner is the highest contact
    }
    let (ux, uy) = (ex / len, ey / len);
    let (px, py) = (a.x - c.x, a.y - c.y);
    let xa = px * ux + py * uy;
    let d = (px * uy - py * ux).abs();
    if d > radius {
        return;
    }
    let x_r = (radius * radius - d * d).sqrt();
    let lo = xa.max(-x_r);
    let hi = (xa + len).min(x_r);
    if lo > hi {
        return;
    }
    let m = (b.z - a.z) / len;
    let z_at = |x: f64| a.z + m * (x - xa);
    if z_at(lo).max(z_at(hi)) <= best.tip.z {
        return;
    }
    let x_c = maximiser(shape, m.abs(), d, x_r);
    let x = (if m < 0.0 { -x_c } else { x_c }).clamp(lo, hi);
    let zc = z_at(x);
    let tip = zc - shape.height_at((x * x + d * d).sqrt());
    if tip > best.tip.z {
        let t = (x - xa) / len;
        best.tip.z = tip;
        best.contact = Contact::Edge { triangle, point: Point3::new(a.x + t * ex, a.y + t * ey, zc) };
    }
}

/// The x >= 0 that maximises `m x - h(sqrt(x^2 + d^2))` on [0, x_r], for m >= 0.
fn maximiser(shape: &CutterShape, m: f64, d: f64, x_r: f64) -> f64 {
    match *shape {
        CutterShape::Flat { .. } => {
            if m > 0.0 {
                x_r
            } else {
                0.0
            }
        }
        CutterShape::Ball { .. } => m * x_r / (1.0 + m * m).sqrt(),
        CutterShape::Cone { half_angle, .. } => {
            let k = m * half_angle.tan();
            if k >= 1.0 { x_r } else { (d * k / (1.0 - k * k).sqrt()).min(x_r) }
        }
        CutterShape::Bull { radius, corner } => {
            if m == 0.0 {
                0.0
            } else {
                bull_maximiser(radius - corner, corner, m, d, x_r)
            }
        }
    }
}

/// Solves G(phi) = sin(phi) x - m cos(phi) rho = 0 with rho = a + r sin(phi),
/// x = sqrt(rho^2 - d^2), on [phi_0, pi/2] where G(phi_0) <= 0 <= G(pi/2) = x_r.
fn bull_maximiser(a: f64, r: f64, m: f64, d: f64, x_r: f64) -> f64 {
    let x_of = |phi: f64| {
        let rho = a + r * phi.sin();
        (rho * rho - d * d).max(0.0).sqrt()
    };
    let phi0 = if d <= a { 0.0 } else { ((d - a) / r).min(1.0).asin() };
    let (mut lo, mut hi) = (phi0, FRAC_PI_2);
    if hi <= lo {
        return x_r;
    }
    let mut phi = 0.5 * (lo + hi);
    for _ in 0..MAX_ITERATIONS {
        let (s, co) = phi.sin_cos();
        let rho = a + r * s;
        let x = (rho * rho - d * d).max(0.0).sqrt();
        let g = s * x - m * co * rho;
        if g < 0.0 {
            lo = phi;
        } else {
            hi = phi;
        }
        // G' = cos x + sin x' + m sin rho - m cos rho', rho' = r cos, x' = rho rho' / x
        let drho = r * co;
        let dx = if x > 0.0 { rho * drho / x } else { f64::INFINITY };
        let dg = co * x + s * dx + m * s * rho - m * co * drho;
        let newton = phi - g / dg;
        let next = if dg.is_finite() && dg > 0.0 && newton > lo && newton < hi { newton } else { 0.5 * (lo + hi) };
        if next == phi || hi - lo <= f64::EPSILON * hi {
            phi = next;
            break;
        }
        phi = next;
    }
    x_of(phi).min(x_r)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// max of m x - h(rho(x)) by dense sampling, for comparison.
    fn sampled_max(shape: &CutterShape, m: f64, d: f64, x_r: f64) -> f64 {
        let n = 200_000;
        (0..=n)
            .map(|i| {
                let x = -x_r + 2.0 * x_r * f64::from(i) / f64::from(n);
                m * x - shape.height_at((x * x + d * d).sqrt())
            })
            .fold(f64::NEG_INFINITY, f64::max)
    }

    #[test]
    fn maximiser_beats_dense_sampling_for_every_shape() {
        let shapes = [
            CutterShape::Flat { radius: 2.0 },
            CutterShape::Ball { radius: 2.0 },
            CutterShape::Bull { radius: 2.0, corner: 0.5 },
            CutterShape::Bull { radius: 2.0, corner: 2.0 },
            CutterShape::Bull { radius: 2.0, corner: 1e-3 },
            CutterShape::Cone { radius: 2.0, half_angle: 0.7 },
        ];
        for shape in shapes {
            for &d in &[0.0, 0.3, 1.2, 1.6, 1.99] {
                for &m in &[0.0, 0.01, 0.3, 1.0, 4.0, 100.0] {
                    let x_r = (4.0_f64 - d * d).sqrt();
                    let x = maximiser(&shape, m, d, x_r);
                    assert!((0.0..=x_r).contains(&x), "{shape:?} d={d} m={m}: x={x}");
                    let ours = m * x - shape.height_at((x * x + d * d).sqrt());
                    let sampled = sampled_max(&shape, m, d, x_r);
                    // ours is the true maximum: never below the samples, and above by
                    // no more than the sampling step can hide (slope * step).
                    assert!(ours >= sampled - 1e-12, "{shape:?} d={d} m={m}: {ours} < {sampled}");
                    assert!(ours <= sampled + (m + 50.0) * 4.0 * x_r / 200_000.0, "{shape:?} d={d} m={m}");
                }
            }
        }
    }
}
