//! The 3-axis baselines of 5-axis roughing on the same part, tool and
//! cutting data (Jousselin 2020, Ch. 1 §2 and Ch. 2 §4, runs 2 and 3 of the
//! test pocket; docs/rough5.md, "Baselines"):
//!
//! - [`plan_zlevel`]: z-level roughing in one setup, the tool axis +Z: the
//!   levels and tool-centre regions of `scallop-rough` on the pocket's bottom
//!   and flanks (every a_p from the stock top plus a level on each flat
//!   floor, the cutter grown by the allowances), each region also kept inside
//!   the pocket's opening shrunk by the tool radius and the flank allowance
//!   (the tool passes through the opening; the rest of the block's top is not
//!   a face of the pocket), cleared by contour-parallel offsets;
//! - [`plan_three_plus_two`]: that program, then rest roughing in further
//!   fixed orientations chosen from the part ([`setup_axes`]: one per group
//!   of undercut flanks, the axis along the flanks' mean upward tangent plus
//!   a margin, within the machine's tilt): the same levels and regions in the
//!   setup's frame, cut down to the centres that reach material the earlier
//!   setups left (the in-process tri-dexel stock seen along the setup's axis,
//!   [`scallop_rough::limit_to_material`]).
//!
//! Every setup's passes are written in the part frame as straight moves with
//! the setup's fixed tool axis, so they are proven, posted and timed as the
//! 5-axis programs are.

use rayon::prelude::*;
use scallop_contour::Region;
use scallop_cutter::Cutter;
use scallop_geom::{Aabb3, Point3, Vec3};
use scallop_mesh::{MeshIndex, TriMesh};
use scallop_rough::{Level, MaterialMap, Motion, Pattern, RoughSettings, level_heights, level_regions, plan_levels};
use scallop_sim::{DexelOptions, DexelPart, DexelStock, ToolMove};
use scallop_toolpath::{Move, Toolpath};

use crate::{Rough5Error, tol};

/// The pocket as the baselines see it.
#[derive(Debug, Clone, Copy)]
pub struct Pocket<'a> {
    /// The faces the tool must not cut into: the bottom and the flanks.
    pub surface: &'a TriMesh,
    /// The pocket's opening in the stock top (the crossable top faces).
    pub opening: &'a TriMesh,
    /// The flanks alone, outward normals (out of the volume to remove): the
    /// undercuts that choose the 3+2 setups.
    pub flanks: &'a TriMesh,
    /// The volume to remove (closed, outward normals).
    pub volume: &'a TriMesh,
    /// The stock block.
    pub stock: Aabb3,
    /// The blank inside the stock box when the stock is not the whole box (a
    /// turned blank: closed, outward normals), as the proof takes it
    /// ([`crate::prove_from_blank`]); `None`: the whole box.
    pub blank: Option<&'a TriMesh>,
}

/// Settings of the baselines (mm, rad, mm/min).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BaselineSettings {
    /// Axial depth of cut a_p between levels.
    pub stepdown: f64,
    /// Radial depth of cut a_e between passes.
    pub stepover: f64,
    /// Material left on the flanks.
    pub flank_allowance: f64,
    /// Material left on the bottom.
    pub bottom_allowance: f64,
    /// Cutting feed (mm/min).
    pub feed: f64,
    /// Rapid rate of the time estimate (mm/min).
    pub rapid_rate: f64,
    /// Rapids run this far above the stock (plus the tool radius), mm.
    pub clearance: f64,
    /// Largest angle of a setup's axis from +Z (the machine's tilt range).
    pub max_tilt: f64,
    /// Spacing of the tri-dexel stock the rest setups read (mm).
    pub resolution: f64,
    /// Its 5-axis sweep tolerance (mm; [`DexelOptions::axis_tolerance`]).
    pub axis_tolerance: f64,
}

/// One fixed orientation of a baseline program.
#[derive(Debug, Clone, PartialEq)]
pub struct SetupReport {
    /// The tool axis (unit, part frame).
    pub axis: Vec3,
    /// Undercut flank area that chose it (mm^2; 0 for the first setup).
    pub undercut_area: f64,
    /// Levels with something to cut.
    pub levels: usize,
    /// Closed passes.
    pub passes: usize,
    /// Links at the cutting depth.
    pub links: usize,
    /// Retract-rapid-plunge connections.
    pub retracts: usize,
    /// Helical entries.
    pub helices: usize,
    /// Moves of the setup in the program.
    pub moves: usize,
}

