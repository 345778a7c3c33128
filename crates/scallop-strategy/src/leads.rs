//! Lead-in and lead-out moves (issue 3): the cutter enters and leaves a pass
//! tangentially instead of plunging straight onto the surface.
//!
//! At every straight plunge onto the start `p0` of a pass (a `Plunge` followed by a
//! `Feed`), and at every retract from the end of a pass (a `Feed` followed by a
//! `Retract`), with `t` the unit direction of the adjacent pass move:
//! - [`LeadKind::Arc`]: a quarter circle of radius `R` in the vertical plane through
//!   `t`, tangent to the pass at `p0`, starting `R` behind and `R` above it (mirrored
//!   at the pass end); sampled so that its chords stay within the given tolerance.
//! - [`LeadKind::Ramp`]: a straight ramp of length `L` in the same vertical plane,
//!   `angle` above the pass's tangent, arriving at `p0` from behind (leaving the
//!   pass end forward).
//!
//! The plunge then goes straight down to the lead's top point (and the retract up
//! from it). **Gouge check:** the cutter is dropped (exact drop-cutter on the part's
//! mesh) under every lead sample and under the midpoint of every lead chord; a lead
//! whose tip would lie more than `gouge` below the drop-cutter height there, or whose
//! top is above the retract height, is not applied: the straight plunge (retract)
//! stays and a [`LeadFallback`] says where and why.

use scallop_cutter::{Cutter, drop_cutter};
use scallop_geom::{Point2, Point3, Vec3};
use scallop_mesh::MeshIndex;
use scallop_toolpath::{Move, MoveKind, Toolpath};
use serde::Serialize;

use crate::StrategyError;

/// Shape of the lead moves.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum LeadKind {
    /// Straight plunges and retracts.
    None,
    /// Quarter circles of `radius` (mm) in the vertical plane of the pass.
    Arc {
        /// Radius (mm, > 0).
        radius: f64,
    },
    /// Straight ramps of `length` (mm) at `angle` (rad) above the pass's tangent.
    Ramp {
        /// Length (mm, > 0).
        length: f64,
        /// Angle above the tangent (rad, 0 < angle < pi/2).
        angle: f64,
    },
}

/// A lead that was not applied.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LeadFallback {
    /// Index of the plunge or retract move (in the input toolpath).
    pub move_index: usize,
    /// `lead-in` or `lead-out`.
    pub which: &'static str,
    /// Where the pass starts or ends (mm).
    pub at: [f64; 3],
    /// Why: the gouge depth found, or the height problem.
    pub why: String,
}

/// What [`apply_leads`] did.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LeadReport {
    /// The lead shape asked for.
    pub kind: LeadKind,
    /// Leads applied (in and out).
    pub applied: usize,
    /// Leads replaced by straight plunges or retracts, with the reason.
    pub fallbacks: Vec<LeadFallback>,
}

/// Replaces straight plunges onto pass starts and retracts from pass ends by leads
/// (see the module docs). `chord_tolerance` bounds the sagitta of arc samples (mm);
/// `gouge` is the depth (mm) a lead may go below the drop-cutter height.
///
/// # Errors
/// [`StrategyError::BadParameter`] for a non-positive radius or length, an angle out of
/// `(0, pi/2)` or a non-positive chord tolerance.
pub fn apply_leads(
    path: &Toolpath,
    index: &MeshIndex,
    cutter: &Cutter,
    kind: LeadKind,
    chord_tolerance: f64,
    gouge: f64,
) -> Result<(Toolpath, LeadReport), StrategyError> {
    let bad = |name, value: f64, fix| StrategyError::BadParameter { name, value, fix };
    match kind {
        LeadKind::Arc { radius } if !(radius.is_finite() && radius > 0.0) => {
            return Err(bad("lead.radius", radius, "give the lead arc radius in mm, > 0"));
        }
        LeadKind::Ramp { length, .. } if !(length.is_finite() && length > 0.0) => {
            return Err(bad("lead.length", length, "give the ramp length in mm, > 0"));
        }
        LeadKind::Ramp { angle, .. } if !(angle > 0.0 && angle < std::f64::consts::FRAC_PI_2) => {
            return Err(bad("lead.angle", angle, "give a ramp angle between 0 and 90 degrees"));
        }
        _ => {}
    }
    if !(chord_tolerance.is_finite() && chord_tolerance > 0.0) {
        return Err(bad("tolerances.path", chord_tolerance, "give a positive path tolerance"));
    }
    let mut report = LeadReport { kind, applied: 0, fallbacks: Vec::new() };
    let moves = path.moves();
    if kind == LeadKind::None {
        return Ok((path.clone(), report));
    }
    let mut out: Vec<Move> = Vec::with_capacity(moves.len());
    let floor = index_floor(index);
    for (i, &m) in moves.iter().enumerate() {
        let prev = if i > 0 { Some(moves[i - 1]) } else { None };
        let next = moves.get(i + 1).copied();
        let lead = match (m.kind, prev, next) {
            // Lead-in: a plunge from a height onto the start of a pass.
            (MoveKind::Plunge, Some(p), Some(n)) if n.kind == MoveKind::Feed => {
                let points = lead_points(m.to, n.to - m.to, kind, chord_tolerance, false)
                    .and_then(|pts| checked(&pts, p.to.z, index, cutter, floor, gouge));
                Some(("lead-in", m.to, points))
            }
            // Lead-out: a retract from the end of a pass.
            (MoveKind::Retract, Some(p), _) if p.kind == MoveKind::Feed && i >= 2 => {
                let points = lead_points(p.to, p.to - moves[i - 2].to, kind, chord_tolerance, true)
                    .and_then(|pts| checked(&pts, m.to.z, index, cutter, floor, gouge));
                Some(("lead-out", p.to, points))
            }
            _ => None,
        };
        match lead {
            Some(("lead-in", _, Ok(pts))) => {
                // The rapid at the safe height goes above the lead's top instead of
                // above p0 (any XY is safe there), straight down to the top, then
                // along the lead onto p0.
                if let Some(last) = out.last_mut()
                    && last.kind == MoveKind::Rapid
                {
                    last.to = Point3::new(pts[0].x, pts[0].y, last.to.z);
                }
                for q in &pts {
                    out.push(Move::new(MoveKind::Plunge, *q));
                }
                report.applied += 1;
            }
            Some((_, _, Ok(pts))) => {
                // pts run from the lead's top down to the pass end: walk them
                // backwards, then retract straight up from the top.
                for q in pts.iter().rev().skip(1) {
                    out.push(Move::new(MoveKind::Plunge, *q));
                }
                out.push(Move::new(m.kind, Point3::new(pts[0].x, pts[0].y, m.to.z)));
                report.applied += 1;
            }
            Some((which, at, Err(why))) => {
                report.fallbacks.push(LeadFallback { move_index: i, which, at: at.coords.into(), why });
                out.push(m);
            }
            None => out.push(m),
        }
    }
    let mut led = Toolpath::new(path.feed);
    led.plunge_feed = path.plunge_feed;
    for m in out {
        led.push(m);
    }
    Ok((led, report))
}

