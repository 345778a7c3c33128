//! Effective cutting radius and scallop height of a torus tool (Jousselin
//! 2020, Ch. 3 §1.3, Eq. 3.8 after Lee 1997, and Eq. 3.9), with the exact
//! swept profile they approximate (docs/rough5.md, "Effective radius").
//!
//! The tool is the torus of body radius `radius` (R) and corner radius
//! `corner` (r); its major radius is R_t = R - r. The thesis prints Eq. 3.8
//! with the body radius R: that overstates R_eff by r / sin(theta_t) (with R_t
//! it is exact for the swept profile at theta_n = 0, see below), so R_t is
//! used here and the thesis's "R_eff divided by 20 from 1 deg to 6 deg" is not
//! reproduced (the ratio is about 5.78).
//!
//! With the axis tilted by theta_t in the plane (f, n), the centre circle of
//! the corner seen along the feed f is an ellipse of semi-axes R_t (across
//! the feed) and R_t sin(theta_t) (along n); the swept profile is that
//! ellipse offset by r. Its radius of curvature at the lowest point is
//! R_t / sin(theta_t) + r, Eq. 3.8 at theta_n = 0.

/// The effective cutting radius R_eff (mm) of Eq. 3.8 with the major radius
/// R_t = R - r: the normal-section radius of the torus at the contact in the
/// cross-feed direction, for the pitch `pitch` (theta_t) and the yaw `yaw`
/// (theta_n), both in rad. Infinite for a flat contact (theta_t = 0,
/// theta_n = 0).
///
/// ```
/// let r = scallop_rough5::effective_radius(5.0, 1.5, 6f64.to_radians(), 0.0);
/// assert!((r - 34.98).abs() < 0.005);
/// ```
#[must_use]
pub fn effective_radius(radius: f64, corner: f64, pitch: f64, yaw: f64) -> f64 {
    let (rt, r) = (radius - corner, corner);
    let s = pitch.abs().sin();
    let (c2, s2) = (yaw.cos().powi(2), yaw.sin().powi(2));
    r * (rt + r * s) / (r * s * c2 + (rt + r * s) * s2)
}

/// The radius (mm) of the apparent contour of the torus seen along the feed
/// at its lowest point, for the pitch `pitch` and the yaw `yaw` (rad):
/// cos^2(theta_n) (R_t + r sin theta_t) / sin theta_t + r sin^2(theta_n). It
/// sets the scallop for 0 < theta_n < 90 deg, where Eq. 3.8 is only a
/// normal-section radius; both agree at theta_n = 0 and 90 deg.
#[must_use]
pub fn apparent_contour_radius(radius: f64, corner: f64, pitch: f64, yaw: f64) -> f64 {
    let (rt, r) = (radius - corner, corner);
    let s = pitch.abs().sin();
    yaw.cos().powi(2) * (rt + r * s) / s + r * yaw.sin().powi(2)
}

/// The scallop height h_c = a_e^2 / (8 R_eff) of Eq. 3.9 (mm): the
/// osculating-circle approximation of the crest between two passes `step`
/// (a_e) apart.
#[must_use]
pub fn scallop_height(step: f64, effective_radius: f64) -> f64 {
    step * step / (8.0 * effective_radius)
}

