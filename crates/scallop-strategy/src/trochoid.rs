//! Trochoidal slot milling (kinematics.md section 5): the tool centre turns uniformly on a
//! circle of radius `R = (W - D) / 2` whose centre advances `p` per loop along a guide
//! polyline, `P(t) = c(V t) + R (cos t, sin t)` with `V = p / (2 pi)` per radian. The slot
//! is cut by the loops' fronts, never at full width.
//!
//! [DECISION] The circular term is written in the part's XY frame, not in the guide's
//! local frame, so a polyline guide with corners gives a continuous path (the centre just
//! turns the corner). The loop turns counter-clockwise by default (climb milling of the
//! loop front with M03). The parameter step is set by the chordal tolerance from the
//! circle term, `dt = 2 acos(1 - tol / R)`, which makes the deviation of the circle term
//! exactly `tol` (the advance adds a straight component that does not bend the chord).
//!
//! ```
//! use scallop_geom::Point3;
//! use scallop_strategy::trochoid::{trochoid_slot, TrochoidParams};
//! let params = TrochoidParams { diameter: 20.0, width: 28.0, step: 1.5, tolerance: 0.02,
//!     depth: -2.0, clearance: 5.0, feed: 2400.0, clockwise: false };
//! let guide = [Point3::new(0.0, 0.0, 0.0), Point3::new(120.0, 0.0, 0.0)];
//! let path = trochoid_slot(&guide, &params).unwrap();
//! assert!(path.moves().len() > 80 * 31); // 80 loops of about 31 points
//! ```

use scallop_geom::{Point3, Vec3};
use scallop_toolpath::{Move, MoveKind, Toolpath};

use crate::StrategyError;

/// Largest number of points one slot may have (memory guard against absurd inputs).
const MAX_POINTS: f64 = 5e7;

/// Settings of [`trochoid_slot`] (lengths mm, feed mm/min).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrochoidParams {
    /// Cutter diameter D.
    pub diameter: f64,
    /// Slot width W (> D).
    pub width: f64,
    /// Advance per loop p (< 2 pi R so the path loops).
    pub step: f64,
    /// Chordal tolerance of the polyline.
    pub tolerance: f64,
    /// Z of the tool tip while cutting (the slot floor, part frame).
    pub depth: f64,
    /// Height above the guide's highest point for the approach and the retract.
    pub clearance: f64,
    /// Cutting feed.
    pub feed: f64,
    /// Turn the loops clockwise (conventional milling with M03) instead of counter-clockwise.
    pub clockwise: bool,
}

impl TrochoidParams {
    /// Loop radius `R = (W - D) / 2`.
    #[must_use]
    pub fn loop_radius(&self) -> f64 {
        (self.width - self.diameter) / 2.0
    }

    /// Centre advance per radian `V / omega = p / (2 pi)`.
    #[must_use]
    pub fn advance_per_radian(&self) -> f64 {
        self.step / std::f64::consts::TAU
    }

    /// Parameter step for the chordal tolerance.
    #[must_use]
    pub fn parameter_step(&self) -> f64 {
        2.0 * (1.0 - self.tolerance / self.loop_radius()).clamp(-1.0, 1.0).acos()
    }

    fn validate(&self) -> Result<(), StrategyError> {
        let positive: [(&'static str, f64, &'static str); 5] = [
            ("diameter", self.diameter, "give the cutter diameter in mm (> 0)"),
            ("step", self.step, "give the advance per loop in mm (> 0), typically 5 to 15 % of the diameter"),
            ("tolerance", self.tolerance, "give the chordal tolerance in mm (> 0), e.g. 0.01"),
            ("feed", self.feed, "give the cutting feed in mm/min (> 0)"),
            ("clearance", self.clearance, "give a clearance height in mm (> 0)"),
        ];
        for (name, value, fix) in positive {
            if !(value.is_finite() && value > 0.0) {
                return Err(StrategyError::BadParameter { name, value, fix });
            }
        }
        if !self.depth.is_finite() {
            return Err(StrategyError::BadParameter { name: "depth", value: self.depth, fix: "give a finite Z" });
        }
        if !(self.width.is_finite() && self.width > self.diameter) {
            return Err(StrategyError::BadParameter {
                name: "width",
                value: self.width,
                fix: "the slot must be wider than the cutter (a slot as wide as the cutter is a straight cut)",
            });
        }
        let r = self.loop_radius();
        if self.advance_per_radian() >= r {
            return Err(StrategyError::BadParameter {
                name: "step",
                value: self.step,
                fix: "the advance per loop must be below 2 pi (W - D) / 2 so the path loops; lower it",
            });
        }
        if self.tolerance >= r {
            return Err(StrategyError::BadParameter {
                name: "tolerance",
                value: self.tolerance,
                fix: "the chordal tolerance must be well below the loop radius (W - D) / 2",
            });
        }
        Ok(())
    }
}

