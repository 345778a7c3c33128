//! Machining decisions of parallel-planes finishing (no `Default`: every value is
//! the user's choice).

use scallop_analysis::MachineLimits;
use serde::{Deserialize, Serialize};

use crate::StrategyError;

/// Order of the passes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Pattern {
    /// Alternate directions; consecutive passes joined on the CL surface when safe.
    Zigzag,
    /// Every pass in the feed direction; retract, rapid and plunge between passes.
    OneWay,
}

/// Which cutter locations belong to the region to machine.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Boundary {
    /// The cutter's contact lies on the part away from its open boundary: a
    /// facet contact, or an edge or vertex contact on an interior edge or vertex
    /// (a cutter riding on the part's edge, or touching nothing, has left the
    /// part). The contact points of the passes then sweep the surface up to
    /// its edges, so pass lengths are those of the surface (the analytic models
    /// of finishing.md 8 and its "contact-point polyline" lengths, 6.5).
    ContactInside,
}

/// Parameters of [`crate::plan_finishing`]. Lengths mm, angles rad, speeds mm/s.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FinishingParams {
    /// Feed direction: angle of the passes from +X in the XY plane (rad).
    pub direction: f64,
    /// Zigzag or one-way.
    pub pattern: Pattern,
    /// Maximum scallop height `sh` (mm), `0 < sh < R` (and `< r` for a bull-nose).
    pub scallop_height: f64,
    /// Region rule.
    pub boundary: Boundary,
    /// Longest forward step between drop-cutter samples before the chordal
    /// refinement (mm); also the sampling step of the scallop check. Features
    /// narrower than this may be missed by the boundary search.
    pub max_step: f64,
    /// Clearance height above the part's highest point for retracts (mm, > 0).
    pub clearance: f64,
    /// Cutting feed `V`, acceleration `A`, jerk `J` (mm/s, mm/s^2, mm/s^3).
    pub machine: MachineLimits,
    /// Plunge feed (mm/s).
    pub plunge_feed: f64,
    /// Rapid rate (mm/s); rapids use the same `A` and `J`.
    pub rapid_rate: f64,
    /// Direction change (rad) above which a corner is sharp: the stop-to-stop
    /// model (finishing.md 7) stops there; smaller changes are traversed at speed.
    pub sharp_corner: f64,
    /// Corner-blending tolerance of the look-ahead model (mm): the largest
    /// distance the controller may cut off a corner (junction deviation).
    pub blend_tolerance: f64,
}

fn check(name: &'static str, value: f64, ok: bool, fix: &'static str) -> Result<(), StrategyError> {
    if value.is_finite() && ok { Ok(()) } else { Err(StrategyError::BadParameter { name, value, fix }) }
}

impl FinishingParams {
    /// Checks every value; the error names the parameter and the fix.
    ///
    /// # Errors
    /// [`StrategyError::BadParameter`] for the first bad value.
    pub fn validate(&self) -> Result<(), StrategyError> {
        check("direction", self.direction, true, "give a finite angle in radians")?;
        let sh = self.scallop_height;
        check("scallop_height", sh, sh > 0.0, "give a positive height in mm (typically 0.001 to 0.1)")?;
        check("max_step", self.max_step, self.max_step > 0.0, "give a positive step in mm (e.g. 0.5)")?;
        check("clearance", self.clearance, self.clearance > 0.0, "give a positive height above the part in mm")?;
        let m = &self.machine;
        check("machine.feed", m.feed, m.feed > 0.0, "give a positive feed in mm/s")?;
        check("machine.acceleration", m.acceleration, m.acceleration > 0.0, "give a positive acceleration")?;
        check("machine.jerk", m.jerk, m.jerk > 0.0, "give a positive jerk")?;
        check("plunge_feed", self.plunge_feed, self.plunge_feed > 0.0, "give a positive feed in mm/s")?;
        check("rapid_rate", self.rapid_rate, self.rapid_rate > 0.0, "give a positive rate in mm/s")?;
        let pi = std::f64::consts::PI;
        check(
            "sharp_corner",
            self.sharp_corner,
            self.sharp_corner > 0.0 && self.sharp_corner < pi,
            "use 0 < angle < pi rad",
        )?;
        check(
            "blend_tolerance",
            self.blend_tolerance,
            self.blend_tolerance >= 0.0,
            "give a non-negative distance in mm (0 stops at every corner)",
        )
    }
}