/// A baseline program.
#[derive(Debug, Clone)]
pub struct BaselinePlan {
    /// The program: tool tips in the part frame with their (fixed) axes.
    pub toolpath: Toolpath,
    /// The setups in cutting order.
    pub setups: Vec<SetupReport>,
    /// Time at the programmed feeds and the rapid rate (s).
    pub estimated_time: f64,
}

/// A right-handed frame whose z is a setup's tool axis.
#[derive(Debug, Clone, Copy)]
struct Frame {
    e1: Vec3,
    e2: Vec3,
    u: Vec3,
}

impl Frame {
    /// The frame of axis `u` (unit): x is +Y x u (+X for u = +Z).
    fn new(u: Vec3) -> Frame {
        let side = Vec3::y().cross(&u);
        let e1 = if side.norm() > 0.5 { side.normalize() } else { u.cross(&Vec3::x()).normalize() };
        Frame { e1, e2: u.cross(&e1), u }
    }

    fn local(&self, p: &Point3) -> Point3 {
        Point3::new(self.e1.dot(&p.coords), self.e2.dot(&p.coords), self.u.dot(&p.coords))
    }

    fn part(&self, p: &Point3) -> Point3 {
        Point3::from(self.e1 * p.x + self.e2 * p.y + self.u * p.z)
    }
}

fn check(settings: &BaselineSettings) -> Result<(), Rough5Error> {
    let s = settings;
    for (name, value) in [
        ("stepdown", s.stepdown),
        ("stepover", s.stepover),
        ("feed", s.feed),
        ("rapid_rate", s.rapid_rate),
        ("clearance", s.clearance),
        ("max_tilt", s.max_tilt),
        ("resolution", s.resolution),
        ("axis_tolerance", s.axis_tolerance),
    ] {
        if !(value.is_finite() && value > 0.0) {
            return Err(Rough5Error::BadSetting { name, value });
        }
    }
    for (name, value) in [("flank_allowance", s.flank_allowance), ("bottom_allowance", s.bottom_allowance)] {
        if !(value.is_finite() && value >= 0.0) {
            return Err(Rough5Error::BadSetting { name, value });
        }
    }
    Ok(())
}

fn rough_error(e: scallop_rough::RoughError) -> Rough5Error {
    Rough5Error::Rough(e.to_string())
}

/// `mesh` in the frame.
fn rotated(mesh: &TriMesh, frame: &Frame) -> Result<TriMesh, Rough5Error> {
    let vertices: Vec<Point3> = mesh.vertices().iter().map(|p| frame.local(p)).collect();
    let triangles: Vec<[usize; 3]> = mesh.triangles().iter().map(|t| t.map(|i| i as usize)).collect();
    TriMesh::from_indexed(&vertices, &triangles)
        .map(|m| m.0)
        .map_err(|e| Rough5Error::Rough(format!("the pocket in a setup frame: {e}")))
}

/// The box of `stock` in the frame.
fn rotated_box(stock: &Aabb3, frame: &Frame) -> Aabb3 {
    let (a, b) = (stock.min, stock.max);
    let corners = (0..8).map(|k| {
        let pick = |bit: usize, lo: f64, hi: f64| if k & bit == 0 { lo } else { hi };
        frame.local(&Point3::new(pick(1, a.x, b.x), pick(2, a.y, b.y), pick(4, a.z, b.z)))
    });
    Aabb3::from_points(corners).unwrap_or(*stock)
}

/// The opening seen along the frame's axis, shrunk by `inset`: where the
/// centre of a tool of radius `inset` (grown by the allowance) may pass.
fn opening_region(opening: &TriMesh, frame: &Frame, inset: f64) -> Region {
    let v = opening.vertices();
    let rings: Vec<Vec<[f64; 2]>> = opening
        .triangles()
        .iter()
        .map(|t| {
            t.iter()
                .map(|&i| {
                    let p = frame.local(&v[i as usize]);
                    [p.x, p.y]
                })
                .collect()
        })
        .collect();
    Region::from_polygons(&rings, false).offset(inset)
}

/// The rough settings of the baselines for `cutter`.
fn rough_settings(settings: &BaselineSettings, cutter: &Cutter) -> RoughSettings {
    RoughSettings {
        stepdown: settings.stepdown,
        stepover: (settings.stepover / (2.0 * cutter.radius())).min(0.5),
        radial_allowance: settings.flank_allowance,
        axial_allowance: settings.bottom_allowance,
        pattern: Pattern::Offset,
        direction: scallop_rough::Direction::Climb,
    }
}

