//! Cutter locations for network plans: the fast planner's passes turned into a
//! toolpath a machine can run (issue 3: G-code from the planner that meets the
//! 50 ms planning budget).
//!
//! The network planner places planes and passes as **contact** polylines on the
//! surface. A contact point `P` with unit normal `n` (`n_z > 0`) is touched by a
//! vertical cutter of radius `R` and corner radius `r` (ball: `r = R`; flat:
//! `r = 0`) whose tip lies at `P + r n + (R - r) h - r z`, `h` the unit horizontal
//! part of `n` (zero when `n` is vertical). Only the XY of that location is
//! kept: the height is the **drop-cutter** height there, so every cutter
//! location touches the part and none is below it, wherever the surface's other
//! points are (a tangent placement alone can gouge a concave neighbourhood).
//! Between two locations a move is split at its XY midpoint, dropped again,
//! while the midpoint is farther than the sampling share of the path tolerance
//! from the chord (as the drop-cutter planner samples its passes); collinear
//! points are then merged within the simplification share. A location where
//! the cutter touches nothing (off the part) ends the pass there.
//!
//! Passes run in the plan's machining order (zigzag within a zone). Two passes
//! of a zone are joined along the straight XY segment between them by its
//! drop-cutter points when the cutter rests on the part all along it; otherwise,
//! and between zones (the [`super::TransitionModel::RetractTraverse`] model the
//! optimiser times), the cutter retracts to the clearance height, rapids and
//! plunges.
//!
//! The spacing of the passes is the network's (the circle model at the contact
//! points); this module measures no scallop: the stock simulation
//! (`scallop-sim`) verifies the program.

use rayon::prelude::*;
use scallop_cutter::{ClPoint, Contact, Cutter, CutterShape, drop_cutter, drop_path};
use scallop_geom::{Point2, Point3, Tolerances, Vec3};
use scallop_mesh::MeshIndex;
use scallop_toolpath::{Move, MoveKind, Toolpath, simplify};

use super::{Network, ZonePlan};
use scallop_strategy::{FinishingParams, StrategyError, tol};

/// A toolpath made from network plans, with what it took.
#[derive(Debug, Clone, PartialEq)]
pub struct NetworkToolpath {
    /// The moves (part frame).
    pub toolpath: Toolpath,
    /// Cutting passes written.
    pub passes: usize,
    /// Links along the part between passes.
    pub links: usize,
    /// Retract, rapid, plunge sequences between passes and zones.
    pub retracts: usize,
    /// Drop-cutter queries made.
    pub drops: usize,
}

struct Dropper<'a> {
    cutter: &'a Cutter,
    index: &'a MeshIndex,
    floor: f64,
    sample_tol: f64,
    min_step: f64,
    drops: usize,
}

impl Dropper<'_> {
    fn drop(&mut self, xy: Point2) -> ClPoint {
        self.drops += 1;
        drop_cutter(self.cutter, self.index, xy, self.floor)
    }

    /// As [`Dropper::refine`] with the first midpoint's location already dropped.
    fn refine_with(&mut self, a: &ClPoint, b: &ClPoint, mid: &ClPoint, out: &mut Vec<Point3>) -> Option<()> {
        let (pa, pb) = (Point2::new(a.tip.x, a.tip.y), Point2::new(b.tip.x, b.tip.y));
        if (pb - pa).norm() > self.min_step {
            if matches!(mid.contact, Contact::Floor) {
                return None;
            }
            if distance_to_segment(&mid.tip, &a.tip, &b.tip) > self.sample_tol {
                self.refine(a, mid, out)?;
                return self.refine(mid, b, out);
            }
        }
        out.push(b.tip);
        Some(())
    }

    /// Appends the locations after `a` up to `b`, splitting while the XY
    /// midpoint's location is off the chord; `None` when the cutter touches
    /// nothing at a midpoint.
    fn refine(&mut self, a: &ClPoint, b: &ClPoint, out: &mut Vec<Point3>) -> Option<()> {
        let (pa, pb) = (Point2::new(a.tip.x, a.tip.y), Point2::new(b.tip.x, b.tip.y));
        if (pb - pa).norm() > self.min_step {
            let mid = self.drop(Point2::from((pa.coords + pb.coords) * 0.5));
            if matches!(mid.contact, Contact::Floor) {
                return None;
            }
            if distance_to_segment(&mid.tip, &a.tip, &b.tip) > self.sample_tol {
                self.refine(a, &mid, out)?;
                return self.refine(&mid, b, out);
            }
        }
        out.push(b.tip);
        Some(())
    }
}