/// The trochoidal toolpath of a slot along `guide` (tool-centre line, XY; its Z is
/// ignored): rapid above the first loop point, plunge to `depth`, the loops, then a
/// retract. Loops cover the whole guide; the last loop ends at the guide's end.
///
/// # Errors
/// [`StrategyError::BadParameter`] naming the parameter: non-positive sizes, a slot not
/// wider than the cutter, an advance too large to loop, a guide shorter than one step
/// or with fewer than two points.
pub fn trochoid_slot(guide: &[Point3], params: &TrochoidParams) -> Result<Toolpath, StrategyError> {
    params.validate()?;
    let mut lengths = vec![0.0];
    for w in guide.windows(2) {
        let d = Vec3::new(w[1].x - w[0].x, w[1].y - w[0].y, 0.0).norm();
        if !d.is_finite() {
            return Err(StrategyError::BadParameter { name: "guide", value: d, fix: "give finite guide points" });
        }
        lengths.push(lengths[lengths.len() - 1] + d);
    }
    let total = lengths[lengths.len() - 1];
    if guide.len() < 2 || total < params.step {
        return Err(StrategyError::BadParameter {
            name: "guide",
            value: total,
            fix: "give a guide of at least two points and longer than one advance per loop",
        });
    }
    let centre = |s: f64| -> Point3 {
        let k = lengths.partition_point(|&l| l <= s).clamp(1, guide.len() - 1);
        let (a, b) = (guide[k - 1], guide[k]);
        let span = lengths[k] - lengths[k - 1];
        let t = if span > 0.0 { ((s - lengths[k - 1]) / span).clamp(0.0, 1.0) } else { 0.0 };
        Point3::new(a.x + t * (b.x - a.x), a.y + t * (b.y - a.y), params.depth)
    };
    let r = params.loop_radius();
    let v = params.advance_per_radian();
    let sign = if params.clockwise { -1.0 } else { 1.0 };
    let t_end = total / v;
    // Whole steps, shortened uniformly so the last point lands on the guide's end.
    let n = (t_end / params.parameter_step()).ceil().max(1.0);
    if n > MAX_POINTS {
        return Err(StrategyError::BadParameter {
            name: "tolerance",
            value: params.tolerance,
            fix: "this guide and tolerance need more than 50 million points; raise the tolerance or split the slot",
        });
    }
    let dt = t_end / n;
    let at = |t: f64| {
        let c = centre(v * t);
        Point3::new(c.x + r * t.cos(), c.y + sign * r * t.sin(), params.depth)
    };
    let top = guide.iter().map(|p| p.z).fold(params.depth, f64::max) + params.clearance;
    let mut path = Toolpath::new(params.feed);
    let first = at(0.0);
    path.push(Move::new(MoveKind::Rapid, Point3::new(first.x, first.y, top)));
    path.push(Move::new(MoveKind::Plunge, first));
    // n is a whole number of steps below 2^53 for any guide that fits in memory.
    let steps = n as u64;
    for i in 1..=steps {
        path.push(Move::new(MoveKind::Feed, at(i as f64 * dt)));
    }
    let last = at(t_end);
    path.push(Move::new(MoveKind::Retract, Point3::new(last.x, last.y, top)));
    Ok(path)
}
