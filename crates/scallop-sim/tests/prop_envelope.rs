//! The exact swept floor against an independent oracle: for random moves and
//! points, the feasible tip interval (rho <= R, a quadratic inequality in t) is
//! found in closed form and the convex `z(t) = tip_z(t) + h(rho(t))` minimised
//! on it by a long ternary search using only `CutterShape::height_at`; a dense
//! sample along the move must never lie below the exact floor.

#![allow(clippy::unwrap_used, clippy::float_cmp, reason = "tests fail loudly by design; exact cases compare exactly")]

mod common;

use proptest::prelude::*;
use scallop_cutter::CutterShape;
use scallop_geom::{Point2, Point3};
use scallop_sim::swept_floor;

/// Minimum of tip_z(t) + h(rho(t)) over t in [0, 1] with rho(t) <= R, or None.
fn oracle(shape: &CutterShape, a: &Point3, b: &Point3, p: &Point2) -> Option<f64> {
    let r = shape.radius();
    let (qx, qy) = (p.x - a.x, p.y - a.y);
    let (dx, dy) = (b.x - a.x, b.y - a.y);
    // |q - t d|^2 <= r^2  <=>  A t^2 - 2 B t + C <= 0
    let (qa, qb, qc) = (dx * dx + dy * dy, qx * dx + qy * dy, qx * qx + qy * qy - r * r);
    let (lo, hi) = if qa == 0.0 {
        if qc > 0.0 {
            return None;
        }
        (0.0, 1.0)
    } else {
        let disc = qb * qb - qa * qc;
        if disc < 0.0 {
            return None;
        }
        let s = disc.sqrt();
        (((qb - s) / qa).max(0.0), ((qb + s) / qa).min(1.0))
    };
    if lo > hi {
        return None;
    }
    let z = |t: f64| {
        let rho = ((qx - t * dx).powi(2) + (qy - t * dy).powi(2)).sqrt().min(r);
        a.z + t * (b.z - a.z) + shape.height_at(rho)
    };
    let (mut l, mut h) = (lo, hi);
    for _ in 0..300 {
        let (m1, m2) = (l + (h - l) / 3.0, h - (h - l) / 3.0);
        if z(m1) <= z(m2) {
            h = m2;
        } else {
            l = m1;
        }
    }
    Some(z(0.5 * (l + h)).min(z(lo)).min(z(hi)))
}

fn shapes() -> impl Strategy<Value = CutterShape> {
    common::shapes(0.5..5.0, 0.05..1.0, 0.1..1.4)
}

fn point() -> impl Strategy<Value = Point3> {
    (-10.0..10.0f64, -10.0..10.0f64, -10.0..10.0f64).prop_map(|(x, y, z)| Point3::new(x, y, z))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn exact_floor_matches_oracle(shape in shapes(), a in point(), b in point(), steep in any::<bool>(),
                                  px in -1.2..1.2f64, py in -1.2..1.2f64, s in 0.0..1.0f64) {
        // Half the cases are short, steep moves (plunges and ramps).
        let b = if steep { Point3::new(a.x + 0.05 * (b.x - a.x), a.y + 0.05 * (b.y - a.y), b.z) } else { b };
        // A point near the move: around a point of the segment, within ~1.7 R.
        let r = shape.radius();
        let c = a + (b - a) * s;
        let p = Point2::new(c.x + px * r, c.y + py * r);
        let exact = swept_floor(&shape, &a, &b, &p);
        let reference = oracle(&shape, &a, &b, &p);
        match (exact, reference) {
            (Some(e), Some(o)) => {
                prop_assert!((e - o).abs() <= 1e-7, "{shape:?} {a} {b} {p}: exact {e} oracle {o}");
                for k in 0..=2000 {
                    let t = f64::from(k) / 2000.0;
                    let tip = a + (b - a) * t;
                    let rho = (p - tip.xy()).norm();
                    if rho <= r {
                        let z = tip.z + shape.height_at(rho);
                        prop_assert!(e <= z + 1e-9, "{shape:?}: sample {z} at t = {t} below exact {e}");
                    }
                }
            }
            (None, None) => {}
            // Points within rounding of the reach boundary may differ.
            (e, o) => {
                let d = distance_to_segment(&p, &a.xy(), &b.xy());
                prop_assert!((d - r).abs() <= 1e-9, "{shape:?} {a} {b} {p}: exact {e:?} oracle {o:?}, d = {d}");
            }
        }
    }
}

fn distance_to_segment(p: &Point2, a: &Point2, b: &Point2) -> f64 {
    let ab = b - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 { ((p - a).dot(&ab) / len2).clamp(0.0, 1.0) } else { 0.0 };
    (p - (a + ab * t)).norm()
}

#[test]
fn vertical_moves_leave_the_profile() {
    let shape = CutterShape::Bull { radius: 3.0, corner: 1.0 };
    let (a, b) = (Point3::new(1.0, 2.0, 5.0), Point3::new(1.0, 2.0, -1.0));
    for k in 0..30 {
        let rho = 3.0 * f64::from(k) / 30.0;
        let z = swept_floor(&shape, &a, &b, &Point2::new(1.0 + rho, 2.0)).unwrap();
        scallop_geom::assert_near!(z, -1.0 + shape.height_at(rho), 1e-12);
    }
    assert_eq!(swept_floor(&shape, &a, &b, &Point2::new(4.1, 2.0)), None);
}
