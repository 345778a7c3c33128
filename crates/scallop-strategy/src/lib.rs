//! Finishing strategies for scallop (finishing.md chapters 5 to 7): parallel
//! planes over a part with a **guaranteed scallop height**, links, an
//! independent scallop measurement, and the machining time from jerk-limited
//! kinematics.
//!
//! [`plan_finishing`] takes the part as a [`MeshIndex`] (a mesh, or the
//! tessellation of parametric surfaces made by `scallop_engine::prepare_part`),
//! a ball, flat or bull-nose [`Cutter`], the machining decisions
//! ([`FinishingParams`]) and the [`Tolerances`], and returns a [`Planned`]: the
//! [`Toolpath`], the planes and their passes, the verified scallop
//! ([`ScallopReport`]) and a serialisable [`Report`].
//!
//! [`network`] is the specification's fast method on one parametric patch
//! (finishing.md 6.3 to 6.5, 7.4): contact passes on the isoparametric network,
//! zones from clustering labels, 3+2 orientations, zone and surface times; the
//! optimiser's black box. It drops no cutter and writes no toolpath.
//!
//! ```
//! use scallop_analysis::MachineLimits;
//! use scallop_cutter::{Cutter, CutterShape};
//! use scallop_geom::{Point3, Tolerances};
//! use scallop_mesh::{MeshIndex, TriMesh};
//! use scallop_strategy::{plan_finishing, Boundary, FinishingParams, Pattern};
//!
//! // A 20 x 10 mm plane tilted 30 degrees about Y.
//! let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
//! let p = |x: f64, y: f64| Point3::new(x * c, y, x * s);
//! let (mesh, _) = TriMesh::from_soup(&[[p(0., 0.), p(10., 0.), p(0., 20.)], [p(10., 0.), p(10., 20.), p(0., 20.)]]).unwrap();
//! let index = MeshIndex::build(&mesh);
//! let cutter = Cutter::new(CutterShape::Bull { radius: 5.0, corner: 2.0 }, 20.0).unwrap();
//! let params = FinishingParams {
//!     direction: 0.0,                      // passes along X: the steepest slope
//!     pattern: Pattern::Zigzag,
//!     scallop_height: 0.01,
//!     boundary: Boundary::ContactInside,
//!     max_step: 1.0,
//!     clearance: 5.0,
//!     machine: MachineLimits::default(),   // V = 5 m/min, A = 6 m/s^2, J = 40 m/s^3
//!     plunge_feed: 20.0,
//!     rapid_rate: 500.0,
//!     sharp_corner: 30f64.to_radians(),
//!     blend_tolerance: 0.01,
//! };
//! let planned = plan_finishing(&index, &cutter, &params, &Tolerances { path: 0.01, gouge: 0.0 }).unwrap();
//! assert!(planned.report.max_scallop_mm <= 0.01);
//! assert!(planned.report.passes > 10);
//! assert!(planned.report.machining_time_lookahead_s < planned.report.machining_time_s);
//! ```
//!
//! # Strategy
//! - **Region.** A cutter location belongs to the region when its contact lies on
//!   the part away from the part's open boundary ([`Boundary::ContactInside`]): a
//!   cutter riding on the part's edge, or touching nothing, has left it. The
//!   contact points then sweep the surface up to its edges, so pass lengths are
//!   the surface's (the analytic models of finishing.md 8).
//! - **Zones.** [`plan_zone_finishing`] adds a [`ZoneRegion`]: a cutter location
//!   also needs its contact in one zone of a per-triangle labelling of the mesh,
//!   dilated by a margin (facet contacts by their triangle, edge and vertex
//!   contacts by any triangle on that edge or vertex). Passes split where their
//!   contact leaves the dilated zone, and the plane range is the dilated zone's.
//!   Pass ends then lie inside the part: the scallop is measured only at
//!   sections at least the cutter radius from both passes' ends (nearer, the
//!   envelope lacks the cutter locations beyond the end);
//!   the margin makes each zone finish itself up to its border (see
//!   [`ZoneRegion`]), and the whole program's stock simulation checks it
//!   (`scallop_engine::finish_zones`).
//! - **Passes.** Plane `k` is the vertical plane `m . p = d_k`, `m` normal to the
//!   feed direction `f`. Along it the cutter is dropped (exact drop-cutter) on a
//!   uniform grid of step `max_step` (in parallel), then a step is bisected while
//!   the CL midpoint lies farther than `SAMPLING_SHARE * path` above or below the
//!   chord (vertically: gouges are heights, and on a steep pass the vertical gap
//!   is the perpendicular one over the cosine of the slope).
//!   Samples outside the region split the plane into passes (non-convex parts
//!   give several); each pass end is located by bisection to
//!   `BOUNDARY_SHARE * path`. Collinear points are merged by
//!   `scallop_toolpath::simplify_above` within `PASS_SIMPLIFY_SHARE * path` (budget in
//!   [`tol`], and at most `MERGE_SCALLOP_SHARE * sh`): one-sided and vertical, a
//!   kept chord never passes below a point it replaces; the measured scallop of a
//!   pair of planes counts the largest height of a chord above a point it
//!   replaced, since that material adds to the scallop between feed samples.
//! - **No gouge between cutter locations.** A straight move between two exact
//!   cutter locations gouges only where the CL surface rises above it (convex
//!   crests, the top of steep descents). A step (of a pass or a link) is also
//!   bisected while the CL surface at its middle or quarter points (an
//!   inflection can put the middle on the chord) lies more than
//!   `GOUGE_MIDPOINT_SHARE * SAMPLING_SHARE * path` above the chord, as OpenCAMLib's adaptive path
//!   drop-cutter (`AdaptivePathDropCutter`) subdivides; where the CL surface is
//!   concave over the step the chord is then nowhere deeper than
//!   `SAMPLING_SHARE * path` under it. A jump of the CL surface (a wall) is
//!   bisected down to a step over which an arc of the cutter's radius rises by
//!   less than that depth, then stepped over: up vertically, level, down
//!   vertically. With the one-sided merging, every feed and link move lies at
//!   most `SAMPLING_SHARE * path` below the exact drop-cutter surface (property
//!   test `tests/prop_gouge.rs`, 16 points a move, on cliffs, hemispheres and
//!   steps); a bump of the CL surface narrower than a quarter step can still
//!   fall between the checks, as with any sampling (keep `max_step` below the
//!   part's smallest feature).
//! - **Spacing rule (finishing.md 6.4, worst point).** At every CL sample of the
//!   plane: the part normal `n` at the contact, tilt `s = acos |n_z|`, horizontal
//!   feed angle `alpha` between `f` and `(n_x, n_y)`, effective radius
//!   `R_eff(s, alpha)` (Eq. 1.5 via `scallop_analysis`; ball `R`; a flat end as
//!   the torus with `r = 0`), step-over `sod = min(2 sqrt(2 sh R_eff - sh^2), sod_max)`
//!   (5.2, 5.3; for a flat end at least `sh / sin s`, its saw tooth), and the
//!   horizontal spacing `sod |c . m|`, `c = n x (m x n)` normalised (the on-surface
//!   cross-feed direction). The candidate gap is the minimum over the plane. The
//!   normal at a contact is the cutter's own normal there where that is smooth
//!   (ball; torus of a bull-nose), which equals the part normal at tangent
//!   contacts and is the normal of the envelope actually cut at edge and vertex
//!   contacts; elsewhere the contact triangle's normal.
//! - **Guarantee: the rule, then a measurement.** The circle model ignores the
//!   part's curvature across the feed and its change between planes, so the
//!   candidate next plane is planned and the real scallop between the two is
//!   *measured* ([`verify_scallop`]'s method, at every feed sample); while it
//!   exceeds `sh` the gap shrinks (`sqrt(sh / h)`, then at least 10 % per retry).
//!   On a plane the model is exact and nothing shrinks. After planning, every
//!   pair of adjacent planes is measured again ([`Planned::scallop`]); a pair over
//!   `sh` is an `Err`. The measurement shares no model with the rule, but it is
//!   the same code the planner used to accept the plane.
//! - **Rest material.** Where the cutter cannot follow the part (a hollow
//!   tighter than the cutter, the flat bottom of a bull-nose over a concave
//!   region), the residual under a cusp does not vanish at any spacing. A cusp
//!   over `sh` is therefore re-measured against a dense family of virtual passes
//!   between the two planes; what even they leave is rest material, reported in
//!   [`ScallopReport::rest_material_mm`], not counted as scallop.
//! - **Margins.** Ranges of plane offsets with passes are found by scanning at
//!   `max_step` and bisecting their edges; the first plane of a range lies half
//!   its spacing inside the edge, and the last within half its spacing of the far
//!   edge: the strips along the boundary get half a step-over, as between passes,
//!   and the pass count is `ceil(width / sod)`, the analytic count rounded up
//!   (on the spec's 56 x 28 plane: 85 passes for 84.7, 45 for 44.3).
//! - **Gaps between ranges.** Between two ranges the cutter has no interior
//!   contact (it would ride on the part's open boundary, e.g. a raised edge), yet
//!   the surface between the last plane of one range and the first of the next
//!   can stand above `sh`. The sweep then bridges the gap with planes whose passes
//!   accept any contact with the part, within the feed span of the two planes'
//!   passes widened by the cutter radius, spaced by the same measured rule; the
//!   final verification checks every pair, bridges included.
//! - **Links.** Zigzag: the next pass starts where the previous one ended, on the
//!   adjacent plane; if the cutter rests on the part all along the straight XY
//!   segment between them, the link follows its drop-cutter points (sampled and
//!   refined like a pass: on the CL surface, hence safe) as `Link` moves.
//!   Otherwise, and always for one-way: retract to the clearance height above the
//!   part's top, rapid, plunge at the plunge feed.
//! - **Time.** [`stop_to_stop_time`] (model (a), finishing.md 7, the chains between
//!   sharp corners) and [`lookahead_time`] (model (b)); see their docs. Model (b)
//!   may exceed model (a): (a) takes corners below the sharp angle at full feed,
//!   (b) slows down for every corner beyond the blending tolerance.
//!
//! # Limits
//! - Features narrower than `max_step` (along a pass or across planes) may be missed.
//! - The scallop is measured in the vertical section normal to the feed, as the
//!   vertical residual times `n_z` (the distance to the local tangent plane), at
//!   the cusp of the two envelopes (for a flat end: the largest of 33 lateral
//!   samples); sections where an envelope comes from a pass end (the end strips,
//!   an edge effect) and the strips between the boundary and the first or last
//!   plane are not measured.
//! - Heights are relative to the part's mesh (the tessellation for surfaces,
//!   within `Tolerances::TESSELLATION_SHARE * path` of the true surface).
//!
//! # Invariants
//! - Never performs I/O, never prints, never reads clocks or the environment:
//!   [`Report::planning_time_s`] is 0 and the caller fills it in.
//! - Deterministic: the output does not depend on the number of rayon threads
//!   (parallel drops and measurements are collected in order; reductions run in
//!   a fixed order).
//! - Every CL point is a drop-cutter point on the part's mesh (no gouge of the mesh).
//! - Every pair of adjacent passes is measured with scallop `<= sh` (up to a
//!   relative measurement slack of [`tol::SCALLOP_REL_SLACK`]); otherwise the
//!   result is an `Err`, never a warning.
//! - Every numeric threshold lives in [`tol`].

