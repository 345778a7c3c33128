//! PLAN_ZONE (finishing.md 6.5): the plane sweep with the worst-point spacing
//! and its look-ahead, zigzag order, connections and the zone's time.

use scallop_geom::Point3;

use super::passes::{PlaneCut, PlaneCutter, Workspace};
use super::spacing::ToolModel;
use super::{Margins, Network, NetworkPlane, ZoneParams, ZonePlan, Zoning};
use scallop_strategy::{StrategyError, tol};

/// Plans zone `zone` of `zoning` on `network` (the whole surface when `zoning` is
/// `None`; `zone` is then only recorded) along `params.direction` in the
/// network's frame (see the module docs of [`super`] for the method).
///
/// # Errors
/// - [`StrategyError::BadParameter`]: a parameter out of range (direction,
///   scallop height, tool radii, margins, sharp corner, machine limits);
/// - [`StrategyError::ScallopTooLarge`]: `sh` not below the (corner) radius;
/// - [`StrategyError::Unsupported`]: `Cutter::Flat` (use `Toroidal { corner: 0 }`);
/// - [`StrategyError::BadLabels`]: `zoning` made for another network resolution;
/// - [`StrategyError::EmptyZone`]: the zone has no cell or no pass;
/// - [`StrategyError::Unreachable`]: the spacing needed falls below [`tol::MIN_SPACING`].
pub fn plan_zone(
    network: &Network,
    zoning: Option<&Zoning>,
    zone: u32,
    params: &ZoneParams,
) -> Result<ZonePlan, StrategyError> {
    plan_zone_with(network, zoning, zone, params, &mut ZoneWorkspace::default())
}

/// Buffers of [`plan_zone_with`], reused from one zone to the next (their
/// sizes follow the network: one value per node, one mark per edge).
#[derive(Debug, Default)]
pub struct ZoneWorkspace(Workspace);

/// PLANE_PASSES and NEXT_SPACING (finishing.md 6.3, 6.4) of one plane `m . P =
/// offset` (`m = (-sin t, cos t, 0)`, `t = params.direction`): the passes of
/// `zone` (the whole surface without a zoning), oriented along the feed and
/// sorted by feed coordinate, and the plane's spacing. Passes shorter than
/// [`tol::MIN_PASS_LENGTH`] are left out but count for the spacing.
///
/// # Errors
/// As [`plan_zone`]; a zone without cells is [`StrategyError::EmptyZone`].
pub fn plane_passes(
    network: &Network,
    zoning: Option<&Zoning>,
    zone: u32,
    params: &ZoneParams,
    offset: f64,
) -> Result<NetworkPlane, StrategyError> {
    validate(network, zoning, params)?;
    let tool = ToolModel::new(&params.tool, params.scallop_height)?;
    let cos_sharp = params.sharp_corner.min(std::f64::consts::PI).cos();
    let mut ws = Workspace::default();
    let Some(mut cutter) =
        PlaneCutter::new(network, zoning.map(|z| (z, zone)), params.direction, cos_sharp, params.machine, &mut ws)
    else {
        return Err(StrategyError::EmptyZone { zone });
    };
    let cut = cutter.plane(offset, &tool);
    Ok(NetworkPlane { offset, spacing: cut.spacing, passes: cut.passes })
}

/// Plans every zone of `zoning` (3-axis), zone `zoning.zones()[i]` along
/// `directions[i]`, the other settings shared; the plans come in increasing
/// label, the order of [`super::surface_time`]. Buffers are shared between zones.
///
/// # Errors
/// As [`plan_zone`], plus [`StrategyError::BadParameter`] (`directions`) when
/// there is not one direction per zone.
pub fn plan_zones(
    network: &Network,
    zoning: &Zoning,
    directions: &[f64],
    params: &ZoneParams,
) -> Result<Vec<ZonePlan>, StrategyError> {
    if directions.len() != zoning.zones().len() {
        return Err(StrategyError::BadParameter {
            name: "directions",
            value: directions.len() as f64,
            fix: "give one feed direction per zone of the labelling (Zoning::zones)",
        });
    }
    let mut ws = ZoneWorkspace::default();
    zoning
        .zones()
        .iter()
        .zip(directions)
        .map(|(&zone, &direction)| {
            plan_zone_with(network, Some(zoning), zone, &ZoneParams { direction, ..*params }, &mut ws)
        })
        .collect()
}