/// The lowest tip height drop-cutter may return (below the part).
fn index_floor(index: &MeshIndex) -> f64 {
    index.bounds().min.z - 1.0
}

/// Lead points from the lead's top to `p0` (the pass start; for a lead-out the pass
/// end, with `dir` the direction of travel and the lead mirrored forward).
fn lead_points(p0: Point3, dir: Vec3, kind: LeadKind, chord: f64, forward: bool) -> Result<Vec<Point3>, String> {
    let t = dir.try_normalize(1e-12).ok_or_else(|| "the pass has no direction there".to_string())?;
    // `behind` points from p0 to where the lead comes from.
    let s = if forward { 1.0 } else { -1.0 };
    match kind {
        LeadKind::None => Ok(vec![p0]),
        LeadKind::Arc { radius } => {
            let up = Vec3::z() - t * t.z;
            let up = up.try_normalize(1e-9).ok_or_else(|| "a vertical pass: no vertical lead plane".to_string())?;
            let c = p0 + up * radius;
            // Sagitta r (1 - cos(d/2)) <= chord.
            let step = if radius > chord { 2.0 * (1.0 - chord / radius).acos() } else { std::f64::consts::FRAC_PI_2 };
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "a small positive count")]
            let n = ((std::f64::consts::FRAC_PI_2 / step).ceil() as usize).clamp(2, 256);
            Ok((0..=n)
                .rev()
                .map(|k| {
                    #[allow(clippy::cast_precision_loss, reason = "small counts")]
                    let phi = std::f64::consts::FRAC_PI_2 * k as f64 / n as f64;
                    c - up * (radius * phi.cos()) + t * (s * radius * phi.sin())
                })
                .collect())
        }
        LeadKind::Ramp { length, angle } => {
            let up = Vec3::z() - t * t.z;
            let up = up.try_normalize(1e-9).ok_or_else(|| "a vertical pass: no vertical lead plane".to_string())?;
            // `angle` above the pass's tangent, in its vertical plane.
            let top = p0 + (t * (s * angle.cos()) + up * angle.sin()) * length;
            Ok(vec![top, p0])
        }
    }
}

/// Checks `pts` against the part (drop-cutter under every point and chord midpoint)
/// and the height `top` of the plunge or retract.
fn checked(
    pts: &[Point3],
    top: f64,
    index: &MeshIndex,
    cutter: &Cutter,
    floor: f64,
    gouge: f64,
) -> Result<Vec<Point3>, String> {
    if pts[0].z > top {
        return Err(format!("the lead's top {:.4} mm is above the retract height {top:.4} mm", pts[0].z));
    }
    let mut samples: Vec<Point3> = pts.to_vec();
    samples.extend(pts.windows(2).map(|w| Point3::from((w[0].coords + w[1].coords) * 0.5)));
    // The pass end point itself is a CL point; skip it (it is where the lead meets the pass).
    let end = pts[pts.len() - 1];
    for p in samples {
        if (p - end).norm() == 0.0 {
            continue;
        }
        let cl = drop_cutter(cutter, index, Point2::new(p.x, p.y), floor);
        if p.z < cl.tip.z - gouge {
            return Err(format!(
                "the lead would gouge {:.4} mm at ({:.3}, {:.3}); straight plunge kept",
                cl.tip.z - p.z,
                p.x,
                p.y
            ));
        }
    }
    Ok(pts.to_vec())
}