mod error;
mod geometry;
mod iso;
mod leads;
mod params;
mod plan;
mod region;
mod scallop;
mod steep;
mod time;
pub use scallop_geom::tol::strategy as tol;
pub mod trochoid;

pub use error::StrategyError;
pub use geometry::contact_to_tip;
pub use iso::{IsoDirection, IsoPass, IsoPlanned, IsoSurface, iso_fitted_passes, iso_scallop, plan_isoparametric};
pub use leads::{LeadFallback, LeadKind, LeadReport, apply_leads};
pub use params::{Boundary, FinishingParams, Pattern};
pub use plan::rule_spacing;
pub use region::ZoneRegion;
pub use scallop::{PairScallop, ScallopReport, verify_scallop};
pub use steep::{SteepPlanned, SteepShallow, convex_factor, crease_residual, plan_steep_shallow};
pub use time::{ClassTimes, MoveFeed, lookahead_profile, lookahead_time, stop_to_stop_time};

use scallop_cutter::Cutter;
use scallop_geom::{Point3, Tolerances};
use scallop_mesh::MeshIndex;
use scallop_toolpath::{MoveKind, Toolpath};
use serde::{Deserialize, Serialize};

/// One vertical plane of the sweep and its passes.
#[derive(Debug, Clone, PartialEq)]
pub struct Plane {
    /// Offset `d = m . p` of the plane (mm), `m = (-sin theta, cos theta)`.
    pub offset: f64,
    /// Passes: CL polylines of the tool tip in increasing feed coordinate
    /// (the toolpath may run them backwards).
    pub passes: Vec<Vec<Point3>>,
}