/// The swept profile of the torus tilted by `pitch` (rad) in the plane of the
/// feed and the normal (theta_n = 0), seen along the feed: its height (mm)
/// above its lowest point at the cross-feed offset `y` (mm). `None` beyond
/// the tool's width (|y| >= R).
#[must_use]
pub fn swept_profile(radius: f64, corner: f64, pitch: f64, y: f64) -> Option<f64> {
    let (a, r) = (radius - corner, corner);
    let b = a * pitch.abs().sin();
    let y = y.abs();
    if y >= a + r {
        return None;
    }
    if b == 0.0 {
        // Flat bottom of width 2 R_t, then the corner arc.
        let out = (y - a).max(0.0);
        return Some(r - (r * r - out * out).sqrt());
    }
    // The offset ellipse e(phi) + r N(phi), e = (a sin phi, -b cos phi), N the
    // outward unit normal; its abscissa grows with phi on [0, pi/2).
    let point = |phi: f64| {
        let (s, c) = phi.sin_cos();
        let nu = (b * b * s * s + a * a * c * c).sqrt();
        (a * s + r * b * s / nu, -b * c - r * a * c / nu)
    };
    let (mut lo, mut hi) = (0.0, std::f64::consts::FRAC_PI_2);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if point(mid).0 < y {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= f64::EPSILON {
            break;
        }
    }
    Some(point(0.5 * (lo + hi)).1 + b + r)
}

/// The exact scallop height (mm) between two straight passes `step` apart
/// of the torus tilted by `pitch` (rad, theta_n = 0): the swept profile at
/// half the step. `None` when the passes leave a gap (step >= 2 R).
///
/// ```
/// let h = scallop_rough5::exact_scallop(5.0, 1.5, 6f64.to_radians(), 4.5).unwrap();
/// assert!((h - 0.0804).abs() < 1e-4);
/// ```
#[must_use]
pub fn exact_scallop(radius: f64, corner: f64, pitch: f64, step: f64) -> Option<f64> {
    swept_profile(radius, corner, pitch, 0.5 * step)
}

#[cfg(test)]
mod tests {
    use super::*;

    const R: f64 = 5.0;
    const CORNER: f64 = 1.5;
    const AE: f64 = 4.5;

    fn deg(d: f64) -> f64 {
        d.to_radians()
    }

    /// Spec 12.1 item 4: R_eff(1 deg) = 202.05, R_eff(6 deg) = 34.98 mm,
    /// h_c(6 deg) = 0.0724 mm (R 5, r 1.5, a_e 4.5, theta_n = 0).
    #[test]
    fn effective_radius_and_scallop_of_the_thesis_tool() {
        let r1 = effective_radius(R, CORNER, deg(1.0), 0.0);
        let r6 = effective_radius(R, CORNER, deg(6.0), 0.0);
        assert!((r1 - 202.05).abs() < 0.005, "{r1}");
        assert!((r6 - 34.98).abs() < 0.005, "{r6}");
        let h6 = scallop_height(AE, r6);
        assert!((h6 - 0.0724).abs() < 5e-5, "{h6}");
        // The thesis's "divided by 20" does not follow: the ratio is about 5.78.
        assert!((r1 / r6 - 5.78).abs() < 0.005, "{}", r1 / r6);
        // Eq. 3.8 at theta_n = 0 is R_t / sin(theta_t) + r.
        for d in [1.0, 6.0, 10.0, 25.0, 45.0, 80.0] {
            let expected = (R - CORNER) / deg(d).sin() + CORNER;
            assert!((effective_radius(R, CORNER, deg(d), 0.0) - expected).abs() <= 1e-12 * expected);
        }
    }

    /// The torus (centre circle of radius R_t tilted by theta_t about the
    /// feed-normal plane, tube radius r) seen along the feed: the lowest
    /// point at cross-feed offset y, as the lowest point over the tube's
    /// spheres (golden-section search on the centre-circle angle), built in
    /// 3-D without the ellipse.
    fn profile_from_torus(pitch: f64, y: f64) -> f64 {
        let (rt, r) = (R - CORNER, CORNER);
        // Axis u = (sin t, 0, cos t) in (f, t, n) = (x, y, z); e1 = (cos t, 0, -sin t), e2 = y.
        let centre = |phi: f64| {
            let (s, c) = phi.sin_cos();
            (rt * s, rt * c * -pitch.sin())
        };
        let low = |phi: f64| {
            let (cy, cz) = centre(phi);
            let d = y - cy;
            cz - (r * r - d * d).max(0.0).sqrt()
        };
        // The centres within r of the section y: sin(phi) in [(y - r) / R_t, (y + r) / R_t].
        let (mut a, mut b) = (((y - r) / rt).max(-1.0).asin(), ((y + r) / rt).min(1.0).asin());
        let g = (5f64.sqrt() - 1.0) / 2.0;
        for _ in 0..200 {
            let (c, d) = (b - g * (b - a), a + g * (b - a));
            if low(c) < low(d) {
                b = d;
            } else {
                a = c;
            }
        }
        low(0.5 * (a + b))
    }

