//! Cutter shapes, their profiles and validation.

use std::f64::consts::FRAC_PI_2;

/// Why a cutter description is not a real tool. Each says which number and the fix.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CutterError {
    /// A size that must be a finite positive number of mm.
    #[error("{what} must be a finite number > 0 mm, got {value}")]
    NotPositive {
        /// Which size.
        what: &'static str,
        /// The value given.
        value: f64,
    },
    /// A size outside the physical range of cutters ([`crate::tol`]).
    #[error(
        "{what} {value:?} mm is outside the range of real cutters [{min}, {max}] mm; check the units (mm) and the digits"
    )]
    OutOfRange {
        /// Which size.
        what: &'static str,
        /// The value given.
        value: f64,
        /// Smallest accepted (mm).
        min: f64,
        /// Largest accepted (mm).
        max: f64,
    },
    /// Bull-nose corner radius larger than the cutter radius.
    #[error("corner radius {corner} mm is larger than the cutter radius {radius} mm; use r <= D/2")]
    CornerTooLarge {
        /// Corner radius r.
        corner: f64,
        /// Cutter radius R.
        radius: f64,
    },
    /// Cone half angle outside (0, 90) degrees.
    #[error("cone half angle {degrees} deg must lie strictly between 0 and 90 deg")]
    BadConeAngle {
        /// The half angle in degrees.
        degrees: f64,
    },
    /// The flutes are shorter than the cutting profile.
    #[error("flute length {flute} mm is shorter than the cutting profile's height {profile} mm")]
    FluteTooShort {
        /// Flute length.
        flute: f64,
        /// Height of the profile (corner or cone) above the tip.
        profile: f64,
    },
}

/// The cutting profile. Radii in mm, angles in radians.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CutterShape {
    /// Flat end mill (cylinder) of radius R.
    Flat {
        /// R (mm).
        radius: f64,
    },
    /// Ball end mill of radius R.
    Ball {
        /// R (mm).
        radius: f64,
    },
    /// Bull-nose (toroidal) end mill: radius R, corner radius r (0 < r <= R).
    Bull {
        /// R (mm).
        radius: f64,
        /// r (mm).
        corner: f64,
    },
    /// Cone (V) cutter: radius R at the top of the cone, half angle between axis and flank.
    Cone {
        /// R (mm).
        radius: f64,
        /// Half of the included tip angle (radians).
        half_angle: f64,
    },
}

impl CutterShape {
    /// Radius R of the cutter.
    #[must_use]
    pub fn radius(&self) -> f64 {
        match *self {
            CutterShape::Flat { radius }
            | CutterShape::Ball { radius }
            | CutterShape::Bull { radius, .. }
            | CutterShape::Cone { radius, .. } => radius,
        }
    }

    /// Height above the tip of the profile at radial distance `rho` (0 <= rho <= R):
    /// OpenCAMLib's `height(r)`.
    ///
    /// ```
    /// use scallop_cutter::CutterShape;
    /// let ball = CutterShape::Ball { radius: 2.0 };
    /// assert_eq!(ball.height_at(2.0), 2.0);
    /// assert_eq!(ball.height_at(0.0), 0.0);
    /// ```
    #[must_use]
    pub fn height_at(&self, rho: f64) -> f64 {
        match *self {
            CutterShape::Flat { .. } => 0.0,
            // h = R - sqrt(R^2 - rho^2)
            CutterShape::Ball { radius } => radius - (radius * radius - rho * rho).max(0.0).sqrt(),
            // h = r - sqrt(r^2 - (rho - (R - r))^2) on the corner, 0 on the flat bottom
            CutterShape::Bull { radius, corner } => {
                let s = rho - (radius - corner);
                if s <= 0.0 { 0.0 } else { corner - (corner * corner - s * s).max(0.0).sqrt() }
            }
            // h = rho / tan(alpha)
            CutterShape::Cone { half_angle, .. } => rho / half_angle.tan(),
        }
    }

