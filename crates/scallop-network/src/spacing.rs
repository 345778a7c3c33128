//! NEXT_SPACING (finishing.md 6.4): the horizontal plane spacing a contact point
//! allows, from its unit normal, without trigonometry.
//!
//! With `n` the unit normal, `f = (cos t, sin t, 0)` the feed and `m = (-sin t,
//! cos t, 0)` the plane normal, `h = |(n_x, n_y)|`:
//!
//! ```text
//! sin s = h, cos s = |n_z|, cos a = |f . n| / h, sin a = |m . n| / h
//! Eq. 1.5:  R_eff = (R - r) (f.n)^2 / ( h ((f.n)^2 + (m.n)^2 n_z^2) ) + r
//! c = n x (m x n) = m - (n.m) n,  so  |c . m| / |c| = sqrt(1 - (n.m)^2)
//! Delta = sod(R_eff) sqrt(1 - (n.m)^2)
//! ```
//!
//! which is `scallop_analysis::Cutter::step_over(sh, s, a)` (5.2, 5.3) with `s` and
//! `a` read from the normal (the unit test below checks the two agree).

use scallop_analysis::Cutter;
use scallop_geom::Vec3;

use scallop_strategy::StrategyError;

/// The cutter's step-over constants for one scallop height.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ToolModel {
    /// `R - r` (0 for a ball).
    flat_part: f64,
    /// Corner radius `r` (ball: `R`).
    corner: f64,
    /// `sh`.
    scallop_height: f64,
    /// Largest step-over (5.3), and the constant one of a ball.
    cap: f64,
    /// Ball: `R_eff = R` everywhere.
    ball: bool,
    /// Flat end (`r = 0`): at least the saw tooth `sh / sin s`.
    flat: bool,
}

impl ToolModel {
    pub(crate) fn new(tool: &Cutter, scallop_height: f64) -> Result<ToolModel, StrategyError> {
        if !(scallop_height.is_finite() && scallop_height > 0.0) {
            return Err(StrategyError::BadParameter {
                name: "scallop_height",
                value: scallop_height,
                fix: "give a positive scallop height in mm (e.g. 0.01)",
            });
        }
        let bad_radius = |value: f64| StrategyError::BadParameter {
            name: "tool.radius",
            value,
            fix: "give a positive radius in mm, the corner radius in [0, radius]",
        };
        let (radius, corner, ball) = match *tool {
            Cutter::Ball { radius } => (radius, radius, true),
            Cutter::Toroidal { radius, corner } => (radius, corner, false),
            Cutter::Flat { .. } => return Err(StrategyError::Unsupported { shape: "flat (inclined)" }),
        };
        if !(radius.is_finite() && radius > 0.0 && corner.is_finite() && (0.0..=radius).contains(&corner)) {
            return Err(bad_radius(if radius.is_finite() && radius > 0.0 { corner } else { radius }));
        }
        let flat = corner <= 0.0;
        let bound = if flat { radius } else { corner };
        if scallop_height >= bound {
            let what = if ball || flat { "radius" } else { "corner radius" };
            return Err(StrategyError::ScallopTooLarge { scallop_height, what, radius: bound });
        }
        let cap = if flat { 2.0 * radius } else { tool.max_step_over(scallop_height) };
        Ok(ToolModel { flat_part: radius - corner, corner, scallop_height, cap, ball, flat })
    }

    /// The largest spacing any point can allow.
    pub(crate) fn cap(&self) -> f64 {
        self.cap
    }

    /// `Delta` of 6.4 at a point of (not necessarily unit) normal `n` for feed
    /// `f` and plane normal `m` (unit, horizontal).
    #[inline]
    pub(crate) fn spacing(&self, n: &Vec3, f: [f64; 2], m: [f64; 2]) -> f64 {
        let norm2 = n.norm_squared();
        if norm2 <= 0.0 {
            return self.cap;
        }
        let inv = norm2.sqrt().recip();
        let (nx, ny, nz) = (n.x * inv, n.y * inv, n.z * inv);
        let nm = nx * m[0] + ny * m[1];
        let factor = (1.0 - nm * nm).max(0.0).sqrt();
        if self.ball {
            return self.cap * factor;
        }
        let h2 = nx * nx + ny * ny;
        let h = h2.sqrt();
        if h < scallop_analysis::tol::SIN_SLOPE_HORIZONTAL {
            return self.cap * factor;
        }
        let nf = nx * f[0] + ny * f[1];
        let across = nf * nf + nm * nm * nz * nz;
        let r_eff = if across <= 0.0 { self.corner } else { self.flat_part * nf * nf / (h * across) + self.corner };
        let sh = self.scallop_height;
        let mut sod = (2.0 * (sh * (2.0 * r_eff - sh)).max(0.0).sqrt()).min(self.cap);
        if self.flat {
            // A sharp rim leaves a saw tooth of height sod sin s, not a circle.
            sod = sod.max(sh / h).min(self.cap);
        }
        sod * factor
    }

