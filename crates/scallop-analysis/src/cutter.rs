//! Cutters, effective cutting radius and step-over (finishing.md 5).
//!
//! Angles in radians, lengths in mm.

use std::f64::consts::FRAC_PI_2;

use serde::{Deserialize, Serialize};

use crate::tol;

/// A finishing cutter as the analytic models see it (finishing.md 5.1).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Cutter {
    /// Ball-end cutter of radius `R`: `R_eff = R` in any direction.
    Ball {
        /// `R` (mm).
        radius: f64,
    },
    /// Toroidal (bull-nose) cutter of outer radius `R` and corner radius `r <= R`.
    Toroidal {
        /// `R` (mm).
        radius: f64,
        /// `r` (mm).
        corner: f64,
    },
    /// Flat-end cutter of radius `R` inclined by `phi` (Vickers and Quan): defined
    /// for completeness, excluded from finishing (finishing.md 1).
    Flat {
        /// `R` (mm).
        radius: f64,
        /// Inclination `phi` of the tool axis (rad).
        inclination: f64,
    },
}

/// Folds any angle between two directions (defined modulo pi) into `[0, pi/2]`.
///
/// ```
/// use std::f64::consts::PI;
/// let a = scallop_analysis::fold_direction_angle(0.75 * PI);
/// assert!((a - 0.25 * PI).abs() < 1e-15);
/// ```
#[must_use]
pub fn fold_direction_angle(angle: f64) -> f64 {
    let a = angle.rem_euclid(std::f64::consts::PI);
    if a > FRAC_PI_2 { std::f64::consts::PI - a } else { a }
}

impl Cutter {
    /// Outer radius `R` (mm).
    #[must_use]
    pub fn radius(&self) -> f64 {
        match *self {
            Cutter::Ball { radius } | Cutter::Toroidal { radius, .. } | Cutter::Flat { radius, .. } => radius,
        }
    }

    /// Effective cutting radius `R_eff` (mm) at a point of tilt `slope` (`s`, rad)
    /// fed in a direction at angle `alpha` (rad, any value; folded into `[0, pi/2]`)
    /// from the steepest-slope direction, both measured as **horizontal (XY)
    /// projections** (finishing.md 5.1 \[DECISION\]).
    ///
    /// - Ball: `R`.
    /// - Flat: `R / sin(phi)`, `+inf` when `sin(phi) < SIN_SLOPE_HORIZONTAL`.
    /// - Toroidal, Eq. 1.5 written without cancellation
    ///   (`1 - sin^2(a) sin^2(s) = cos^2(a) + sin^2(a) cos^2(s)`):
    ///
    /// ```text
    /// R_eff = (R - r) cos^2(a) / ( sin(s) (cos^2(a) + sin^2(a) cos^2(s)) ) + r
    /// ```
    ///
    ///   `+inf` when `sin(s) < SIN_SLOPE_HORIZONTAL` (horizontal: the flat bottom
    ///   cuts; the step-over is then capped, see [`Cutter::step_over`]); `r` at the
    ///   0/0 point `s = a = pi/2` (vertical wall fed along itself: the corner circle
    ///   cuts, the smallest and so the safe value).
    ///
    /// ```
    /// use scallop_analysis::Cutter;
    /// let torus = Cutter::Toroidal { radius: 5.0, corner: 2.0 };
    /// let r = torus.effective_radius(60f64.to_radians(), 0.0);
    /// assert!((r - 5.464_101_6).abs() < 1e-6);                                   // A2
    /// assert!((torus.effective_radius(0.5, std::f64::consts::FRAC_PI_2) - 2.0).abs() < 1e-12);
    /// ```
    #[must_use]
    pub fn effective_radius(&self, slope: f64, alpha: f64) -> f64 {
        match *self {
            Cutter::Ball { radius } => radius,
            Cutter::Flat { radius, inclination } => {
                let sin_phi = inclination.sin().abs();
                if sin_phi < tol::SIN_SLOPE_HORIZONTAL { f64::INFINITY } else { radius / sin_phi }
            }
            Cutter::Toroidal { radius, corner } => {
                let sin_s = slope.sin().abs();
                if sin_s < tol::SIN_SLOPE_HORIZONTAL {
                    return f64::INFINITY;
                }
                let alpha = fold_direction_angle(alpha);
                let (sin_a, cos_a) = alpha.sin_cos();
                let cos_s = slope.cos();
                let across = cos_a * cos_a + sin_a * sin_a * cos_s * cos_s;
                if across <= 0.0 {
                    return corner;
                }
                (radius - corner) * cos_a * cos_a / (sin_s * across) + corner
            }
        }
    }