fn validate(network: &Network, zoning: Option<&Zoning>, params: &ZoneParams) -> Result<(), StrategyError> {
    let bad = |name, value, fix| Err(StrategyError::BadParameter { name, value, fix });
    if !params.direction.is_finite() {
        return bad("direction", params.direction, "give the feed direction in radians from +X");
    }
    if !(params.sharp_corner.is_finite() && params.sharp_corner >= 0.0) {
        return bad("sharp_corner", params.sharp_corner, "give an angle in radians, e.g. 30 degrees = 0.5236");
    }
    if let Margins::Fixed { start, end } = params.margins {
        for (name, value) in [("margins.start", start), ("margins.end", end)] {
            if !(value.is_finite() && value >= 0.0) {
                return bad(name, value, "give a margin >= 0 mm");
            }
        }
    }
    if let Err(e) = params.machine.validate() {
        return bad(
            "machine",
            f64::NAN,
            match e {
                scallop_analysis::AnalysisError::BadMachine { what: "feed", .. } => "give a positive feed V (mm/s)",
                scallop_analysis::AnalysisError::BadMachine { what: "acceleration", .. } => {
                    "give a positive acceleration A (mm/s^2)"
                }
                _ => "give a positive jerk J (mm/s^3)",
            },
        );
    }
    if let Some(z) = zoning
        && network.resolution() != (z.quads_u, z.quads_v)
    {
        return Err(StrategyError::BadLabels {
            cells_u: z.labels.cells_u,
            cells_v: z.labels.cells_v,
            found: z.labels.labels.len(),
        });
    }
    Ok(())
}

/// [`plan_zone`] with reused buffers: the same plan, without allocating and
/// clearing per-node and per-edge buffers for every zone.
///
/// # Errors
/// As [`plan_zone`].
pub fn plan_zone_with(
    network: &Network,
    zoning: Option<&Zoning>,
    zone: u32,
    params: &ZoneParams,
    workspace: &mut ZoneWorkspace,
) -> Result<ZonePlan, StrategyError> {
    let ws = &mut workspace.0;
    validate(network, zoning, params)?;
    let tool = ToolModel::new(&params.tool, params.scallop_height)?;
    let cos_sharp = params.sharp_corner.min(std::f64::consts::PI).cos();
    let Some(mut cutter) =
        PlaneCutter::new(network, zoning.map(|z| (z, zone)), params.direction, cos_sharp, params.machine, ws)
    else {
        return Err(StrategyError::EmptyZone { zone });
    };
    let planes = sweep(&mut cutter, &tool, params)?;
    if planes.is_empty() {
        return Err(StrategyError::EmptyZone { zone });
    }
    let mut plan = ZonePlan {
        zone,
        direction: params.direction,
        orientation: network.orientation().copied(),
        planes,
        connections: Vec::new(),
        passes: 0,
        cut_length_mm: 0.0,
        link_length_mm: 0.0,
        time_s: 0.0,
        start: Point3::origin(),
        end: Point3::origin(),
    };
    let mut first: Option<Point3> = None;
    let mut last: Option<Point3> = None;
    let mut connections = Vec::new();
    let (mut cut, mut link, mut time, mut passes) = (0.0, 0.0, 0.0, 0);
    for (pass, backwards) in plan.machining_order() {
        let (a, b) = (pass.points[0], pass.points[pass.points.len() - 1]);
        let (start, end) = if backwards { (b, a) } else { (a, b) };
        if let Some(previous) = last {
            let l = (start - previous).norm();
            link += l;
            time += params.machine.segment_time(l);
            connections.push([previous, start]);
        }
        first.get_or_insert(start);
        last = Some(end);
        cut += pass.length;
        time += pass.time;
        passes += 1;
    }
    plan.connections = connections;
    plan.passes = passes;
    plan.cut_length_mm = cut;
    plan.link_length_mm = link;
    plan.time_s = time;
    // INVARIANT: a kept plane has at least one pass.
    plan.start = network.to_part(&first.unwrap_or_else(Point3::origin));
    plan.end = network.to_part(&last.unwrap_or_else(Point3::origin));
    Ok(plan)
}