/// The numbers of a plan (mm, s), serialisable for `report.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Report {
    /// Stop-to-stop jerk-limited time of the cutting moves (passes and links), model (a) (s).
    pub machining_time_s: f64,
    /// Look-ahead time of the cutting moves, model (b) (s).
    pub machining_time_lookahead_s: f64,
    /// Stop-to-stop time of rapids and retracts at the rapid rate (s).
    pub rapid_time_s: f64,
    /// Stop-to-stop time of plunges at the plunge feed (s).
    pub plunge_time_s: f64,
    /// `machining_time_s + rapid_time_s + plunge_time_s` (s).
    pub total_time_s: f64,
    /// Passes plus links (mm), the thesis's path length.
    pub path_length_mm: f64,
    /// Passes only (mm).
    pub feed_length_mm: f64,
    /// Links only (mm).
    pub link_length_mm: f64,
    /// Rapids and retracts (mm).
    pub rapid_length_mm: f64,
    /// Plunges (mm).
    pub plunge_length_mm: f64,
    /// Number of passes.
    pub passes: usize,
    /// Number of planes (including planes without a pass).
    pub planes: usize,
    /// Links on the CL surface.
    pub links: usize,
    /// Retract-rapid-plunge connections.
    pub retracts: usize,
    /// Largest verified scallop (mm).
    pub max_scallop_mm: f64,
    /// Mean verified scallop (mm).
    pub mean_scallop_mm: f64,
    /// Moves of the toolpath.
    pub points: usize,
    /// Drop-cutter queries made.
    pub cl_points_dropped: usize,
    /// Planning time (s): 0 from the library (no clocks); the caller measures it.
    pub planning_time_s: f64,
    /// Planes and levels added where the stock simulation found the scallop
    /// over sh (`None`: the first plan held it; see [`Refinement`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub refinement: Option<RefinementReport>,
}