    /// Radial distance of the profile at height `h` above the tip, capped at R:
    /// OpenCAMLib's `width(h)`.
    ///
    /// ```
    /// use scallop_cutter::CutterShape;
    /// let cone = CutterShape::Cone { radius: 5.0, half_angle: std::f64::consts::FRAC_PI_4 };
    /// assert!((cone.radius_at(1.0) - 1.0).abs() < 1e-12);
    /// assert_eq!(cone.radius_at(100.0), 5.0);
    /// ```
    #[must_use]
    pub fn radius_at(&self, h: f64) -> f64 {
        let h = h.max(0.0);
        match *self {
            CutterShape::Flat { radius } => radius,
            CutterShape::Ball { radius } => {
                if h >= radius {
                    radius
                } else {
                    (radius * radius - (radius - h) * (radius - h)).sqrt()
                }
            }
            CutterShape::Bull { radius, corner } => {
                if h >= corner {
                    radius
                } else {
                    radius - corner + (corner * corner - (corner - h) * (corner - h)).sqrt()
                }
            }
            CutterShape::Cone { radius, half_angle } => (h * half_angle.tan()).min(radius),
        }
    }

    /// Height above the tip where the profile reaches R (0 for flat).
    #[must_use]
    pub fn profile_height(&self) -> f64 {
        match *self {
            CutterShape::Flat { .. } => 0.0,
            CutterShape::Ball { radius } => radius,
            CutterShape::Bull { corner, .. } => corner,
            CutterShape::Cone { radius, half_angle } => radius / half_angle.tan(),
        }
    }

    fn validate(&self) -> Result<(), CutterError> {
        let r = self.radius();
        positive("cutter radius", r)?;
        in_range("cutter radius", r, crate::tol::MIN_RADIUS, crate::tol::MAX_RADIUS)?;
        match *self {
            CutterShape::Bull { radius, corner } => {
                positive("corner radius", corner)?;
                if corner > radius {
                    return Err(CutterError::CornerTooLarge { corner, radius });
                }
            }
            CutterShape::Cone { half_angle, .. } => {
                if !(half_angle.is_finite() && half_angle > 0.0 && half_angle < FRAC_PI_2) {
                    return Err(CutterError::BadConeAngle { degrees: half_angle.to_degrees() });
                }
            }
            CutterShape::Flat { .. } | CutterShape::Ball { .. } => {}
        }
        Ok(())
    }
}

/// The profile with its constants computed once (no trigonometry in the hot loop).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Profile {
    pub(crate) shape: CutterShape,
    pub(crate) radius: f64,
    /// R - r for the bull-nose.
    pub(crate) flat_radius: f64,
    /// r for the bull-nose and R for the ball.
    pub(crate) corner: f64,
    /// tan(half angle) for the cone.
    pub(crate) tan: f64,
    /// 1 / tan(half angle) for the cone.
    pub(crate) cot: f64,
}

impl Profile {
    pub(crate) fn new(shape: &CutterShape) -> Profile {
        let radius = shape.radius();
        let (flat_radius, corner, tan) = match *shape {
            CutterShape::Flat { .. } => (radius, 0.0, 0.0),
            CutterShape::Ball { radius } => (0.0, radius, 0.0),
            CutterShape::Bull { radius, corner } => (radius - corner, corner, 0.0),
            CutterShape::Cone { half_angle, .. } => (0.0, 0.0, half_angle.tan()),
        };
        let cot = if tan > 0.0 { 1.0 / tan } else { 0.0 };
        Profile { shape: *shape, radius, flat_radius, corner, tan, cot }
    }

