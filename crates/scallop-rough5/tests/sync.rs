//! SPU synchronisation and the pitch angle: Eq. 3.7 against its arccos form
//! (spec 12.1 item 3), push and pull on hand-built frames, concentric
//! circles (the axis stays in the radial plane: zero pitch), the angular step.
#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

use proptest::prelude::*;
use scallop_geom::{Point3, Vec3};
use scallop_guides::Curve;
use scallop_mesh::Polyline3;
use scallop_rough5::{limit_angular_step, pitch_angle, synchronise};

/// A circle of `radius` at height `z`, `n` points, counter-clockwise from
/// angle `start`, normals +Z.
fn circle(radius: f64, z: f64, n: usize, start: f64) -> Curve {
    let pts: Vec<Point3> = (0..n)
        .map(|k| {
            let a = start + std::f64::consts::TAU * k as f64 / n as f64;
            Point3::new(radius * a.cos(), radius * a.sin(), z)
        })
        .collect();
    Curve { line: Polyline3::new(pts, true), normals: vec![Vec3::z(); n] }
}

/// Eq. 3.7 as the thesis writes it: sign(u.f) arccos(([u - (u.t)t].n) / |u - (u.t)t|).
fn eq_3_7(u: &Vec3, f: &Vec3, n: &Vec3) -> f64 {
    let t = f.cross(n);
    let w = u - t * u.dot(&t);
    let sign = if u.dot(f) < 0.0 { -1.0 } else { 1.0 };
    sign * (w.dot(n) / w.norm()).clamp(-1.0, 1.0).acos()
}

proptest! {
    #[test]
    fn pitch_angle_is_eq_3_7(a in 0.0..6.3f64, b in -1.5..1.5f64, c in -1.2..1.2f64, d in 0.0..6.3f64) {
        // A random orthonormal frame (f, n) and a random axis with u.n > 0.
        let n = Vec3::new(b.cos() * a.cos(), b.cos() * a.sin(), b.sin());
        let seed = if n.x.abs() < 0.9 { Vec3::x() } else { Vec3::y() };
        let f = (seed - n * seed.dot(&n)).normalize();
        let t = f.cross(&n);
        let u = (n * c.cos() + (f * d.cos() + t * d.sin()) * c.sin()).normalize();
        prop_assume!(u.dot(&n) > 1e-3 && (u - t * u.dot(&t)).norm() > 1e-3);
        prop_assert!((pitch_angle(&u, &f, &n) - eq_3_7(&u, &f, &n)).abs() < 1e-9);
    }
}

#[test]
fn leaning_back_pushes_and_forwards_pulls() {
    let back = Vec3::new(-0.3, 0.0, 1.0).normalize();
    let forwards = Vec3::new(0.3, 0.0, 1.0).normalize();
    assert!(pitch_angle(&back, &Vec3::x(), &Vec3::z()) < 0.0);
    assert!(pitch_angle(&forwards, &Vec3::x(), &Vec3::z()) > 0.0);
    // A tangent not orthogonal to the normal is made orthogonal first.
    let tilted_tangent = Vec3::new(1.0, 0.0, 0.4);
    assert!(
        (pitch_angle(&forwards, &tilted_tangent, &Vec3::z()) - pitch_angle(&forwards, &Vec3::x(), &Vec3::z())).abs()
            < 1e-12
    );
}

#[test]
fn concentric_circles_give_radial_axes_and_zero_pitch() {
    for (a, b, start) in [(10.0, 13.0, 0.3), (20.0, 16.0, 2.0), (8.0, 8.0, 4.0)] {
        let path = circle(a, 0.0, 2000, 0.0);
        // The tilt curve starts elsewhere and runs clockwise: both are fixed.
        let tilt = circle(b, 4.0, 1500, start).reversed();
        let pairs = synchronise(&path, Some(&tilt), &Point3::new(a, 0.0, 0.0), 0.5);
        assert!(pairs.len() > 100);
        for p in &pairs {
            let u = p.axis();
            let radial = Vec3::new(p.path.x, p.path.y, 0.0).normalize();
            // No component along the tangent of the circle (within the chords).
            assert!(u.dot(&p.tangent).abs() < 0.005, "{p:?}");
            let pitch = pitch_angle(&u, &p.tangent, &p.normal);
            assert!(pitch.abs() < 0.005, "{a} {b}: pitch {pitch} at {p:?}");
            // Leaning outwards when the tilt circle is larger.
            assert!((u.dot(&radial) * (b - a)) >= -1e-9);
        }
        assert!((pairs[0].path - Point3::new(a, 0.0, 0.0)).norm() < 1e-12);
    }
}

#[test]
fn the_angular_step_is_limited() {
    let path = circle(10.0, 0.0, 60, 0.0);
    let tilt = circle(30.0, 4.0, 60, 0.0);
    let pairs = synchronise(&path, Some(&tilt), &Point3::new(10.0, 0.0, 0.0), 5.0);
    let max = 1f64.to_radians();
    let fine = limit_angular_step(&pairs, max, 3f64.to_radians());
    assert!(fine.len() > pairs.len());
    for w in fine.windows(2) {
        let (a, b) = (w[0].axis(), w[1].axis());
        assert!(a.angle(&b) <= max + 1e-12);
        let az = |u: Vec3| u.y.atan2(u.x);
        let d = (az(b) - az(a)).rem_euclid(std::f64::consts::TAU);
        assert!(d.min(std::f64::consts::TAU - d) <= 3f64.to_radians() + 1e-9);
    }
}

#[test]
fn interpolated_axes_go_around_the_pole() {
    // Two axes 3 degrees off +Z on opposite sides: the straight chord crosses
    // the pole (the C table would flip); the interpolation keeps the tilt.
    let t = 3f64.to_radians();
    let a = Vec3::new(t.sin(), 0.0, t.cos());
    let b = Vec3::new(-t.sin(), 1e-9, t.cos());
    for k in 0..=20 {
        let u = scallop_rough5::interpolate_axis(&a, &b, f64::from(k) / 20.0);
        assert!((u.norm() - 1.0).abs() < 1e-12);
        assert!((u.z.acos() - t).abs() < 1e-9);
    }
    assert_eq!(scallop_rough5::axis_steps(&a, &b, 1.0, 5f64.to_radians()), 36);
}