/// What a refinement added to a plan ([`Report::refinement`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct RefinementReport {
    /// Rounds of planning again.
    pub rounds: usize,
    /// Planes added.
    pub planes_added: usize,
    /// Waterline levels added.
    pub levels_added: usize,
}

impl Report {
    /// The times and lengths of `toolpath` under `params` (the stop-to-stop
    /// and look-ahead models, lengths by move kind, retracts and points); the
    /// planner's own counts (passes, planes, links, scallop, drops) are zero,
    /// for the caller to fill in.
    #[must_use]
    pub fn timed(toolpath: &Toolpath, params: &FinishingParams) -> Report {
        let a = stop_to_stop_time(toolpath, params);
        let b = lookahead_time(toolpath, params);
        let feed = toolpath.length(MoveKind::Feed);
        let link = toolpath.length(MoveKind::Link);
        Report {
            machining_time_s: a.cutting,
            machining_time_lookahead_s: b.cutting,
            rapid_time_s: a.rapid,
            plunge_time_s: a.plunge,
            total_time_s: a.total(),
            path_length_mm: feed + link,
            feed_length_mm: feed,
            link_length_mm: link,
            rapid_length_mm: toolpath.length(MoveKind::Rapid) + toolpath.length(MoveKind::Retract),
            plunge_length_mm: toolpath.length(MoveKind::Plunge),
            passes: 0,
            planes: 0,
            links: 0,
            retracts: toolpath.count(MoveKind::Retract),
            max_scallop_mm: 0.0,
            mean_scallop_mm: 0.0,
            points: toolpath.moves().len(),
            cl_points_dropped: 0,
            planning_time_s: 0.0,
            refinement: None,
        }
    }
}

/// The result of [`plan_finishing`].
#[derive(Debug, Clone, PartialEq)]
pub struct Planned {
    /// The moves.
    pub toolpath: Toolpath,
    /// The planes in sweep order with their passes.
    pub planes: Vec<Plane>,
    /// Feed coordinates `t` at which the scallop was measured.
    pub feed_samples: Vec<f64>,
    /// The verified scallop; for the shallow planes of steep-and-shallow
    /// (rest tolerated) the raw measure, rest material included
    /// (`rest_material_mm` 0), which the stock simulation replaces.
    pub scallop: ScallopReport,
    /// Times, lengths and counts.
    pub report: Report,
}

/// Plans parallel-planes finishing of the part indexed by `index` (see the crate
/// docs for the method) and verifies its scallop.
///
/// # Errors
/// - [`StrategyError::BadParameter`]: a parameter or `tol.path` out of range;
/// - [`StrategyError::ScallopTooLarge`]: `sh` not below the cutter (corner) radius;
/// - [`StrategyError::Unsupported`]: a cone cutter;
/// - [`StrategyError::EmptyRegion`]: no pass anywhere;
/// - [`StrategyError::Unreachable`]: the spacing needed for `sh` falls below
///   [`tol::MIN_SPACING`] (e.g. a flat end across a slope);
/// - [`StrategyError::ScallopExceeded`]: the verification failed (a bug).
pub fn plan_finishing(
    index: &MeshIndex,
    cutter: &Cutter,
    params: &FinishingParams,
    tol: &Tolerances,
) -> Result<Planned, StrategyError> {
    plan(index, cutter, params, tol, None, false, &[])
}