fn distance_to_segment(p: &Point3, a: &Point3, b: &Point3) -> f64 {
    let ab = b - a;
    let len2 = ab.norm_squared();
    let ap = p - a;
    let t = if len2 > 0.0 { (ap.dot(&ab) / len2).clamp(0.0, 1.0) } else { 0.0 };
    (ap - ab * t).norm()
}

/// The XY of the cutter location that touches contact point `p` with unit
/// normal `n` (see the module docs).
fn location_xy(shape: &CutterShape, p: &Point3, n: &Vec3) -> Point2 {
    let tip = p + scallop_strategy::contact_to_tip(shape, n);
    Point2::new(tip.x, tip.y)
}

/// Cutter locations of the passes of `plans` (planned on `network` without an
/// orientation) on the part indexed by `index`, joined into one toolpath (see
/// the module docs). `params` gives the feed, plunge feed, clearance, pattern
/// is zigzag (the network's order); `tolerances.path` is shared as in
/// [`scallop_strategy::plan_finishing`].
///
/// # Errors
/// - [`StrategyError::Unsupported`]: a cone cutter, or plans made on an
///   oriented (3+2) network;
/// - [`StrategyError::BadParameter`]: `tolerances.path` or `params` out of range;
/// - [`StrategyError::EmptyRegion`]: no cutter location touches the part.
pub fn network_toolpath(
    network: &Network,
    plans: &[ZonePlan],
    index: &MeshIndex,
    cutter: &Cutter,
    params: &FinishingParams,
    tolerances: &Tolerances,
) -> Result<NetworkToolpath, StrategyError> {
    params.validate()?;
    if !(tolerances.path.is_finite() && tolerances.path > 0.0) {
        return Err(StrategyError::BadParameter {
            name: "tolerances.path",
            value: tolerances.path,
            fix: "give a positive chordal tolerance in mm (e.g. 0.01)",
        });
    }
    let shape = *cutter.shape();
    if matches!(shape, CutterShape::Cone { .. }) {
        return Err(StrategyError::Unsupported { shape: "cone" });
    }
    if network.orientation().is_some() || plans.iter().any(|p| p.orientation.is_some()) {
        return Err(StrategyError::Unsupported { shape: "an oriented (3+2) network plan" });
    }
    let bounds = index.bounds();
    let mut dropper = Dropper {
        cutter,
        index,
        floor: bounds.min.z - bounds.diagonal() - 1.0,
        sample_tol: tol::SAMPLING_SHARE * tolerances.path,
        min_step: params.max_step * tol::MIN_STEP_FRACTION,
        drops: 0,
    };
    let simplify_tol = tol::SIMPLIFY_SHARE * tolerances.path;

    // Every pass of every zone, in machining order, as runs of cutter locations.
    let mut zones: Vec<Vec<Vec<Point3>>> = Vec::with_capacity(plans.len());
    for plan in plans {
        let mut runs = Vec::new();
        for (pass, backwards) in plan.machining_order() {
            let order: Vec<usize> =
                if backwards { (0..pass.points.len()).rev().collect() } else { (0..pass.points.len()).collect() };
            let xys: Vec<Point2> = order
                .iter()
                .map(|&i| {
                    let [u, v] = pass.params[i];
                    location_xy(&shape, &pass.points[i], &network.normal_at(u, v))
                })
                .collect();
            let cls = drop_path(cutter, index, &xys, dropper.floor);
            // The chord midpoints in one batch too; deeper splits one by one (rare).
            let mids: Vec<Point2> = cls
                .windows(2)
                .map(|w| Point2::new(0.5 * (w[0].tip.x + w[1].tip.x), 0.5 * (w[0].tip.y + w[1].tip.y)))
                .collect();
            let mid_cls = drop_path(cutter, index, &mids, dropper.floor);
            dropper.drops += cls.len() + mids.len();
            let mut run: Vec<Point3> = Vec::new();
            for (k, cl) in cls.iter().enumerate() {
                if matches!(cl.contact, Contact::Floor) {
                    flush(&mut runs, &mut run, simplify_tol);
                    continue;
                }
                let previous = if k > 0 && !run.is_empty() { Some(&cls[k - 1]) } else { None };
                match previous {
                    None => run.push(cl.tip),
                    Some(a) => {
                        if dropper.refine_with(a, cl, &mid_cls[k - 1], &mut run).is_none() {
                            flush(&mut runs, &mut run, simplify_tol);
                            run.push(cl.tip);
                        }
                    }
                }
            }
            flush(&mut runs, &mut run, simplify_tol);
        }
        zones.push(runs);
    }
    if zones.iter().all(Vec::is_empty) {
        return Err(StrategyError::EmptyRegion {
            direction_deg: plans.first().map_or(0.0, |p| p.direction.to_degrees()),
        });
    }

    let mut path = Toolpath::new(params.machine.feed * 60.0);
    path.plunge_feed = params.plunge_feed * 60.0;
    let clear = bounds.max.z + params.clearance;
    let (mut passes, mut links, mut retracts) = (0, 0, 0);
    let mut previous: Option<Point3> = None;
    for runs in &zones {
        for (i, run) in runs.iter().enumerate() {
            let (Some(start), Some(end)) = (run.first(), run.last()) else { continue };
            passes += 1;
            let linked = match previous {
                Some(from) if i > 0 => link(&mut dropper, &from, start, simplify_tol, params.max_step),
                _ => None,
            };
            match (previous, linked) {
                (Some(_), Some(points)) => {
                    links += 1;
                    for p in points {
                        path.push(Move::new(MoveKind::Link, p));
                    }
                }
                (Some(from), None) => {
                    retracts += 1;
                    path.push(Move::new(MoveKind::Retract, Point3::new(from.x, from.y, clear)));
                    path.push(Move::new(MoveKind::Rapid, Point3::new(start.x, start.y, clear)));
                    path.push(Move::new(MoveKind::Plunge, *start));
                }
                (None, _) => {
                    path.push(Move::new(MoveKind::Rapid, Point3::new(start.x, start.y, clear)));
                    path.push(Move::new(MoveKind::Plunge, *start));
                }
            }
            for p in &run[1..] {
                path.push(Move::new(MoveKind::Feed, *p));
            }
            previous = Some(*end);
        }
    }
    if let Some(end) = previous {
        path.push(Move::new(MoveKind::Retract, Point3::new(end.x, end.y, clear)));
    }
    Ok(NetworkToolpath { toolpath: path, passes, links, retracts, drops: dropper.drops })
}

