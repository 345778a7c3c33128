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

use crate::StrategyError;

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
}

#[cfg(test)]
mod tests {
    use super::*;

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