    /// The largest step-over the cutter geometry allows, whatever `R_eff`
    /// (finishing.md 5.3): toroidal `sod_max = 2 (R - r) + 2 sqrt(2 r sh - sh^2)`
    /// (flat bottom plus the corner's own scallop); ball `2 sqrt(2 R sh - sh^2)`;
    /// flat `2 R`.
    ///
    /// ```
    /// let torus = scallop_analysis::Cutter::Toroidal { radius: 5.0, corner: 2.0 };
    /// assert!((torus.max_step_over(0.01) - 6.399_5).abs() < 1e-4);               // A16
    /// ```
    #[must_use]
    pub fn max_step_over(&self, scallop_height: f64) -> f64 {
        match *self {
            Cutter::Ball { radius } => step_over(scallop_height, radius),
            Cutter::Toroidal { radius, corner } => 2.0 * (radius - corner) + step_over(scallop_height, corner),
            Cutter::Flat { radius, .. } => 2.0 * radius,
        }
    }

    /// Step-over (mm) at tilt `slope` and horizontal feed angle `alpha` for scallop
    /// height `scallop_height`: `min(2 sqrt(2 sh R_eff - sh^2), max_step_over)`
    /// (finishing.md 5.2, 5.3). Ball: constant. Finite for every input.
    ///
    /// ```
    /// use scallop_analysis::Cutter;
    /// let torus = Cutter::Toroidal { radius: 5.0, corner: 2.0 };
    /// assert!((torus.step_over(0.01, 60f64.to_radians(), 0.0) - 0.660_9).abs() < 1e-4);
    /// assert_eq!(torus.step_over(0.01, 0.0, 0.0), torus.max_step_over(0.01)); // horizontal
    /// ```
    #[must_use]
    pub fn step_over(&self, scallop_height: f64, slope: f64, alpha: f64) -> f64 {
        let r_eff = self.effective_radius(slope, alpha);
        let cap = self.max_step_over(scallop_height);
        if r_eff.is_finite() { step_over(scallop_height, r_eff).min(cap) } else { cap }
    }
}

/// Eq. 2.3: step-over `sod = 2 sqrt(2 sh R_eff - sh^2)` (mm) between passes of a
/// cutter of effective radius `effective_radius` leaving scallops of height
/// `scallop_height` on a locally flat surface. The radicand is clamped at 0 and
/// `+inf` radii give `+inf`.
///
/// ```
/// let sod = scallop_analysis::step_over(0.01, 5.0);
/// assert!((sod - 0.632_1).abs() < 1e-4);
/// assert!((scallop_analysis::effective_radius_for_step_over(0.01, sod) - 5.0).abs() < 1e-12);
/// ```
#[must_use]
pub fn step_over(scallop_height: f64, effective_radius: f64) -> f64 {
    if effective_radius.is_infinite() {
        return f64::INFINITY;
    }
    2.0 * (scallop_height * (2.0 * effective_radius - scallop_height)).max(0.0).sqrt()
}

/// Inverse of [`step_over`]: `R_eff = (sod^2 + 4 sh^2) / (8 sh)` (mm), used by Eq. 2.10.
#[must_use]
pub fn effective_radius_for_step_over(scallop_height: f64, step_over: f64) -> f64 {
    (step_over * step_over + 4.0 * scallop_height * scallop_height) / (8.0 * scallop_height)
}