    /// [`Profile::height`] at the horizontal distance `sqrt(rho2)`, for bounds:
    /// without the square root of `rho2` where the profile does not need it
    /// (flat, ball), so equal to `height(rho2.sqrt())` up to rounding only.
    #[inline(always)]
    pub(crate) fn height_sq(&self, rho2: f64) -> f64 {
        match self.shape {
            CutterShape::Flat { .. } => 0.0,
            CutterShape::Ball { .. } => self.corner - (self.corner * self.corner - rho2).max(0.0).sqrt(),
            CutterShape::Bull { .. } | CutterShape::Cone { .. } => self.height(rho2.sqrt()),
        }
    }

    /// The profile's slope dh/drho at radial distance `rho`, where it is
    /// positive and finite (`None` on a flat bottom, for the flat end, and at
    /// or past the rim of a ball or a bull-nose's corner).
    #[inline]
    pub(crate) fn slope(&self, rho: f64) -> Option<f64> {
        let slope = match self.shape {
            CutterShape::Flat { .. } => return None,
            CutterShape::Ball { .. } | CutterShape::Bull { .. } => {
                let s = rho - self.flat_radius;
                let r = self.corner;
                s / (r * r - s * s).sqrt()
            }
            CutterShape::Cone { .. } => self.cot,
        };
        (slope.is_finite() && slope > 0.0).then_some(slope)
    }

    /// Same as [`CutterShape::height_at`], without trigonometry.
    #[inline(always)]
    pub(crate) fn height(&self, rho: f64) -> f64 {
        match self.shape {
            CutterShape::Flat { .. } => 0.0,
            CutterShape::Ball { .. } => self.corner - (self.corner * self.corner - rho * rho).max(0.0).sqrt(),
            CutterShape::Bull { .. } => {
                let s = rho - self.flat_radius;
                if s <= 0.0 { 0.0 } else { self.corner - (self.corner * self.corner - s * s).max(0.0).sqrt() }
            }
            CutterShape::Cone { .. } => rho * self.cot,
        }
    }
}

fn in_range(what: &'static str, value: f64, min: f64, max: f64) -> Result<(), CutterError> {
    if (min..=max).contains(&value) { Ok(()) } else { Err(CutterError::OutOfRange { what, value, min, max }) }
}

fn length(what: &'static str, value: f64) -> Result<(), CutterError> {
    positive(what, value)?;
    in_range(what, value, 0.0, crate::tol::MAX_LENGTH)
}

fn positive(what: &'static str, value: f64) -> Result<(), CutterError> {
    if value.is_finite() && value > 0.0 { Ok(()) } else { Err(CutterError::NotPositive { what, value }) }
}

/// One solid of revolution of the holder stack, from the bottom up: a cylinder
/// when both radii are equal, else a cone frustum.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HolderSegment {
    /// Height of the segment (mm).
    pub length: f64,
    /// Radius at its bottom (mm).
    pub bottom_radius: f64,
    /// Radius at its top (mm).
    pub top_radius: f64,
}

/// A milling cutter: profile, flutes, shank and holder. Validated on construction.
#[derive(Debug, Clone, PartialEq)]
pub struct Cutter {
    shape: CutterShape,
    flute_length: f64,
    shank_radius: f64,
    shank_length: f64,
    holder: Vec<HolderSegment>,
}

impl Cutter {
    /// A cutter with the given profile and flute length; the shank has the
    /// cutter's radius and the flute length, and there is no holder until
    /// [`Cutter::with_holder`].
    ///
    /// # Errors
    /// Non-positive or non-finite sizes, a radius or length outside [`crate::tol`], r > R, a cone angle outside (0, 90) deg,
    /// flutes shorter than the profile.
    ///
    /// ```
    /// use scallop_cutter::{Cutter, CutterShape};
    /// assert!(Cutter::new(CutterShape::Bull { radius: 5.0, corner: 6.0 }, 20.0).is_err());
    /// assert!(Cutter::new(CutterShape::Bull { radius: 5.0, corner: 2.0 }, 20.0).is_ok());
    /// ```
    pub fn new(shape: CutterShape, flute_length: f64) -> Result<Cutter, CutterError> {
        shape.validate()?;
        length("flute length", flute_length)?;
        let profile = shape.profile_height();
        if flute_length < profile {
            return Err(CutterError::FluteTooShort { flute: flute_length, profile });
        }
        Ok(Cutter { shape, flute_length, shank_radius: shape.radius(), shank_length: flute_length, holder: Vec::new() })
    }