/// `region` (tool centres at tip height `z` in a setup's frame) less the
/// centres where the shank or the holder would stand in the stock seen along
/// the setup's axis (`stock`: the highest material of each cell): within the
/// shank's radius of stock above the flutes (`z` + flute length), or within
/// the holder's largest radius of stock above the holder's bottom (`z` +
/// stick-out), each grown by a cell's diagonal (the stock's samples lie
/// anywhere in their cell). The shank and holder reach up from there, so a
/// cell whose material rises above those heights is met wherever it lies
/// under them.
fn clear_of_stock(region: &Region, stock: &MaterialMap, z: f64, cutter: &Cutter, tolerance: f64) -> Region {
    let [cx, cy] = stock.cell_size();
    let grow = cx.hypot(cy);
    let flutes = cutter.flute_length();
    let stick_out = flutes + cutter.shank_length();
    let holder = cutter.holder().iter().map(|s| s.bottom_radius.max(s.top_radius)).fold(0.0, f64::max);
    let mut out = region.clone();
    for (from, radius) in [(flutes, cutter.shank_radius()), (stick_out, holder)] {
        if radius <= 0.0 || out.is_empty() {
            continue;
        }
        let above = stock.above(z + from);
        if !above.is_empty() {
            out = out.difference(&above.offset(-(radius + grow)), tolerance);
        }
    }
    out
}

/// The passes of one setup in its own frame, from the in-process stock
/// `material` when given (rest roughing: `material.0` inside the volume to
/// remove, what the setup cuts; `material.1` all of it, what its shank and
/// holder must stay off, [`clear_of_stock`]).
fn plan_setup(
    pocket: &Pocket,
    cutter: &Cutter,
    frame: &Frame,
    material: Option<(&MaterialMap, &MaterialMap)>,
    settings: &BaselineSettings,
) -> Result<(Toolpath, SetupReport), Rough5Error> {
    let surface = rotated(pocket.surface, frame)?;
    let index = MeshIndex::build(&surface);
    let stock = rotated_box(&pocket.stock, frame);
    let rough = rough_settings(settings, cutter);
    let chord = tol::BASELINE_CHORD;
    let zs = level_heights(&index, &stock, &rough);
    let levels = level_regions(&index, cutter, &stock, &rough, &zs, chord).map_err(rough_error)?;
    let opening = opening_region(pocket.opening, frame, cutter.radius() + settings.flank_allowance);
    let levels: Vec<Level> = levels
        .into_par_iter()
        .map(|l| {
            let region = l.region.intersection(&opening, chord);
            let region = match material {
                Some((_, all)) if !region.is_empty() => clear_of_stock(&region, all, l.z, cutter, chord),
                _ => region,
            };
            Level { region, z: l.z }
        })
        .filter(|l| !l.region.is_empty())
        .collect();
    let motion = Motion { clearance_z: stock.max.z + settings.clearance + cutter.radius(), feed: settings.feed };
    let plan =
        plan_levels(levels, cutter, &stock, material.map(|m| m.0), &rough, &motion, chord).map_err(rough_error)?;
    let report = SetupReport {
        axis: frame.u,
        undercut_area: 0.0,
        levels: plan.levels.len(),
        passes: plan.passes,
        links: plan.links,
        retracts: plan.retracts,
        helices: plan.helices,
        moves: 0,
    };
    Ok((plan.toolpath, report))
}

/// Appends `local` (a setup's passes in its frame, XY arcs as chords) to
/// `out` in the part frame with the setup's axis; after an earlier setup,
/// the tool leaves along the old axis and comes in along the new one from
/// [`tol::SETUP_CHANGE_LIFT`] above `top`. Returns the moves added.
fn append_setup(out: &mut Toolpath, local: &Toolpath, frame: &Frame, top: f64) -> usize {
    let before = out.moves().len();
    let moves = local.moves();
    let lift = |p: Point3, u: &Vec3| p + u * ((top + tol::SETUP_CHANGE_LIFT - p.z) / u.z).max(0.0);
    if let (Some(last), Some(first)) = (out.moves().last().copied(), moves.first()) {
        let old = out.axis(before - 1);
        out.push_with_axis(Move::new(scallop_toolpath::MoveKind::Retract, lift(last.to, &old)), old);
        let start = lift(frame.part(&first.to), &frame.u);
        out.push_with_axis(Move::new(scallop_toolpath::MoveKind::Rapid, start), frame.u);
    }
    for (i, m) in moves.iter().enumerate() {
        let points = match (i.checked_sub(1), local.arc(i)) {
            (Some(j), Some(arc)) => arc.chords(&moves[j].to, &m.to, tol::BASELINE_CHORD),
            _ => vec![m.to],
        };
        for p in points {
            out.push_with_axis(Move::new(m.kind, frame.part(&p)), frame.u);
        }
    }
    out.moves().len() - before
}