    /// Whether [`ToolModel::spacing`] at the unit normal `w / |w|` (`w` of any
    /// length, the normal up to rounding) is certainly above `best`: a
    /// conservative test without square root or division, false whenever in
    /// doubt (a flat end, `best` not finite, `w` badly scaled, a point near the
    /// horizontal-slope threshold, ...).
    ///
    /// With `N = |w|^2`, `W_m = w . m`, `W_f = w . f`, `H = w_x^2 + w_y^2` the
    /// exact quantities are `F = 1 - (n . m)^2 = (N - W_m^2) / N`, `h^2 = H / N`,
    /// `across = (W_f^2 N + W_m^2 w_z^2) / N^2`, `R_eff = r + (R - r) W_f^2
    /// N^1.5 / (sqrt(H) A)` with `A = N^2 across`, and `spacing^2 = min(4 sh (2
    /// R_eff - sh), cap^2) F`. The test bounds `F` and `W_f^2` from below by
    /// `1e-12 N` (far above the rounding of either evaluation, and of their
    /// cancellations), `A` from above, adds a relative slack of `1e-9` to `best^2`
    /// and compares squares: `4 sh (2 R_eff - sh) F >= B` is `8 sh (R_eff - r)
    /// (N F) >= U = B N - 4 sh (2 r - sh) (N F)`, squared on both sides.
    #[inline]
    pub(crate) fn exceeds(&self, w: &Vec3, f: [f64; 2], m: [f64; 2], best: f64) -> bool {
        const SLACK: f64 = 1e-9;
        const ABS: f64 = 1e-12;
        // Every condition is evaluated and combined without branches (the
        // caller branches once, on the result); values out of range give
        // infinities or NaN, which fail the comparisons or are not selected.
        let n2 = w.x * w.x + w.y * w.y + w.z * w.z;
        // N scaled so that the powers below (up to N^7) stay normal numbers.
        let valid = !self.flat & best.is_finite() & (1e-20..=1e20).contains(&n2);
        let b = best * best * (1.0 + SLACK);
        let wm = w.x * m[0] + w.y * m[1];
        // N F from below; the spacing is at most cap sqrt(F) whatever the radius.
        let f_lo = (n2 - wm * wm) - ABS * n2;
        let cap_ok = (f_lo > 0.0) & (self.cap * self.cap * f_lo >= b * n2);
        let s2 = scallop_analysis::tol::SIN_SLOPE_HORIZONTAL * scallop_analysis::tol::SIN_SLOPE_HORIZONTAL;
        let hx = w.x * w.x + w.y * w.y;
        // Clearly horizontal: the spacing is cap sqrt(F), tested above.
        let horizontal = hx < s2 * n2 * (1.0 - SLACK);
        let sloped = hx > s2 * n2 * (1.0 + SLACK);
        let sh = self.scallop_height;
        let u = b * n2 - 4.0 * sh * (2.0 * self.corner - sh) * f_lo;
        let wf = w.x * f[0] + w.y * f[1];
        let x_lo = (wf * wf - ABS * n2).max(0.0);
        let a_hi = ((wf * wf + ABS * n2) * n2 + (wm * wm + ABS * n2) * (w.z * w.z)) * (1.0 + SLACK);
        let lhs = {
            let t = 8.0 * sh * self.flat_part * x_lo * n2 * f_lo;
            t * t * n2
        };
        let rhs = u * u * hx * a_hi * a_hi * (1.0 + SLACK);
        // `u <= 0`: even R_eff = r allows more than best.
        let radius_ok = (u <= 0.0) | (lhs.is_finite() & rhs.is_finite() & (rhs > 0.0) & (lhs >= rhs));
        valid & cap_ok & (self.ball | horizontal | (sloped & radius_ok))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `exceeds` never claims a spacing above `best` that the exact evaluation
    /// (normalise, then `spacing`) does not give, on random and on adversarial
    /// normals (nearly along `m`, nearly across `f`, at the horizontal-slope
    /// threshold, badly scaled) with `best` at and around the exact value; and
    /// it does skip most points well above `best`.
    #[test]
    fn exceeds_is_conservative() {
        let tools = [
            Cutter::Toroidal { radius: 5.0, corner: 2.0 },
            Cutter::Toroidal { radius: 6.0, corner: 0.5 },
            Cutter::Ball { radius: 3.0 },
            Cutter::Toroidal { radius: 4.0, corner: 0.0 },
        ];
        let mut rng = scallop_geom::rng::SplitMix64::new(0x2545_f491_4f6c_dd1d);
        let mut random = || rng.unit();
        let sin_h = scallop_analysis::tol::SIN_SLOPE_HORIZONTAL;
        for tool in tools {
            let model = ToolModel::new(&tool, 0.01).unwrap_or_else(|e| panic!("{e}"));
            let (mut skipped, mut clear) = (0usize, 0usize);
            for case in 0..40_000 {
                let theta = random() * std::f64::consts::TAU;
                let f = [theta.cos(), theta.sin()];
                let m = [-f[1], f[0]];
                let (slope, azimuth) = (random() * 1.55, random() * std::f64::consts::TAU);
                let mut n = Vec3::new(slope.sin() * azimuth.cos(), slope.sin() * azimuth.sin(), slope.cos());
                let tiny = 1e-9 * (random() - 0.5);
                match case % 6 {
                    // Nearly along m (F near 0).
                    1 => n = Vec3::new(m[0] + tiny, m[1], tiny.abs() * 1e-3),
                    // Nearly across f (f . n near 0).
                    2 => n = Vec3::new(m[0] * n.x.abs() + f[0] * tiny, m[1] * n.x.abs() + f[1] * tiny, n.z),
                    // At the horizontal-slope threshold.
                    3 => {
                        let h = sin_h * (1.0 + tiny);
                        n = Vec3::new(h * azimuth.cos(), h * azimuth.sin(), (1.0 - h * h).sqrt());
                    }
                    _ => {}
                }
                let w = n * 10f64.powf(random() * 24.0 - 12.0);
                let unit = w / w.norm();
                let exact = model.spacing(&unit, f, m);
                for best in [
                    exact,
                    exact * (1.0 + 1e-15),
                    exact * (1.0 - 1e-15),
                    exact * (1.0 - 1e-10),
                    exact * (1.0 - 1e-6),
                    exact * 0.5,
                    exact * random(),
                ] {
                    if model.exceeds(&w, f, m, best) {
                        assert!(exact > best, "{tool:?} case {case}: w {w:?} spacing {exact} best {best}");
                        skipped += usize::from(best <= exact * 0.5);
                    }
                }
                clear += usize::from(case % 6 == 0 || case % 6 >= 4);
            }
            if !matches!(tool, Cutter::Toroidal { corner, .. } if corner == 0.0) {
                // Half the exact spacing is skipped on ordinary normals.
                assert!(skipped * 10 >= clear * 9, "{tool:?}: {skipped} of {clear}");
            }
        }
    }

    /// The trigonometry-free form equals `Cutter::step_over` times `|c . m|`.
    #[test]
    fn matches_the_analysis_step_over() {
        let torus = Cutter::Toroidal { radius: 5.0, corner: 2.0 };
        let model = ToolModel::new(&torus, 0.01).unwrap_or_else(|e| panic!("{e}"));
        for &theta in &[0.0, 0.4, 1.3, 2.9] {
            let f = [f64::cos(theta), f64::sin(theta)];
            let m = [-f[1], f[0]];
            for &(s, dir) in &[(0.3, 0.2), (1.0, -1.1), (0.05, 2.0), (1.4, 0.7)] {
                let n = Vec3::new(f64::sin(s) * f64::cos(dir), f64::sin(s) * f64::sin(dir), f64::cos(s));
                let alpha = dir - theta;
                let sod = torus.step_over(0.01, s, alpha);
                let mv = Vec3::new(m[0], m[1], 0.0);
                let tau = mv.cross(&n).normalize();
                let c = n.cross(&tau).normalize();
                let expected = sod * c.dot(&mv).abs();
                let got = model.spacing(&(n * 3.0), f, m);
                assert!((got - expected).abs() < 1e-12 * expected.max(1.0), "{got} vs {expected}");
            }
        }
    }
}