#[cfg(test)]
#[allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]
mod tests {
    use super::*;
    use scallop_cutter::CutterShape;
    use scallop_mesh::TriMesh;

    fn plane(slope: f64) -> MeshIndex {
        let p = |x: f64, y: f64| Point3::new(x, y, slope * x);
        let (mesh, _) =
            TriMesh::from_soup(&[[p(0., 0.), p(40., 0.), p(0., 40.)], [p(40., 0.), p(40., 40.), p(0., 40.)]]).unwrap();
        MeshIndex::build(&mesh)
    }

    fn one_pass(index: &MeshIndex, cutter: &Cutter) -> Toolpath {
        let drop = |x: f64| drop_cutter(cutter, index, Point2::new(x, 20.0), -10.0).tip;
        let mut path = Toolpath::new(1000.0);
        let (a, b) = (drop(10.0), drop(30.0));
        path.push(Move::new(MoveKind::Rapid, Point3::new(a.x, a.y, 30.0)));
        path.push(Move::new(MoveKind::Plunge, a));
        for k in 1..=20 {
            path.push(Move::new(MoveKind::Feed, drop(10.0 + f64::from(k))));
        }
        path.push(Move::new(MoveKind::Retract, Point3::new(b.x, b.y, 30.0)));
        path
    }

    #[test]
    fn arc_and_ramp_leads_are_tangent_and_clear_of_the_part() {
        let index = plane(0.2);
        let cutter = Cutter::new(CutterShape::Ball { radius: 3.0 }, 20.0).unwrap();
        let path = one_pass(&index, &cutter);
        for kind in [LeadKind::Arc { radius: 2.0 }, LeadKind::Ramp { length: 3.0, angle: 10f64.to_radians() }] {
            let (led, report) = apply_leads(&path, &index, &cutter, kind, 0.001, 0.0).unwrap();
            assert_eq!(report.applied, 2, "{kind:?}: {report:?}");
            assert!(led.moves().len() > path.moves().len());
            // Every lead point lies on or above the drop-cutter height (no gouge).
            for m in led.moves().iter().filter(|m| m.kind == MoveKind::Plunge) {
                let cl = drop_cutter(&cutter, &index, Point2::new(m.to.x, m.to.y), -10.0);
                assert!(m.to.z >= cl.tip.z - 1e-9, "{kind:?}: {} below {}", m.to, cl.tip);
            }
            // The lead-in arrives along the pass: an arc's last chord within its chord
            // angle of the tangent, a ramp at its angle.
            let start = led.moves().iter().position(|m| m.kind == MoveKind::Feed).unwrap();
            let arrive = (led.moves()[start - 1].to - led.moves()[start - 2].to).normalize();
            let pass = (led.moves()[start].to - led.moves()[start - 1].to).normalize();
            let expected = if let LeadKind::Ramp { angle, .. } = kind { angle.cos() } else { 0.999 };
            assert!(arrive.dot(&pass) >= expected - 1e-9, "{kind:?}: {arrive} vs {pass}");
        }
    }

    #[test]
    fn a_lead_that_would_gouge_falls_back_with_a_diagnostic() {
        // A steep wall right behind the pass start: the lead-in cannot come from there.
        let p = |x: f64, y: f64, z: f64| Point3::new(x, y, z);
        let (mesh, _) = TriMesh::from_soup(&[
            [p(0., 0., 0.), p(40., 0., 0.), p(0., 40., 0.)],
            [p(40., 0., 0.), p(40., 40., 0.), p(0., 40., 0.)],
            [p(5., 0., 0.), p(5., 40., 0.), p(4., 0., 8.)],
            [p(5., 40., 0.), p(4., 40., 8.), p(4., 0., 8.)],
        ])
        .unwrap();
        let index = MeshIndex::build(&mesh);
        let cutter = Cutter::new(CutterShape::Ball { radius: 1.0 }, 20.0).unwrap();
        let mut path = Toolpath::new(1000.0);
        path.push(Move::new(MoveKind::Rapid, p(6.5, 20.0, 30.0)));
        path.push(Move::new(MoveKind::Plunge, p(6.5, 20.0, 0.0)));
        path.push(Move::new(MoveKind::Feed, p(20.0, 20.0, 0.0)));
        path.push(Move::new(MoveKind::Retract, p(20.0, 20.0, 30.0)));
        let (led, report) =
            apply_leads(&path, &index, &cutter, LeadKind::Ramp { length: 6.0, angle: 0.2 }, 0.001, 0.0).unwrap();
        assert_eq!(report.fallbacks.len(), 1, "{report:?}");
        assert_eq!(report.fallbacks[0].which, "lead-in");
        assert!(report.fallbacks[0].why.contains("gouge"));
        assert_eq!(led.moves()[..2], path.moves()[..2], "the straight plunge stays");
        assert_eq!(report.applied, 1, "the lead-out is clear");
    }
}