/// The 3-axis z-level program in one setup, the tool axis +Z.
///
/// # Errors
/// [`Rough5Error::BadSetting`], [`Rough5Error::Rough`] (the levels and
/// regions of `scallop-rough`), [`Rough5Error::NoPass`] when nothing can be
/// cut.
pub fn plan_zlevel(pocket: &Pocket, cutter: &Cutter, settings: &BaselineSettings) -> Result<BaselinePlan, Rough5Error> {
    check(settings)?;
    let frame = Frame::new(Vec3::z());
    let (local, mut report) = plan_setup(pocket, cutter, &frame, None, settings)?;
    if local.moves().is_empty() {
        return Err(Rough5Error::NoPass { reason: "no z-level region fits the tool in the opening".into() });
    }
    let mut toolpath = Toolpath::new(settings.feed);
    report.moves = append_setup(&mut toolpath, &local, &frame, pocket.stock.max.z);
    let estimated_time = crate::plan::estimate_time(&toolpath, settings.rapid_rate);
    Ok(BaselinePlan { toolpath, setups: vec![report], estimated_time })
}

/// The axes of the rest setups, chosen from the undercut flanks: the flank
/// triangles whose outward normal rises more than [`tol::UNDERCUT_SIN`],
/// grouped by azimuth in [`tol::SETUP_SECTORS`] sectors (the first centred
/// on +X); a sector with at least [`tol::SETUP_MIN_SHARE`] of the undercut
/// area gives the axis along its flanks' area-weighted mean upward tangent
/// (the normal turned up by a right angle in its vertical plane), leaning
/// [`tol::SETUP_MARGIN`] more, at most `max_tilt` from +Z. With their
/// undercut areas, the largest first.
#[must_use]
pub fn setup_axes(flanks: &TriMesh, max_tilt: f64) -> Vec<(Vec3, f64)> {
    let sectors = tol::SETUP_SECTORS;
    let width = std::f64::consts::TAU / sectors as f64;
    let mut sums = vec![(Vec3::zeros(), 0.0); sectors];
    let v = flanks.vertices();
    for t in flanks.triangles() {
        let [a, b, c] = t.map(|i| v[i as usize]);
        let twice = (b - a).cross(&(c - a));
        let area = 0.5 * twice.norm();
        if area <= 0.0 || twice.z / twice.norm() <= tol::UNDERCUT_SIN {
            continue;
        }
        let azimuth = twice.y.atan2(twice.x).rem_euclid(std::f64::consts::TAU);
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "in [0, sectors]")]
        let k = (((azimuth + 0.5 * width) / width).floor() as usize) % sectors;
        sums[k].0 += twice * 0.5;
        sums[k].1 += area;
    }
    let total: f64 = sums.iter().map(|s| s.1).sum();
    let mut axes: Vec<(Vec3, f64)> = sums
        .iter()
        .filter(|s| total > 0.0 && s.1 >= tol::SETUP_MIN_SHARE * total)
        .filter_map(|(n, area)| {
            let n = n.try_normalize(0.0)?;
            let h = Vec3::new(n.x, n.y, 0.0).try_normalize(0.0)?;
            let tilt = (n.z.clamp(-1.0, 1.0).asin() + tol::SETUP_MARGIN).min(max_tilt);
            Some((Vec3::new(-h.x * tilt.sin(), -h.y * tilt.sin(), tilt.cos()), *area))
        })
        .collect();
    axes.sort_by(|a, b| b.1.total_cmp(&a.1));
    axes
}

/// The sorted pieces common to two sorted disjoint interval lists.
fn common(a: &[[f64; 2]], b: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let mut out = Vec::new();
    for x in a {
        for y in b {
            let (lo, hi) = (x[0].max(y[0]), x[1].min(y[1]));
            if hi > lo {
                out.push([lo, hi]);
            }
        }
    }
    out
}