/// The planes of the sweep in increasing offset (planes without a pass of the
/// zone are left out).
fn sweep(
    cutter: &mut PlaneCutter<'_>,
    tool: &ToolModel,
    params: &ZoneParams,
) -> Result<Vec<NetworkPlane>, StrategyError> {
    let (d_min, d_max) = cutter.range();
    let mut planes = Vec::new();
    // The last finite spacing (the spec's fallback for a plane without vertices).
    let mut delta = tool.cap();
    let (mut d, mut cut) = match params.margins {
        Margins::HalfStep => {
            // First plane half its own spacing inside: a short fixed point.
            let mut d = if d_min + 0.5 * delta < d_max { d_min + 0.5 * delta } else { 0.5 * (d_min + d_max) };
            let mut cut = cutter.plane(d, tool);
            for _ in 0..tol::FIRST_PLANE_ITERATIONS {
                if !cut.spacing.is_finite() || cut.spacing >= (d - d_min) * 2.0 * (1.0 - tol::LOOKAHEAD_REL) {
                    break;
                }
                d = d_min + 0.5 * cut.spacing;
                cut = cutter.plane(d, tool);
            }
            (d, cut)
        }
        Margins::Fixed { start, end } => {
            if d_min + start > d_max - end {
                return Ok(planes);
            }
            (d_min + start, cutter.plane(d_min + start, tool))
        }
    };
    // The spacing of the previous plane, for the trend of the look-ahead.
    let mut previous = f64::INFINITY;
    let mut first = true;
    loop {
        if cut.spacing.is_finite() {
            previous = if first { f64::INFINITY } else { delta };
            delta = cut.spacing;
        }
        first = false;
        if delta < tol::MIN_SPACING {
            return Err(unreachable(&cut, delta, params));
        }
        if !cut.passes.is_empty() {
            planes.push(NetworkPlane { offset: d, spacing: cut.spacing, passes: cut.passes });
        }
        // Where the spacing shrinks from plane to plane, the next plane's own
        // spacing is likely below `delta`: step by the extrapolated spacing
        // (at least half of `delta`) to spare the look-ahead a second plane.
        let step = if previous.is_finite() && previous > delta * (1.0 + tol::LOOKAHEAD_REL) {
            (delta - tol::LOOKAHEAD_TREND * (previous - delta)).max(0.5 * delta)
        } else {
            delta
        };
        let target = match params.margins {
            Margins::HalfStep => {
                (d + 0.5 * delta < d_max - tol::END_STRIP_REL * delta).then(|| (d + step).min(d_max - 0.5 * delta))
            }
            Margins::Fixed { end, .. } => {
                let stop = d_max - end;
                if d + delta <= stop {
                    Some(d + step)
                } else {
                    (stop - d > (0.5 + tol::END_STRIP_REL) * delta).then_some(stop)
                }
            }
        };
        let Some(target) = target else { break };
        (d, cut) = lookahead(cutter, tool, d, target - d, params)?;
    }
    Ok(planes)
}

/// The next plane at `d + gap`, moved closer while its own spacing is below
/// the gap (finishing.md 6.4 with the look-ahead \[DECISION\]).
fn lookahead(
    cutter: &mut PlaneCutter<'_>,
    tool: &ToolModel,
    d: f64,
    gap: f64,
    params: &ZoneParams,
) -> Result<(f64, PlaneCut), StrategyError> {
    let mut gap = gap;
    let mut cut = cutter.plane(d + gap, tool);
    for retry in 0..tol::MAX_LOOKAHEAD_RETRIES {
        if cut.spacing >= gap * (1.0 - tol::LOOKAHEAD_REL) {
            // Within rounding of the spacing: record the plane at the spacing
            // (its passes, cut `LOOKAHEAD_REL * gap` away, are kept), so that no
            // recorded gap exceeds a spacing.
            return Ok((d + gap.min(cut.spacing), cut));
        }
        // The fixed point of gap = spacing(d + gap), approached from above; after
        // a few plain steps each retry shrinks more (slow convergence).
        let extra = if retry < tol::LOOKAHEAD_PLAIN_RETRIES {
            0.0
        } else {
            (tol::LOOKAHEAD_SHRINK * f64::from(1u32 << (retry - tol::LOOKAHEAD_PLAIN_RETRIES).min(20))).min(0.5)
        };
        gap = cut.spacing * (1.0 - extra);
        if gap < tol::MIN_SPACING {
            return Err(unreachable(&cut, gap, params));
        }
        cut = cutter.plane(d + gap, tool);
    }
    Err(unreachable(&cut, gap, params))
}

fn unreachable(cut: &PlaneCut, spacing: f64, params: &ZoneParams) -> StrategyError {
    StrategyError::Unreachable { x: cut.worst.x, y: cut.worst.y, spacing, scallop_height: params.scallop_height }
}