    /// Sets the shank (above the flutes).
    ///
    /// # Errors
    /// Non-positive sizes or sizes over [`crate::tol::MAX_LENGTH`].
    pub fn with_shank(mut self, radius: f64, length: f64) -> Result<Cutter, CutterError> {
        self::length("shank radius", radius)?;
        self::length("shank length", length)?;
        self.shank_radius = radius;
        self.shank_length = length;
        Ok(self)
    }

    /// Sets the holder stack (bottom segment first).
    ///
    /// # Errors
    /// Non-positive sizes or sizes over [`crate::tol::MAX_LENGTH`].
    pub fn with_holder(mut self, segments: Vec<HolderSegment>) -> Result<Cutter, CutterError> {
        for s in &segments {
            length("holder segment length", s.length)?;
            length("holder segment bottom radius", s.bottom_radius)?;
            length("holder segment top radius", s.top_radius)?;
        }
        self.holder = segments;
        Ok(self)
    }

    /// The cutting profile.
    #[must_use]
    pub fn shape(&self) -> &CutterShape {
        &self.shape
    }

    /// Radius R.
    #[must_use]
    pub fn radius(&self) -> f64 {
        self.shape.radius()
    }

    /// Flute length (mm).
    #[must_use]
    pub fn flute_length(&self) -> f64 {
        self.flute_length
    }

    /// Shank radius (mm).
    #[must_use]
    pub fn shank_radius(&self) -> f64 {
        self.shank_radius
    }

    /// Shank length above the flutes (mm).
    #[must_use]
    pub fn shank_length(&self) -> f64 {
        self.shank_length
    }

    /// Holder segments, bottom first.
    #[must_use]
    pub fn holder(&self) -> &[HolderSegment] {
        &self.holder
    }
}

#[cfg(test)]
// `unwrap` is allowed in tests by clippy.toml.
#[allow(clippy::float_cmp, reason = "tests: exact values are intended")]
mod tests {
    use super::*;

    #[test]
    fn validation_names_the_number() {
        let e = Cutter::new(CutterShape::Flat { radius: f64::NAN }, 10.0).unwrap_err();
        assert!(e.to_string().contains("cutter radius"), "{e}");
        let e = Cutter::new(CutterShape::Cone { radius: 3.0, half_angle: 0.0 }, 10.0).unwrap_err();
        assert!(matches!(e, CutterError::BadConeAngle { .. }));
        let e = Cutter::new(CutterShape::Ball { radius: 3.0 }, 1.0).unwrap_err();
        assert!(matches!(e, CutterError::FluteTooShort { .. }));
        let c = Cutter::new(CutterShape::Ball { radius: 3.0 }, 10.0).unwrap();
        assert!(c.clone().with_shank(-1.0, 5.0).is_err());
        let h = HolderSegment { length: 0.0, bottom_radius: 5.0, top_radius: 5.0 };
        assert!(c.with_holder(vec![h]).is_err());
    }

    #[test]
    fn profiles_are_inverse() {
        let shapes = [
            CutterShape::Ball { radius: 3.0 },
            CutterShape::Bull { radius: 3.0, corner: 1.0 },
            CutterShape::Cone { radius: 3.0, half_angle: 0.6 },
        ];
        for s in shapes {
            for k in 1..30 {
                let rho = 3.0 * f64::from(k) / 30.0;
                let h = s.height_at(rho);
                if h > 0.0 {
                    scallop_geom::assert_near!(s.radius_at(h), rho, 1e-9);
                }
            }
        }
    }
}