    /// Spec 12.1 item 4: R_eff equals the radius of curvature of the swept
    /// profile at its lowest point, computed independently by central
    /// differences of the torus seen along the feed.
    #[test]
    fn effective_radius_is_the_curvature_radius_of_the_swept_profile() {
        for d in [1.0, 6.0, 10.0, 15.0, 25.0, 45.0] {
            let t = deg(d);
            let h = 0.01;
            let z = |y: f64| profile_from_torus(t, y);
            let curvature = (z(h) - 2.0 * z(0.0) + z(-h)) / (h * h);
            let reff = effective_radius(R, CORNER, t, 0.0);
            assert!((1.0 / curvature - reff).abs() <= 1e-5 * reff, "{d} deg: {} vs {reff}", 1.0 / curvature);
            // The ellipse profile of the module agrees with the 3-D torus.
            for y in [0.3, 1.0, 2.25, 3.4, 4.5] {
                let p = swept_profile(R, CORNER, t, y).unwrap();
                assert!((p - (z(y) - z(0.0))).abs() < 1e-9, "{d} deg at {y}: {p}");
            }
        }
    }

    /// Spec 6.3 table: exact scallop 0.0804 mm at 6 deg (and the other rows),
    /// above the osculating-circle h_c of Eq. 3.9.
    #[test]
    fn exact_scallop_between_two_passes() {
        let h6 = exact_scallop(R, CORNER, deg(6.0), AE).unwrap();
        assert!((h6 - 0.0804).abs() <= 1e-4, "{h6}");
        for (d, exact) in [(1.0, 0.0141), (10.0, 0.1285), (15.0, 0.1834), (25.0, 0.2777), (45.0, 0.4160)] {
            let h = exact_scallop(R, CORNER, deg(d), AE).unwrap();
            assert!((h - exact).abs() <= 1e-4, "{d} deg: {h}");
            assert!(h > scallop_height(AE, effective_radius(R, CORNER, deg(d), 0.0)));
        }
        // Flat: the crest is on the corner arc only beyond R_t.
        assert_eq!(exact_scallop(R, CORNER, 0.0, AE), Some(0.0));
        assert!(exact_scallop(R, CORNER, deg(6.0), 2.0 * R).is_none());
    }

    /// Spec 12.1 item 4: theta_n = 90 deg gives r; the apparent contour at
    /// (10 deg, 30 deg) is 16.62 mm where Eq. 3.8 gives 4.97 mm.
    #[test]
    fn yaw_gives_the_corner_and_the_apparent_contour() {
        for d in [1.0, 6.0, 30.0, 60.0] {
            let r90 = effective_radius(R, CORNER, deg(d), deg(90.0));
            assert!((r90 - CORNER).abs() < 1e-12, "{r90}");
            let c90 = apparent_contour_radius(R, CORNER, deg(d), deg(90.0));
            assert!((c90 - CORNER).abs() < 1e-12, "{c90}");
            let e0 = effective_radius(R, CORNER, deg(d), 0.0);
            assert!((apparent_contour_radius(R, CORNER, deg(d), 0.0) - e0).abs() <= 1e-12 * e0);
        }
        let c = apparent_contour_radius(R, CORNER, deg(10.0), deg(30.0));
        assert!((c - 16.62).abs() < 0.005, "{c}");
        let e = effective_radius(R, CORNER, deg(10.0), deg(30.0));
        assert!((e - 4.97).abs() < 0.005, "{e}");
    }
}