/// The material of `dexels` inside the volume to remove (`part`; all of it
/// for `None`), seen along the frame's axis: the highest sample of each cell
/// of a grid over the stock's box in the frame (the Z rays' material sampled
/// every half ray spacing).
fn material_map(
    dexels: &DexelStock,
    part: Option<&DexelPart>,
    frame: &Frame,
    stock: &Aabb3,
) -> Result<MaterialMap, Rough5Error> {
    let (nu, nv) = dexels.grid(2);
    let spacing = dexels.cell_size()[0].min(dexels.cell_size()[1]);
    let cell = tol::MATERIAL_CELL_FACTOR * spacing;
    let (lo, hi) = (dexels.stock().min.z, dexels.stock().max.z);
    let sample = 0.5 * spacing;
    let points: Vec<Vec<Point3>> = (0..nv)
        .into_par_iter()
        .map(|iv| {
            let mut out = Vec::new();
            for iu in 0..nu {
                let o = dexels.ray_origin(2, iu, iv);
                let pocket: Vec<[f64; 2]> = match part {
                    Some(part) => part
                        .intervals(&o, 2)
                        .iter()
                        .map(|s| [s.0.max(lo), s.1.min(hi)])
                        .filter(|s| s[1] > s[0])
                        .collect(),
                    None => vec![[lo, hi]],
                };
                for [a, b] in common(&dexels.intervals(2, iu, iv), &pocket) {
                    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "short positive span")]
                    let n = ((b - a) / sample).ceil().max(1.0) as usize;
                    out.extend((0..=n).map(|k| frame.local(&Point3::new(o.x, o.y, a + (b - a) * k as f64 / n as f64))));
                }
            }
            out
        })
        .collect();
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "box of the stock over a cell")]
    let (nx, ny) = (
        ((stock.max.x - stock.min.x) / cell).ceil().max(1.0) as usize,
        ((stock.max.y - stock.min.y) / cell).ceil().max(1.0) as usize,
    );
    let mut tops = vec![f64::NEG_INFINITY; nx * ny];
    for p in points.iter().flatten() {
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "clamped to the grid")]
        let (i, j) = (
            (((p.x - stock.min.x) / cell).floor().max(0.0) as usize).min(nx - 1),
            (((p.y - stock.min.y) / cell).floor().max(0.0) as usize).min(ny - 1),
        );
        tops[j * nx + i] = tops[j * nx + i].max(p.z);
    }
    MaterialMap::new([stock.min.x, stock.min.y], [cell, cell], nx, ny, tops).map_err(rough_error)
}

/// Cuts `path` on `dexels` (collisions as errors).
fn cut(
    dexels: &mut DexelStock,
    cutter: &Cutter,
    path: &Toolpath,
    settings: &BaselineSettings,
) -> Result<(), Rough5Error> {
    let sim = |e: scallop_sim::SimError| Rough5Error::Simulation(e.to_string());
    let options = DexelOptions { axis_tolerance: settings.axis_tolerance, check_collisions: true, max_stick_out: None };
    let report = dexels.cut(cutter, &ToolMove::from_toolpath(path), &options).map_err(sim)?;
    report.check().map_err(sim)
}

/// The z-level program, then rest roughing in the setups of
/// [`setup_axes`], each planned on the in-process tri-dexel stock the
/// earlier setups left (see the module documentation). A setup that finds
/// nothing to cut is left out.
///
/// # Errors
/// As [`plan_zlevel`]; [`Rough5Error::Simulation`] when a setup is unsafe on
/// the in-process stock.
pub fn plan_three_plus_two(
    pocket: &Pocket,
    cutter: &Cutter,
    settings: &BaselineSettings,
) -> Result<BaselinePlan, Rough5Error> {
    let mut plan = plan_zlevel(pocket, cutter, settings)?;
    let sim = |e: scallop_sim::SimError| Rough5Error::Simulation(e.to_string());
    // The in-process stock starts as the proof's does: the blank, not its box
    // (the box's material around a turned blank is not there to collide with).
    let blank = pocket.blank.map(DexelPart::new);
    let mut dexels = match &blank {
        Some(b) => DexelStock::from_solid(pocket.stock, settings.resolution, b),
        None => DexelStock::new(pocket.stock, settings.resolution),
    }
    .map_err(sim)?;
    cut(&mut dexels, cutter, &plan.toolpath, settings)?;
    let part = DexelPart::new(pocket.volume);
    for (axis, area) in setup_axes(pocket.flanks, settings.max_tilt) {
        let frame = Frame::new(axis);
        let bounds = rotated_box(&pocket.stock, &frame);
        let material = material_map(&dexels, Some(&part), &frame, &bounds)?;
        let all = material_map(&dexels, None, &frame, &bounds)?;
        let (local, mut report) = plan_setup(pocket, cutter, &frame, Some((&material, &all)), settings)?;
        if local.moves().is_empty() {
            continue;
        }
        let mut alone = Toolpath::new(settings.feed);
        append_setup(&mut alone, &local, &frame, pocket.stock.max.z);
        cut(&mut dexels, cutter, &alone, settings)?;
        report.undercut_area = area;
        report.moves = append_setup(&mut plan.toolpath, &local, &frame, pocket.stock.max.z);
        plan.setups.push(report);
    }
    plan.estimated_time = crate::plan::estimate_time(&plan.toolpath, settings.rapid_rate);
    Ok(plan)
}