/// [`plan_finishing`] with the planes of `refine` added to the sweep's (see
/// [`Refinement`]).
///
/// # Errors
/// As [`plan_finishing`].
pub fn plan_finishing_refined(
    index: &MeshIndex,
    cutter: &Cutter,
    params: &FinishingParams,
    tol: &Tolerances,
    refine: &Refinement,
) -> Result<Planned, StrategyError> {
    plan(index, cutter, params, tol, None, false, &refine.planes)
}

/// Planes and waterline levels added to a plan where the stock simulation
/// found more than `sh` on surface the cutter reaches (docs/simulation.md,
/// "Refinement"): the planner measures the scallop between planes at its feed
/// samples and between levels at their points, and a crease or a narrow
/// feature between those samples can escape it; the simulation then names the
/// places and the engine plans again with a plane or a level between the two
/// that bracket each place.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Refinement {
    /// Plane offsets `d = m . p` to add (mm).
    pub planes: Vec<f64>,
    /// Waterline levels (tip heights, mm) to add (steep and shallow).
    pub levels: Vec<f64>,
}

impl Refinement {
    /// Whether it adds nothing.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.planes.is_empty() && self.levels.is_empty()
    }
}

/// [`plan_finishing`] restricted to one zone of a labelled part: a cutter
/// location belongs to the region when it does under `params.boundary` **and**
/// its contact lies in the dilated zone ([`ZoneRegion`]). Planes crossing a
/// non-convex zone give several passes; the plane range is the dilated zone's.
/// The verified scallop ([`Planned::scallop`]) is that of the zone's passes.
/// `index` must index the mesh the region was built on.
///
/// # Errors
/// As [`plan_finishing`]; [`StrategyError::EmptyRegion`] when no pass touches
/// the dilated zone.
pub fn plan_zone_finishing(
    index: &MeshIndex,
    cutter: &Cutter,
    params: &FinishingParams,
    tol: &Tolerances,
    region: &ZoneRegion,
) -> Result<Planned, StrategyError> {
    plan(index, cutter, params, tol, Some(region), false, &[])
}

/// Plans parallel planes (in `region` when given); with `tolerate_rest` the
/// planner keeps the spacing rule's gap where no spacing holds `sh` (a crease
/// or corner the cutter cannot reach) instead of refusing the part, and the
/// stock simulation tells rest material from scallop (steep-and-shallow
/// finishing, issue 15 item 4).
fn plan(
    index: &MeshIndex,
    cutter: &Cutter,
    params: &FinishingParams,
    tol: &Tolerances,
    region: Option<&ZoneRegion>,
    tolerate_rest: bool,
    extra: &[f64],
) -> Result<Planned, StrategyError> {
    let mut planner = plan::Planner::new(index, cutter, params, tol, region)?;
    planner.tolerate_rest = tolerate_rest;
    let planes = planner.sweep()?;
    let planes = planner.with_planes(planes, extra);
    let (toolpath, links, retracts) = planner.toolpath(&planes);
    let planes: Vec<Plane> = planes.into_iter().map(|p| p.plane).collect();
    let feed_samples = planner.feed_samples.clone();
    // With rest tolerated the measure is a report, not a proof (the stock
    // simulation proves the program): the heights are raw, rest material
    // included, without the dense-pass reference of every cusp over sh, whose
    // drops along every wall's foot cost more than the plan itself.
    let measure = scallop::Measure {
        end_margin: plan::zone_end_margin(cutter, region),
        refine: !tolerate_rest,
        ..scallop::Measure::new(index, cutter, params.direction, params.scallop_height)
    };
    let scallop = scallop::verify_measured(&measure, &planes, &feed_samples, !tolerate_rest)?;
    let report = Report {
        passes: planes.iter().map(|p| p.passes.len()).sum(),
        planes: planes.len(),
        links,
        retracts,
        max_scallop_mm: scallop.max_mm,
        mean_scallop_mm: scallop.mean_mm,
        cl_points_dropped: planner.drops,
        ..Report::timed(&toolpath, params)
    };
    Ok(Planned { toolpath, planes, feed_samples, scallop, report })
}