/// Ends the current run: kept when it has a move, simplified.
fn flush(runs: &mut Vec<Vec<Point3>>, run: &mut Vec<Point3>, simplify_tol: f64) {
    if run.len() >= 2 {
        let kept = simplify(run, simplify_tol);
        runs.push(kept.iter().map(|&i| run[i]).collect());
    }
    run.clear();
}

/// The cutter locations after `a` up to `b` along the straight XY segment
/// between them, or `None` when the cutter would touch nothing somewhere.
fn link(dropper: &mut Dropper<'_>, a: &Point3, b: &Point3, simplify_tol: f64, max_step: f64) -> Option<Vec<Point3>> {
    let (pa, pb) = (Point2::new(a.x, a.y), Point2::new(b.x, b.y));
    let len = (pb - pa).norm();
    let steps = (len / max_step).ceil().max(1.0);
    // INVARIANT: len / max_step is finite (max_step > 0 validated).
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let n = steps as usize;
    let xys: Vec<Point2> = (0..=n).map(|k| pa + (pb - pa) * (k as f64 / steps)).collect();
    let cls: Vec<ClPoint> =
        xys.par_iter().map(|&p| drop_cutter(dropper.cutter, dropper.index, p, dropper.floor)).collect();
    dropper.drops += cls.len();
    if cls.iter().any(|c| matches!(c.contact, Contact::Floor)) {
        return None;
    }
    let mut points = vec![cls[0].tip];
    for w in cls.windows(2) {
        dropper.refine(&w[0], &w[1], &mut points)?;
    }
    // The ends are the pass ends (same XY, same drop): keep them exact.
    if let Some(first) = points.first_mut() {
        *first = *a;
    }
    if let Some(last) = points.last_mut() {
        *last = *b;
    }
    let kept = simplify(&points, simplify_tol);
    Some(kept.iter().skip(1).map(|&i| points[i]).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use scallop_mesh::TriMesh;

    /// On an inclined plane the drop-cutter location at `location_xy` touches the
    /// plane exactly at the contact point, for every shape and slope direction.
    #[test]
    fn the_location_touches_the_contact_point() {
        for (slope_deg, azimuth_deg) in [(20.0f64, 0.0f64), (35.0, 120.0), (60.0, 250.0), (0.0, 0.0)] {
            let (s, a) = (slope_deg.to_radians(), azimuth_deg.to_radians());
            // z = tan(s) (x cos a + y sin a): rising along azimuth a.
            let z = |x: f64, y: f64| s.tan() * (x * a.cos() + y * a.sin());
            let p = |x: f64, y: f64| Point3::new(x, y, z(x, y));
            let (mesh, _) = TriMesh::from_soup(&[
                [p(-40., -40.), p(40., -40.), p(40., 40.)],
                [p(-40., -40.), p(40., 40.), p(-40., 40.)],
            ])
            .unwrap_or_else(|e| panic!("{e}"));
            let index = MeshIndex::build(&mesh);
            let n = Vec3::new(-s.sin() * a.cos(), -s.sin() * a.sin(), s.cos());
            let contact = p(1.5, -2.0);
            for shape in [
                CutterShape::Ball { radius: 4.0 },
                CutterShape::Bull { radius: 5.0, corner: 2.0 },
                CutterShape::Flat { radius: 3.0 },
            ] {
                if matches!(shape, CutterShape::Flat { .. }) && slope_deg == 0.0 {
                    continue; // a flat bottom touches a level plane everywhere
                }
                let cutter = Cutter::new(shape, 20.0).unwrap_or_else(|e| panic!("{e}"));
                let cl = drop_cutter(&cutter, &index, location_xy(&shape, &contact, &n), -100.0);
                let touched = match cl.contact {
                    Contact::Facet { point, .. } | Contact::Edge { point, .. } | Contact::Vertex { point, .. } => point,
                    Contact::Floor => panic!("no contact"),
                };
                if slope_deg == 0.0 {
                    // Level: the tip (ball: the lowest point) rests at the contact.
                    assert!((cl.tip - contact).norm() < 1e-9, "{shape:?}: tip {:?}", cl.tip);
                } else {
                    assert!(
                        (touched - contact).norm() < 1e-9,
                        "{shape:?} slope {slope_deg} az {azimuth_deg}: touched {touched:?}"
                    );
                }
            }
        }
    }
}
