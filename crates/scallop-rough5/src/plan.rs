//! Assembly of the roughing program (module J; Jousselin 2020, Ch. 2 §1.2,
//! Ch. 4 §1; spec 5.12): levels top-down, each emptying the volume between
//! it and the level above; passes inside-out (m = 0 first), one milling mode
//! (the curves' own orientation, inside on the left: climb milling with a
//! clockwise spindle); the tool placed along its axis at every synchronised
//! pair ([`crate::Placer`]), no more than a maximum angular step between
//! neighbouring orientations; pairs whose tool body would meet a flank
//! dropped (the pass is split there); the first run of a level entered from
//! just above the level cut before ([`EntryMode`]: a helix inside a closed
//! run, from outside the stock at the level's depth, a ramp along the run,
//! a plunge only where none of them is found), later runs linked on the
//! level when the link is short, placed and collision free, else through a
//! retract along the tool axis to a safe height, a rapid, and an entry.
//!
//! Three refinements of the guide-curve program (docs/rough5.md, "Where the
//! remaining volume was"), each a setting: the passes inside a level's
//! outermost ones cut with the axis +Z wherever the vertical tool clears the
//! flanks (the tilt kept where it does not, the neighbours leaning in);
//! a pair whose tool still comes too close to a flank translated away from it
//! (the axis translation of Jousselin 2020, Ch. 3 §3, step 3) before it is
//! dropped; and the level repairs of [`LevelOptions`].

use rayon::prelude::*;
use scallop_cutter::Cutter;
use scallop_geom::{Aabb3, Point3, Vec3};
use scallop_guides::{Curve, GuideSettings};
use scallop_mesh::{MeshQuery, TriMesh};
use scallop_sim::DexelPart;
use scallop_toolpath::{Move, MoveKind, Toolpath};

use crate::air::AirSettings;
use crate::collide::BodyCheck;
use crate::correct::{correct_pairs, correct_pairs_spatial};
use crate::entry::{
    EntryCount, EntryMode, HELIX_RADII, HELIX_STARTS, HelixSettings, PathDynamics, SIDE_REACH_RADII, helix_entry,
    path_time_estimate, side_entry,
};
use crate::levels::{LevelOptions, TiltMode, level_passes_with};
use crate::orient::{OrientSettings, Orientation, optimise_pass, synchronise_with};
use crate::rest::{ROOT_REST_MIN_RUN, root_rest_pairs, swept};
use crate::sync::{SyncPoint, axis_steps, interpolate_axis, limit_angular_step, pitch_angle, synchronise};
use crate::{LevelPasses, Placement, Placer, Rough5Error, tol};

/// Settings of [`plan_rough5`] (mm, rad, mm/min).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rough5Settings {
    /// The tool-axis variant.
    pub tilt: TiltMode,
    /// Levels and curves: tool radius, flank allowance, a_p, a_e, voxel, depth.
    pub guides: GuideSettings,
    /// Material left on the bottom (mm).
    pub bottom_allowance: f64,
    /// Spacing of the synchronised pairs along a pass (mm).
    pub step: f64,
    /// Largest change of the tool axis between two CL points (rad).
    pub max_angle_step: f64,
    /// Largest change of the tool axis's azimuth about +Z between two CL
    /// points (rad): the C table of a table-table machine turns evenly.
    pub max_azimuth_step: f64,
    /// Angle of the ramp entries (rad).
    pub ramp_angle: f64,
    /// Entry height above the level cut before, and the safe height above
    /// the stock (plus the tool radius), mm.
    pub clearance: f64,
    /// Longest link kept on the level between two runs (mm).
    pub link_max: f64,
    /// Cutting feed (mm/min).
    pub feed: f64,
    /// Rapid rate of the time estimate (mm/min).
    pub rapid_rate: f64,
    /// The optimised orientation of each paired pass (Jousselin 2020, Ch. 3
    /// §2), or `None` for SPU.
    pub orientation: Option<OrientSettings>,
    /// The optimised orientation of the passes that leave the stock of the
    /// finished faces: every pass of the bottom level and each level's limit
    /// passes (its outermost ones, along the flanks); the other passes (the
    /// bulk) keep [`Self::orientation`]. `None`: one orientation for all
    /// (the per-pass weights of spec module H; Jousselin 2020, Ch. 3 §2.3).
    pub limit_orientation: Option<OrientSettings>,
    /// Whether a pair whose tool collides with a flank is first turned in its
    /// correction plane (Ch. 3 §3, step 1, [`crate::correct_planar`]) before
    /// it is dropped.
    pub correct: bool,
    /// The repairs of the levels' passes (bottom centre offsets, pairing by
    /// rank where `pair_levels` fails).
    pub levels: LevelOptions,
    /// Whether the passes inside a level's outermost ones (those along its
    /// limit curves) are cut with the axis +Z wherever the vertical tool is
    /// placed clear of the flanks: the tilt is kept where it is not, and the
    /// pairs around such a pair lean in by one angular step per pair, in its
    /// azimuth, so the rotary axes stay still on the inner loops.
    pub vertical_inside: bool,
    /// Whether the pairs of a level's limit passes (its outermost ones, along
    /// the flanks) are cut with the axis +Z where the vertical tool is placed
    /// clear of the flanks and the step it leaves between the level and the
    /// level above ([`limit_step`]) is at most
    /// [`tol::LIMIT_STEP_ALLOWANCES`] flank allowances: there the tilt
    /// removes a wedge thinner than the allowance while the C table of a
    /// table-table machine turns round every corner of the outline for it.
    /// The other pairs keep their tilt and their neighbours lean in as with
    /// [`Self::vertical_inside`] (docs/rough5.md, "Limit passes: the tilt
    /// where it pays").
    pub vertical_thin_steps: bool,
    /// Whether a pair of an offset level (not the bottom) whose tool comes
    /// closer to a flank than its radius, in the guide-curve variant, has its
    /// axis turned through a point of a limit curve of a level above (Ch. 3
    /// §3, step 2, Eq. 3.32, [`crate::correct_spatial`]) before it is
    /// translated or dropped, its neighbours leaning towards the new axis;
    /// the angular step is limited again and the pairs this inserts are
    /// corrected in turn, at most [`tol::CORRECTION_ROUNDS`] rounds (the loop
    /// of Fig. 3.34). Off in [`Self::new`]: on the three test parts it changes
    /// the remaining volume by less than 0.05 points and adds about 1 % of
    /// machine time; on the bottom level it left more (docs/rough5.md,
    /// "Collision correction").
    pub spatial: bool,
    /// Whether a pair whose tool still comes closer to a flank than its
    /// radius is translated away from the flank (Ch. 3 §3, step 3, the axis
    /// kept; at most [`TRANSLATION_MAX`]) before it is dropped, its
    /// neighbours following by [`TRANSLATION_SLOPE`] per mm along the pass.
    pub translate: bool,
    /// Whether a run is entered from the level above where its tool stands
    /// (its guide point's tool placed on the level above along the same
    /// axis, plus the clearance), not from the highest point of the level
    /// above, when that is lower ([`local_entry`]): on a level that falls
    /// along an impeller's channel the ramp from the highest point circles
    /// down through the air (docs/rough5.md, "The impeller, sixth session").
    pub local_entry: bool,
    /// Whether the tilted axes of each run are smoothed ([`smooth_axes`]):
    /// an axis that zigzags by a fraction of a degree makes the C table of a
    /// table-table machine swing back and forth by degrees at small tilts
    /// (docs/rough5.md, "Where the machine time goes").
    pub smooth_axes: bool,
    /// Whether the vertical stretches of every pass are written in long
    /// blocks ([`thin_vertical`]) and their corners rounded
    /// ([`round_corners`]): the convex corners of the inner passes by a fillet
    /// of [`tol::CORNER_FILLET_RADII`] tool radii (when a_e is at most the
    /// tool radius), the other corners within the thinning's chord
    /// (docs/rough5.md, "Corners and blocks").
    pub round_corners: bool,
    /// Whether the bottom level ends, in the guide-curve variant, with a rest
    /// pass along its limit
    /// passes, moved towards the flanks and tilted across the pass where the
    /// whole tool keeps the flank allowance and reaches nearer the flank's
    /// root than the limit pass ([`crate::rest::root_rest_pairs`]): under
    /// an overhanging flank (an impeller's blade) the bottom's limit curve
    /// keeps the vertical tool several millimetres from the root
    /// (docs/rough5.md, "Impeller hub and roots").
    pub root_rest: bool,
    /// Whether the bottom level's inner passes are cut with the tool axis
    /// along the bottom's normal where the bottom leans by more than
    /// [`bottom_normal_min_slope`] and that tool is clear of the flanks (the
    /// other pairs as with [`Self::vertical_inside`]), in the guide-curve
    /// variant: on a sloped bottom (an impeller's hub, a surface of
    /// revolution) the vertical torus stands on its corner and leaves steps
    /// about a_e tan(slope) high between passes a_e apart; along the normal
    /// its flat end lies on the bottom (docs/rough5.md, "Impeller hub and
    /// roots"). A flat bottom is cut as before.
    pub bottom_normal: bool,
    /// How the runs are entered ([`EntryMode`]; docs/rough5.md, "Entries"):
    /// a helix inside a closed pass where one fits, a side entry from outside
    /// the stock where a run starts within reach of its side, a ramp along a
    /// closed run, else a plunge.
    pub entry: EntryMode,
    /// The machine's dynamics along a path with the axis fixed
    /// ([`PathDynamics`]): where a closed run can be entered by a helix, the
    /// helix's radius, or the ramp along the run instead, is the one whose
    /// path takes the least time under them ([`path_time_estimate`]): a
    /// helix on a small circle is held to `(j ρ²)^(1/3)` by the linear axes'
    /// jerk (docs/rough5.md, "Entries against the machine's dynamics").
    /// `None`: the largest helix that fits, as before.
    pub entry_dynamics: Option<PathDynamics>,
    /// The air moves ([`crate::air_moves`]; docs/rough5.md, "Air moves"):
    /// the feeds, links and plunges that lie outside the in-process stock by
    /// the clearance, written at the air feed; `None` keeps every cutting
    /// move at its feed.
    pub air: Option<AirSettings>,
}

impl Rough5Settings {
    /// The settings of `scallop rough5` (docs/rough5.md) for the levels and
    /// curves `guides` and a cutting feed (mm/min): guide curves (SPU), CL
    /// points every 1 mm, angular steps of 2 deg (axis) and 5 deg (azimuth),
    /// a 0.5 mm bottom allowance, ramps of 5 deg, 1 mm clearance, links on
    /// the level up to 2 a_e, rapids at 20 m/min, no optimised orientation,
    /// no collision correction (steps 1 and 2), no air moves ([`Self::air`];
    /// `scallop rough5` and jobs turn them on), and every refinement on
    /// ([`Self::with_refinements`]).
    #[must_use]
    pub fn new(guides: GuideSettings, feed: f64) -> Self {
        Self {
            tilt: TiltMode::Guides,
            guides,
            bottom_allowance: 0.5,
            step: 1.0,
            max_angle_step: 2f64.to_radians(),
            max_azimuth_step: 5f64.to_radians(),
            ramp_angle: 5f64.to_radians(),
            clearance: 1.0,
            link_max: 2.0 * guides.radial_step,
            feed,
            rapid_rate: 20_000.0,
            orientation: None,
            limit_orientation: None,
            correct: false,
            levels: LevelOptions::default(),
            vertical_inside: false,
            vertical_thin_steps: false,
            spatial: false,
            translate: false,
            local_entry: false,
            smooth_axes: false,
            round_corners: false,
            root_rest: false,
            bottom_normal: false,
            entry: EntryMode::Auto,
            entry_dynamics: None,
            air: None,
        }
        .with_refinements(true)
    }

    /// These settings with every refinement of the guide-curve program (the
    /// level repairs of [`LevelOptions`], [`Self::vertical_inside`],
    /// [`Self::vertical_thin_steps`], [`Self::translate`],
    /// [`Self::local_entry`], [`Self::smooth_axes`], [`Self::round_corners`], [`Self::root_rest`]
    /// and [`Self::bottom_normal`]) on or off.
    #[must_use]
    pub fn with_refinements(self, on: bool) -> Self {
        Self {
            levels: LevelOptions { centre_offsets: on, pair_by_rank: on, open_bottom: on },
            vertical_inside: on,
            vertical_thin_steps: on,
            translate: on,
            local_entry: on,
            smooth_axes: on,
            round_corners: on,
            root_rest: on,
            bottom_normal: on,
            ..self
        }
    }
}

/// Largest axis translation of a colliding pair (mm).
pub const TRANSLATION_MAX: f64 = 2.5;
/// A translated pair's neighbours are moved by its translation less this much
/// per mm along the pass (mm/mm).
pub const TRANSLATION_SLOPE: f64 = 0.25;
/// Distance kept beyond the intrusion when translating (mm).
const TRANSLATION_MARGIN: f64 = 0.05;
/// Translations tried per pair (each re-placed and checked again).
const TRANSLATION_TRIES: usize = 4;

/// What one pass became.
#[derive(Debug, Clone, PartialEq)]
pub struct PassReport {
    /// Level number (0 = bottom).
    pub level: usize,
    /// Pass number in the level (0 = innermost).
    pub pass: usize,
    /// CL points cut.
    pub points: usize,
    /// Pairs dropped: tool not placed, or its body too close to a flank.
    pub dropped: usize,
    /// Pairs left out because the tool lies above the blank
    /// ([`plan_rough5_in`]).
    pub air: usize,
    /// Pairs whose axis the collision correction turned to clear the flanks
    /// (kept, unless an angular-step insertion next to them collides).
    pub corrected: usize,
    /// Pairs whose axis the spatial correction (step 2,
    /// [`Rough5Settings::spatial`]) turned through an upper limit curve, over
    /// its rounds.
    pub spatial: usize,
    /// Pairs the axis translation (step 3, [`Rough5Settings::translate`])
    /// moved by their own intrusion (not their neighbours).
    pub translated: usize,
    /// Runs the pass was split into.
    pub runs: usize,
    /// Pitch angle theta_t (Eq. 3.7) over the pass: min, max, mean (rad).
    pub pitch: [f64; 3],
    /// Largest angle between the tool axis and +Z (rad).
    pub max_tilt: f64,
}

/// One level of the plan.
#[derive(Debug, Clone, PartialEq)]
pub struct LevelReport {
    /// Distance from the bottom (mm).
    pub distance: f64,
    /// Passes.
    pub passes: usize,
    /// Why the level was cut with the axis +Z in the guide-curve variant.
    pub untilted: Option<String>,
    /// Why `pair_levels` failed when the level's passes were paired with the
    /// level above by rank instead ([`LevelOptions::pair_by_rank`]).
    pub paired_by_rank: Option<String>,
}

/// The roughing program and what it is made of.
#[derive(Debug, Clone)]
pub struct Rough5Plan {
    /// The program: tool tips in the part frame with their tool axes.
    pub toolpath: Toolpath,
    /// The levels, bottom up.
    pub levels: Vec<LevelReport>,
    /// The passes in cutting order.
    pub passes: Vec<PassReport>,
    /// Entries through the safe height.
    pub retracts: usize,
    /// Links kept on the level.
    pub links: usize,
    /// Ramp entries (`entries.ramp`).
    pub ramps: usize,
    /// Entries by kind.
    pub entries: EntryCount,
    /// The pass starts (tool tips) entered by a plunge into material: where
    /// neither a helix, a side entry nor a ramp was found.
    pub plunged_at: Vec<Point3>,
    /// Time at the programmed feeds and the rapid rate (s), without the
    /// machine's dynamics.
    pub estimated_time: f64,
    /// The air moves ([`Rough5Settings::air`]): how many, their length
    /// (mm) and the moves cut into pieces to find them; `None` without.
    pub air: Option<AirReport>,
    /// What each move of the toolpath is for (empty when unknown).
    pub roles: Vec<MoveRole>,
}

/// What a move of a [`Rough5Plan`] is for (its [`MoveKind`] says how it is
/// written): the machine time is broken down by it (docs/rough5.md, "Where
/// the machine time goes").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MoveRole {
    /// A pass along the level (and its lap).
    Cut,
    /// An entry into the level: down a helix, a ramp, from beside the stock,
    /// or a plunge into material.
    Entry,
    /// From the safe height down to where the entry starts.
    Approach,
    /// A link between passes on the level.
    Link,
    /// Out of the material along the axis, then up to the safe height (a
    /// retract, and the retract of a departure from the pole).
    Retract,
    /// The axis turned about the pole at a small tilt before leaving it.
    Turn,
}

impl MoveRole {
    /// Its name in reports.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            MoveRole::Cut => "cut",
            MoveRole::Entry => "entry",
            MoveRole::Approach => "approach",
            MoveRole::Link => "link",
            MoveRole::Retract => "retract",
            MoveRole::Turn => "turn",
        }
    }
}

/// The air moves of a [`Rough5Plan`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AirReport {
    /// Moves written at the air feed.
    pub moves: usize,
    /// Their length (mm).
    pub length: f64,
    /// Long moves cut into pieces where they enter or leave the air.
    pub split: usize,
    /// Time at the programmed feeds and the rapid rate (s) before the air
    /// moves (every cutting move at its cutting feed).
    pub estimated_time_before: f64,
}

/// A CL point and the pair it was placed from.
#[derive(Debug, Clone, Copy)]
struct Cl {
    place: Placement,
    sync: SyncPoint,
}

fn check(settings: &Rough5Settings) -> Result<(), Rough5Error> {
    let s = settings;
    for (name, value) in [
        ("step", s.step),
        ("max_angle_step", s.max_angle_step),
        ("max_azimuth_step", s.max_azimuth_step),
        ("ramp_angle", s.ramp_angle),
        ("clearance", s.clearance),
        ("link_max", s.link_max),
        ("feed", s.feed),
        ("rapid_rate", s.rapid_rate),
    ] {
        if !(value.is_finite() && value > 0.0) {
            return Err(Rough5Error::BadSetting { name, value });
        }
    }
    if !(s.bottom_allowance.is_finite() && s.bottom_allowance >= 0.0) {
        return Err(Rough5Error::BadSetting { name: "bottom_allowance", value: s.bottom_allowance });
    }
    Ok(())
}

/// Plans the roughing of the pocket with bottom faces `bottom` and flank
/// faces `flanks` (normals out of the volume to remove) in `stock`, with
/// `cutter` (its shank and holder checked against the flanks).
/// `progress(done, total)` is called after each level.
///
/// # Errors
/// [`Rough5Error::BadSetting`], the errors of the guide curves and of the
/// placer, [`Rough5Error::NoPass`] when nothing can be cut.
pub fn plan_rough5(
    bottom: &TriMesh,
    flanks: &TriMesh,
    stock: &Aabb3,
    cutter: &Cutter,
    settings: &Rough5Settings,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Rough5Plan, Rough5Error> {
    plan_rough5_in(bottom, flanks, (stock, None), cutter, settings, progress)
}

/// [`plan_rough5`] in a blank inside the stock box (a turned or cast blank,
/// a closed mesh): a CL point whose tool lies above the blank everywhere
/// within its radius (by [`AIR_MARGIN`]) cuts air and is left out, its
/// pass split there (the levels that run over an impeller's blade tips are
/// cut where they are below the blank's envelope: the crossable top).
///
/// # Errors
/// Those of [`plan_rough5`].
pub fn plan_rough5_in(
    bottom: &TriMesh,
    flanks: &TriMesh,
    (stock, blank): (&Aabb3, Option<&TriMesh>),
    cutter: &Cutter,
    settings: &Rough5Settings,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Rough5Plan, Rough5Error> {
    check(settings)?;
    let air = blank.map(|b| Air { blank: DexelPart::new(b), radius: cutter.radius(), flutes: cutter.flute_length() });
    let levels = level_passes_with(bottom, flanks, &settings.guides, settings.tilt, &settings.levels)?;
    if levels.iter().all(|l| l.passes.is_empty()) {
        let reason = "no level has a closed limit curve: open pockets (limit curves ending on the level's boundary) \
                      are not handled yet";
        return Err(Rough5Error::NoPass { reason: reason.into() });
    }
    // The shank and holder clear the blank beyond the pocket too.
    let beyond = blank.and_then(|b| blank_beyond(b, bottom));
    let check_with = |clearance: f64| match &beyond {
        Some(beyond) => BodyCheck::new(flanks, cutter, clearance).with_stock(beyond),
        None => BodyCheck::new(flanks, cutter, clearance),
    };
    let body = check_with(0.0);
    // The rest pass's tool keeps the flank allowance with its flutes and corner.
    let guided = settings.tilt == TiltMode::Guides;
    let rest =
        (guided && settings.root_rest).then(|| (check_with(settings.guides.flank_allowance), MeshQuery::new(flanks)));
    // The limit curves of each level (the path curves of its outer passes),
    // the tilt points of the spatial correction of the levels below.
    let upper_limits: Vec<Vec<scallop_mesh::Polyline3>> = levels
        .iter()
        .map(|l| {
            let outer = &l.passes[l.passes.len() - l.outer.min(l.passes.len())..];
            if guided && settings.spatial { outer.iter().map(|(c, _)| c.line.clone()).collect() } else { Vec::new() }
        })
        .collect();
    let mut out = Emitter::new(stock.max.z, stock.max.z + settings.clearance + cutter.radius(), settings);
    out.flat = Emitter::flat_radius(cutter);
    out.radius = cutter.radius();
    out.air = air;
    out.smooth = settings.smooth_axes;
    out.sides = Some(Sides { stock: *stock, pieces: body_pieces(cutter) });
    let mut reports = Vec::new();
    // The first level is entered from above the stock: the box's top, or the blank's.
    let stock_top = blank.map_or(stock.max.z, |b| b.bounds().max.z.min(stock.max.z));
    let mut entry_z = stock_top + settings.clearance;
    // The level cut before this one, for the local entries.
    let mut above: Option<Placer> = None;
    for (done, j) in (0..levels.len()).rev().enumerate() {
        let level = &levels[j];
        let allowance = if j == 0 { settings.bottom_allowance } else { 0.0 };
        let placer = Placer::new(level.support.mesh(), cutter, allowance)?;
        let mut top = f64::NEG_INFINITY;
        let mut first = true;
        let mut limit_pairs: Vec<Vec<SyncPoint>> = Vec::new();
        // The tools that cut this level, for the rest pass.
        let mut level_cut: Vec<Vec<Placement>> = Vec::new();
        for (m, (path, tilt)) in level.passes.iter().enumerate() {
            let cursor = out.last.map_or_else(|| path.line.points[0], |c| c.sync.path);
            let outer = m + level.outer >= level.passes.len();
            // Per-pass weights: the passes that leave the finished faces' stock
            // (the bottom level's and each level's limit passes) with their own.
            let weighted = match settings.limit_orientation {
                Some(o) if j == 0 || outer => Rough5Settings { orientation: Some(o), ..*settings },
                _ => *settings,
            };
            let (pairs, _) = pass_pairs((path, tilt.as_ref()), &cursor, &weighted)?;
            let (mut pairs, corrected) = corrected_pairs(&placer, &body, pairs, settings);
            if j == 0 && outer && rest.is_some() {
                limit_pairs.push(pairs.clone());
            }
            if guided && settings.bottom_normal && j == 0 && !outer {
                pairs = along_bottom_normal(&placer, &body, pairs, bottom_normal_min_slope(settings));
                pairs = vertical_where_clear(&placer, &body, &pairs, settings, &on_normal);
            } else if settings.vertical_inside && !outer && tilt.is_some() {
                pairs = vertical_where_clear(&placer, &body, &pairs, settings, &|_| false);
            } else if settings.vertical_thin_steps && outer && tilt.is_some() {
                let most = tol::LIMIT_STEP_ALLOWANCES * settings.guides.flank_allowance;
                let height = settings.guides.axial_step;
                pairs = vertical_where_clear(&placer, &body, &pairs, settings, &|s| limit_step(s, height) > most);
            }
            // Step 2 before step 3 (the thesis's order), on the offset levels.
            let mut spatial = 0;
            if guided && settings.spatial && tilt.is_some() && j > 0 {
                (pairs, spatial) = spatial_pairs(&placer, &body, pairs, &upper_limits[j + 1..], settings);
            }
            let mut moved = 0;
            if settings.translate {
                (pairs, moved) = translated(&placer, &body, pairs);
            }
            if settings.round_corners {
                pairs = rounded(pairs, outer, settings);
            }
            let (runs, mut report) = place_pass_in(&placer, &body, out.air.as_ref(), &pairs);
            report.corrected = corrected;
            report.spatial = spatial;
            report.translated = moved;
            report.level = j;
            report.pass = m;
            for run in &runs {
                top = run.iter().fold(top, |t, c| t.max(c.place.tip.z));
                let local = above.as_ref().filter(|_| settings.local_entry).and_then(|a| local_entry(a, &run[0]));
                let entry = local.map_or(entry_z, |z| (z + settings.clearance * run[0].place.axis.z).min(entry_z));
                out.cut_run(run, entry, first, (&placer, &body));
                first = false;
                if rest.is_some() && j == 0 {
                    level_cut.push(run.iter().map(|c| c.place).collect());
                }
            }
            reports.push(report);
        }
        if let Some((rest_body, flank_query)) = rest.as_ref().filter(|_| j == 0) {
            let tool = (cutter.radius(), corner_radius(cutter), cutter.flute_length());
            for (m, pairs) in limit_pairs.iter().enumerate() {
                let cut = swept(&level_cut);
                let mut report = PassReport {
                    level: 0,
                    pass: level.passes.len() + m,
                    points: 0,
                    dropped: 0,
                    air: 0,
                    corrected: 0,
                    spatial: 0,
                    translated: 0,
                    runs: 0,
                    pitch: [0.0; 3],
                    max_tilt: 0.0,
                };
                for seg in root_rest_pairs(
                    &placer,
                    rest_body,
                    flank_query,
                    (pairs, &cut),
                    tool,
                    settings.guides.flank_allowance,
                ) {
                    let seg = limit_angular_step(&seg, settings.max_angle_step, settings.max_azimuth_step);
                    let (runs, r) = place_pass_in(&placer, rest_body, out.air.as_ref(), &seg);
                    report.dropped += r.dropped;
                    report.air += r.air;
                    report.max_tilt = report.max_tilt.max(r.max_tilt);
                    for run in runs.iter().filter(|r| run_length(r) >= ROOT_REST_MIN_RUN) {
                        report.points += run.len();
                        report.runs += 1;
                        let local =
                            above.as_ref().filter(|_| settings.local_entry).and_then(|a| local_entry(a, &run[0]));
                        let entry =
                            local.map_or(entry_z, |z| (z + settings.clearance * run[0].place.axis.z).min(entry_z));
                        out.cut_run(run, entry, false, (&placer, &body));
                        level_cut.push(run.iter().map(|c| c.place).collect());
                    }
                }
                reports.push(report);
            }
        }
        if top.is_finite() {
            entry_z = top + settings.clearance;
        }
        above = Some(placer);
        progress(done + 1, levels.len());
    }
    if out.path.moves().is_empty() {
        return Err(Rough5Error::NoPass { reason: "no pass could be placed clear of the flanks".into() });
    }
    out.finish();
    let mut air_report = None;
    if let Some(a) = &settings.air {
        let found = crate::air_moves(&out.path, cutter, (stock, blank), a)?;
        air_report = Some(AirReport {
            moves: found.moves,
            length: found.length,
            split: found.split,
            estimated_time_before: estimate_time(&out.path, settings.rapid_rate),
        });
        out.path = found.toolpath;
        out.roles = found.from.iter().map(|&i| out.roles[i]).collect();
    }
    let levels = levels
        .iter()
        .map(|l| LevelReport {
            distance: l.distance,
            passes: l.passes.len(),
            untilted: l.untilted.clone(),
            paired_by_rank: l.paired_by_rank.clone(),
        })
        .collect();
    let estimated_time = estimate_time(&out.path, settings.rapid_rate);
    Ok(Rough5Plan {
        toolpath: out.path,
        levels,
        passes: reports,
        retracts: out.retracts,
        links: out.links,
        ramps: out.entries.ramp,
        entries: out.entries,
        plunged_at: out.plunged_at,
        estimated_time,
        air: air_report,
        roles: out.roles,
    })
}

/// One pass of a level as a program of its own (the orientation cases of
/// Jousselin 2020, Ch. 3 §2.3).
#[derive(Debug, Clone)]
pub struct SinglePass {
    /// The optimised orientation (`None` for SPU).
    pub orientation: Option<Orientation>,
    /// The program: a plunge along the first axis from the safe height, the
    /// pass (a full lap of a closed pass), a retract.
    pub toolpath: Toolpath,
    /// (distance along the cut from its first CL point in mm, theta_t in rad)
    /// at every CL point kept.
    pub trace: Vec<(f64, f64)>,
    /// The pass.
    pub report: PassReport,
    /// Time at the programmed feeds and the rapid rate (s).
    pub estimated_time: f64,
}

/// Plans pass `pass` of `level` alone, from the path vertex closest to
/// `entry`, with `cutter` checked against `flanks`; `bottom_allowance` of
/// `settings` applies when `on_bottom`.
///
/// # Errors
/// [`Rough5Error::NoPass`] when the pass does not exist or no CL point can
/// be placed; the errors of the placer and of the orientation.
pub fn plan_single_pass(
    (level, pass, on_bottom): (&LevelPasses, usize, bool),
    entry: &Point3,
    (stock, flanks): (&Aabb3, &TriMesh),
    cutter: &Cutter,
    settings: &Rough5Settings,
) -> Result<SinglePass, Rough5Error> {
    check(settings)?;
    let (path, tilt) = level.passes.get(pass).ok_or_else(|| Rough5Error::NoPass {
        reason: format!("the level has {} passes, not {}", level.passes.len(), pass + 1),
    })?;
    let allowance = if on_bottom { settings.bottom_allowance } else { 0.0 };
    let placer = Placer::new(level.support.mesh(), cutter, allowance)?;
    let body = BodyCheck::new(flanks, cutter, 0.0);
    let (pairs, orientation) = pass_pairs((path, tilt.as_ref()), entry, settings)?;
    let (pairs, corrected) = corrected_pairs(&placer, &body, pairs, settings);
    let (runs, mut report) = place_pass(&placer, &body, &pairs);
    report.corrected = corrected;
    report.pass = pass;
    if runs.is_empty() {
        return Err(Rough5Error::NoPass { reason: "no CL point of the pass is clear of the flanks".into() });
    }
    let mut out = Emitter::new(stock.max.z, stock.max.z + settings.clearance + cutter.radius(), settings);
    let mut trace = Vec::new();
    let mut along = 0.0;
    for (k, run) in runs.iter().enumerate() {
        out.cut_run(run, f64::NEG_INFINITY, k == 0, (&placer, &body));
        for (i, c) in run.iter().enumerate() {
            if i > 0 {
                along += (c.place.tip - run[i - 1].place.tip).norm();
            }
            trace.push((along, pitch_angle(&c.place.axis, &c.sync.tangent, &c.sync.normal)));
        }
    }
    out.finish();
    let estimated_time = estimate_time(&out.path, settings.rapid_rate);
    Ok(SinglePass { orientation, toolpath: out.path, trace, report, estimated_time })
}

/// Time at the programmed feeds and the rapid rate (s).
pub(crate) fn estimate_time(path: &Toolpath, rapid_rate: f64) -> f64 {
    let mut from: Option<Point3> = None;
    let mut t = 0.0;
    for (i, m) in path.moves().iter().enumerate() {
        if let Some(a) = from {
            let rate = match m.kind {
                MoveKind::Rapid | MoveKind::Retract => rapid_rate,
                _ => path.feed_of(i),
            };
            t += (m.to - a).norm() / rate * 60.0;
        }
        from = Some(m.to);
    }
    t
}

/// The synchronised pairs of one pass: SPU, or the optimised
/// reparameterisation when `settings.orientation` is given and the pass has
/// a tilt curve; with the angular step limited.
fn pass_pairs(
    (path, tilt): (&Curve, Option<&Curve>),
    cursor: &Point3,
    settings: &Rough5Settings,
) -> Result<(Vec<SyncPoint>, Option<Orientation>), Rough5Error> {
    let (pairs, orientation) = match (tilt, &settings.orientation) {
        (Some(t), Some(o)) => {
            let start = path.line.points[crate::closest_vertex(path, cursor)];
            let found = optimise_pass(path, t, &start, o)?;
            (synchronise_with(path, t, &start, settings.step, &found.reparam), Some(found))
        }
        _ => (synchronise(path, tilt, cursor, settings.step), None),
    };
    Ok((limit_angular_step(&pairs, settings.max_angle_step, settings.max_azimuth_step), orientation))
}

/// `pairs` with the colliding ones corrected when `settings.correct`, and how
/// many pairs were corrected. Where a correction turned an axis the angular
/// step is limited again; the pairs this inserts between a corrected axis and
/// its neighbour may collide in turn, so the correction runs again on them,
/// at most [`tol::CORRECTION_ROUNDS`] times (the thesis's cap on its
/// correction loop, Jousselin 2020, Ch. 3 §3, Fig. 3.34).
fn corrected_pairs(
    placer: &Placer,
    body: &BodyCheck,
    mut pairs: Vec<SyncPoint>,
    settings: &Rough5Settings,
) -> (Vec<SyncPoint>, usize) {
    let mut corrected = 0;
    if !settings.correct {
        return (pairs, corrected);
    }
    for _ in 0..tol::CORRECTION_ROUNDS {
        let (turned, count) = correct_pairs(placer, body, &pairs, settings.max_angle_step);
        if count.corrected == 0 {
            break;
        }
        corrected += count.corrected;
        pairs = limit_angular_step(&turned, settings.max_angle_step, settings.max_azimuth_step);
    }
    (pairs, corrected)
}

/// `pairs` with the colliding ones corrected by the spatial correction
/// (Jousselin 2020, Ch. 3 §3, step 2) against the limit curves of the levels
/// `upper` (those above the pass's level), and how many pairs it turned. The
/// loop of Fig. 3.34: detect, correct, and where an axis was turned limit the
/// angular step again (the pairs inserted between a corrected axis and its
/// neighbours are the rebuilt curves' points between the corrected ones) and
/// correct again, at most [`tol::CORRECTION_ROUNDS`] rounds, stopping when a
/// round turns no axis. The synchronisation is not optimised again.
fn spatial_pairs(
    placer: &Placer,
    body: &BodyCheck,
    mut pairs: Vec<SyncPoint>,
    upper: &[Vec<scallop_mesh::Polyline3>],
    settings: &Rough5Settings,
) -> (Vec<SyncPoint>, usize) {
    let curves: Vec<scallop_mesh::Polyline3> = upper.iter().flatten().cloned().collect();
    let mut corrected = 0;
    if curves.is_empty() {
        return (pairs, corrected);
    }
    for _ in 0..tol::CORRECTION_ROUNDS {
        let (turned, count) = correct_pairs_spatial(placer, body, &pairs, &curves, settings.max_angle_step);
        if count.corrected == 0 {
            break;
        }
        corrected += count.corrected;
        pairs = limit_angular_step(&turned, settings.max_angle_step, settings.max_azimuth_step);
    }
    (pairs, corrected)
}

/// Whether a pass's pairs close on themselves (the last repeats the first).
fn is_closed(pairs: &[SyncPoint]) -> bool {
    let n = pairs.len();
    n > 2 && (pairs[0].path - pairs[n - 1].path).norm() < 1e-9
}

/// Distance along the pass from pair `i` to pair `j` (`at`: the cumulative
/// length at each pair; `lap` the length of a closed pass, else infinite).
fn along(at: &[f64], lap: f64, i: usize, j: usize) -> f64 {
    let d = (at[i] - at[j]).abs();
    d.min(lap - d)
}

/// Cumulative length along the guide points of `pairs`, and the lap length
/// when the pass is closed (infinite otherwise).
fn arc_positions(pairs: &[SyncPoint]) -> (Vec<f64>, f64) {
    let mut at = Vec::with_capacity(pairs.len());
    let mut s = 0.0;
    for (i, p) in pairs.iter().enumerate() {
        if i > 0 {
            s += (p.path - pairs[i - 1].path).norm();
        }
        at.push(s);
    }
    let lap = if is_closed(pairs) { s } else { f64::INFINITY };
    (at, lap)
}

/// The step (mm) that the vertical tool at pair `s` leaves between its level
/// and the level above, where the tilted tool along the flank leaves none:
/// the horizontal run of the pair's axis over the height between its guide
/// points (P_T on the level, P_D on the level above), or over `height` (the
/// levels' spacing) for a pair without a tilt point. On a flank at a draft
/// alpha with levels a_p apart it is a_p tan alpha; under an undercut it is
/// the overhang the vertical tool cannot reach under.
#[must_use]
pub fn limit_step(s: &SyncPoint, height: f64) -> f64 {
    let rise = s.tilt.map_or(height, |d| (d - s.path).z);
    let rise = if rise > 0.0 { rise } else { height };
    let u = s.axis;
    if u.z <= 0.0 {
        return f64::INFINITY;
    }
    rise * u.x.hypot(u.y) / u.z
}

/// `pairs` with the axis +Z wherever the vertical tool is placed clear of
/// the flanks and `keep` is false for the pair
/// ([`Rough5Settings::vertical_inside`], [`Rough5Settings::vertical_thin_steps`]).
/// A pair where it is not keeps its axis; the pairs around it lean in, in its azimuth, by its tilt
/// less one angular step per `step` mm along the pass (the largest over such
/// pairs), so the axis turns by at most the angular step between pairs. The
/// angular step is limited again afterwards.
fn vertical_where_clear(
    placer: &Placer,
    body: &BodyCheck,
    pairs: &[SyncPoint],
    settings: &Rough5Settings,
    keep: &(dyn Fn(&SyncPoint) -> bool + Sync),
) -> Vec<SyncPoint> {
    let blocked: Vec<bool> = pairs
        .par_iter()
        .map(|s| keep(s) || placer.place(&s.path, &Vec3::z()).is_none_or(|p| body.collides(&p.tip, &p.axis)))
        .collect();
    let (at, lap) = arc_positions(pairs);
    let per_mm = settings.max_angle_step / settings.step;
    // (tilt needed, the blocked pair that needs it) at every pair.
    let mut need: Vec<(f64, Option<usize>)> = vec![(0.0, None); pairs.len()];
    for j in (0..pairs.len()).filter(|&j| blocked[j]) {
        let tilt = pairs[j].axis.angle(&Vec3::z());
        for (i, n) in need.iter_mut().enumerate() {
            let t = tilt - per_mm * along(&at, lap, i, j);
            if t > n.0 {
                *n = (t, Some(j));
            }
        }
    }
    let out: Vec<SyncPoint> = pairs
        .iter()
        .zip(&need)
        .enumerate()
        .map(|(i, (s, &(t, from)))| {
            let axis = match from {
                _ if blocked[i] => s.axis,
                None => Vec3::z(),
                Some(j) => {
                    let u = pairs[j].axis;
                    let f = u.y.atan2(u.x);
                    Vec3::new(t.sin() * f.cos(), t.sin() * f.sin(), t.cos())
                }
            };
            SyncPoint { axis, ..*s }
        })
        .collect();
    let span = tol::THIN_SPAN_STEPS * settings.step;
    let chord = tol::THIN_CHORD_ALLOWANCES * settings.guides.flank_allowance;
    thin_vertical(limit_angular_step(&out, settings.max_angle_step, settings.max_azimuth_step), span, chord)
}

/// Whether the pair's axis is its bottom normal ([`along_bottom_normal`]).
fn on_normal(s: &SyncPoint) -> bool {
    (s.axis - s.normal).norm() < 1e-12 && s.normal.angle(&Vec3::z()) > 0.0
}

/// The least slope (rad) of a bottom whose inner passes follow its normal
/// ([`Rough5Settings::bottom_normal`]): where the vertical torus leaves a
/// step a_e tan(slope) between passes a_e apart thicker than the bottom
/// allowance (6.3 degrees at a_e 4.5 mm and 0.5 mm). A gentler slope leaves
/// the finishing tool at most twice its stock, as a 3-axis program does,
/// and tilting for it costs machine time (the closed pocket's bottom leans
/// 3 to 5 degrees in places).
#[must_use]
pub fn bottom_normal_min_slope(settings: &Rough5Settings) -> f64 {
    (settings.bottom_allowance / settings.guides.radial_step).atan()
}

/// `pairs` of a bottom level's inner pass with the axis along the bottom's
/// normal where the bottom leans by more than `min_slope` (rad) and that
/// tool is placed clear of the flanks; the others keep their axis.
fn along_bottom_normal(placer: &Placer, body: &BodyCheck, pairs: Vec<SyncPoint>, min_slope: f64) -> Vec<SyncPoint> {
    pairs
        .into_par_iter()
        .map(|s| {
            let n = s.normal;
            let lean = n.angle(&Vec3::z()) > min_slope;
            if lean && placer.place(&s.path, &n).is_some_and(|p| !body.collides(&p.tip, &p.axis)) {
                SyncPoint { axis: n, ..s }
            } else {
                s
            }
        })
        .collect()
}

/// Distance from `p` to the segment `a`-`b`.
fn off_segment(p: &Point3, a: &Point3, b: &Point3) -> f64 {
    let ab = b - a;
    let t = if ab.norm_squared() > 0.0 { ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0) } else { 0.0 };
    (p - (a + ab * t)).norm()
}

/// `pairs` without the pairs inside a stretch of vertical axes that their
/// neighbours make redundant: one is dropped when it, the pairs on either
/// side and the last pair kept all have the axis +Z, the next pair's guide
/// point is within `span` of the last kept one's, and every pair from the
/// last kept one to it lies within `chord` of the segment between the two.
/// The synchronisation steps the path curve by the fraction of the longer of
/// the path and tilt curves and the angular-step limit inserts pairs where
/// the guide-curve axis turns, so a pass made vertical keeps pairs a tenth of
/// the step apart, along curves traced on the levels' voxel fields; on the
/// machine those short, kinked blocks slow the feed as much as the rotary
/// axes did (docs/rough5.md, "Limit passes: the tilt where it pays"). Every
/// tilted pair, its neighbours and the first and last pairs stay.
#[must_use]
pub fn thin_vertical(pairs: Vec<SyncPoint>, span: f64, chord: f64) -> Vec<SyncPoint> {
    let n = pairs.len();
    if n < 3 {
        return pairs;
    }
    let vertical = |s: &SyncPoint| s.axis.angle(&Vec3::z()) <= tol::ANGLE_EPS;
    let off = off_segment;
    let mut out: Vec<SyncPoint> = Vec::with_capacity(n);
    out.push(pairs[0]);
    let mut last_at = 0;
    for i in 1..n - 1 {
        let last = pairs[last_at];
        let redundant = vertical(&last)
            && vertical(&pairs[i - 1])
            && vertical(&pairs[i])
            && vertical(&pairs[i + 1])
            && (pairs[i + 1].path - last.path).norm() <= span
            && (last_at + 1..=i).all(|k| off(&pairs[k].path, &last.path, &pairs[i + 1].path) <= chord);
        if !redundant {
            out.push(pairs[i]);
            last_at = i;
        }
    }
    out.push(pairs[n - 1]);
    out
}

/// `pairs` of a pass in long blocks where vertical, their corners rounded
/// ([`Rough5Settings::round_corners`]); `outer` for a limit pass.
fn rounded(pairs: Vec<SyncPoint>, outer: bool, settings: &Rough5Settings) -> Vec<SyncPoint> {
    let g = &settings.guides;
    let span = tol::THIN_SPAN_STEPS * settings.step;
    let chord = tol::THIN_CHORD_ALLOWANCES * g.flank_allowance;
    let radius = if outer || g.radial_step > g.tool_radius { 0.0 } else { tol::CORNER_FILLET_RADII * g.tool_radius };
    round_corners(thin_vertical(pairs, span, chord), radius, chord, tol::CORNER_LINK_STEPS * settings.step)
}

/// A corner of a pass found by [`round_corners`]: the pairs `first..=last`
/// turn it, by `turn` (rad, positive to the left) in all.
struct Corner {
    first: usize,
    last: usize,
    turn: f64,
}

/// The fillet that replaces a corner: from `from` to `to` (positions along
/// the pass, mm), the arc of centre `centre` and radius `radius` from
/// `start` (a unit vector from the centre) turning by `turn`.
struct Fillet {
    from: f64,
    to: f64,
    centre: [f64; 2],
    radius: f64,
    start: f64,
    turn: f64,
}

/// `pairs` with the corners of their vertical stretches rounded (docs/rough5.md,
/// "Corners and blocks"). A corner is a run of pairs that turn, in plan, by more
/// than [`tol::CORNER_TURN_NOISE`] each to the same side, at most `link` mm apart,
/// one of them by more than the arc chords' turn ([`tol::FILLET_TURN_SHARE`] of the
/// time model's smooth junction). It is replaced by the circular fillet tangent to
/// the stretch that comes to it and the one that leaves it, in chords that turn by
/// at most that much each: a convex corner (to the left, the side the pass keeps
/// its inside on) of at most [`tol::CORNER_FILLET_MAX_TURN`] with a radius up to
/// `convex_radius`, every other corner only where the fillet passes within `chord`
/// of the pairs it replaces (the polygon of a curve traced on a voxel field
/// refitted as the arc it stands for). The fillet never reaches past half the way
/// to the next corner, nor past the first or last pair, and every pair it replaces
/// or stands between is vertical. The fillet's pairs have the axis +Z and the
/// guide point's height interpolated along the fillet; their level normal and tilt
/// point are those of the nearest pair replaced.
#[must_use]
pub fn round_corners(pairs: Vec<SyncPoint>, convex_radius: f64, chord: f64, link: f64) -> Vec<SyncPoint> {
    let n = pairs.len();
    if n < 3 {
        return pairs;
    }
    let xy = |i: usize| [pairs[i].path.x, pairs[i].path.y];
    let sub = |a: [f64; 2], b: [f64; 2]| [a[0] - b[0], a[1] - b[1]];
    let norm = |v: [f64; 2]| v[0].hypot(v[1]);
    let turn_of = |a: [f64; 2], b: [f64; 2]| (a[0] * b[1] - a[1] * b[0]).atan2(a[0] * b[0] + a[1] * b[1]);
    let mut at = vec![0.0; n];
    for i in 1..n {
        at[i] = at[i - 1] + norm(sub(xy(i), xy(i - 1)));
    }
    let turns: Vec<f64> = (0..n)
        .map(|i| {
            if i == 0 || i == n - 1 {
                return 0.0;
            }
            let (a, b) = (sub(xy(i), xy(i - 1)), sub(xy(i + 1), xy(i)));
            if norm(a) < tol::ANGLE_EPS.sqrt() || norm(b) < tol::ANGLE_EPS.sqrt() { 0.0 } else { turn_of(a, b) }
        })
        .collect();
    let chord_turn = tol::FILLET_TURN_SHARE * scallop_geom::tol::machine::SMOOTH_JUNCTION;
    let mut corners: Vec<Corner> = Vec::new();
    let mut i = 1;
    while i + 1 < n {
        if turns[i].abs() <= tol::CORNER_TURN_NOISE {
            i += 1;
            continue;
        }
        let first = i;
        while i + 2 < n
            && turns[i + 1].abs() > tol::CORNER_TURN_NOISE
            && turns[i + 1].signum() == turns[first].signum()
            && at[i + 1] - at[i] <= link
        {
            i += 1;
        }
        if (first..=i).any(|k| turns[k].abs() > chord_turn) {
            corners.push(Corner { first, last: i, turn: turns[first..=i].iter().sum() });
        }
        i += 1;
    }
    let vertical = |k: usize| pairs[k].axis.angle(&Vec3::z()) <= tol::ANGLE_EPS;
    let mut fillets: Vec<Fillet> = Vec::new();
    for (c, corner) in corners.iter().enumerate() {
        let (s, e, turn) = (corner.first, corner.last, corner.turn);
        if turn.abs() >= std::f64::consts::PI * 0.95 {
            continue;
        }
        let unit = |v: [f64; 2]| {
            let l = norm(v);
            [v[0] / l, v[1] / l]
        };
        let (d_in, d_out) = (unit(sub(xy(s), xy(s - 1))), unit(sub(xy(e + 1), xy(e))));
        // The corner point V: xy(s) + u d_in = xy(e) - w d_out.
        let det = d_in[0] * d_out[1] - d_in[1] * d_out[0];
        if det.abs() < tol::ANGLE_EPS.sqrt() {
            continue;
        }
        let r = sub(xy(e), xy(s));
        let u = (r[0] * d_out[1] - r[1] * d_out[0]) / det;
        let w = (d_in[0] * r[1] - d_in[1] * r[0]) / det;
        if u < -chord || w < -chord {
            continue;
        }
        let (u, w) = (u.max(0.0), w.max(0.0));
        let corner_at = [xy(s)[0] + u * d_in[0], xy(s)[1] + u * d_in[1]];
        // Room before and after: half the way to the neighbouring corners.
        let before = if c > 0 { (at[s] - at[corners[c - 1].last]) / 2.0 } else { at[s] * 0.999 };
        let after =
            if c + 1 < corners.len() { (at[corners[c + 1].first] - at[e]) / 2.0 } else { (at[n - 1] - at[e]) * 0.999 };
        let room = (u + before).min(w + after);
        let half = turn.abs() / 2.0;
        let need = u.max(w);
        let convex = convex_radius > 0.0 && turn > 0.0 && turn.abs() <= tol::CORNER_FILLET_MAX_TURN;
        let fillet_of = |t: f64| {
            let radius = t / half.tan();
            let side = turn.signum();
            let t1 = [corner_at[0] - t * d_in[0], corner_at[1] - t * d_in[1]];
            let centre = [t1[0] - side * d_in[1] * radius, t1[1] + side * d_in[0] * radius];
            let start = (t1[1] - centre[1]).atan2(t1[0] - centre[0]);
            Fillet { from: at[s] - (t - u), to: at[e] + (t - w), centre, radius, start, turn }
        };
        let deviation = |f: &Fillet| {
            (0..n)
                .filter(|&k| at[k] > f.from && at[k] < f.to)
                .map(|k| (norm(sub(xy(k), f.centre)) - f.radius).abs())
                .fold(0.0, f64::max)
        };
        // The largest fillet within the room, the radius and the deviation allowed.
        let mut t = if convex { room.min(convex_radius * half.tan()) } else { room };
        let mut found = None;
        while t >= need && t > 0.0 {
            let f = fillet_of(t);
            if convex || deviation(&f) <= chord {
                found = Some(f);
                break;
            }
            t *= 0.8;
        }
        let Some(f) = found else { continue };
        if f.radius <= 0.0 || !f.radius.is_finite() {
            continue;
        }
        // Every pair from the one before the fillet to the one after it is vertical.
        let lo = at.partition_point(|&a| a <= f.from).saturating_sub(1);
        let hi = at.partition_point(|&a| a < f.to).min(n - 1);
        if (lo..=hi).all(vertical) {
            fillets.push(f);
        }
    }
    if fillets.is_empty() {
        return pairs;
    }
    let mut out = Vec::with_capacity(n + 16 * fillets.len());
    let mut next = fillets.iter().peekable();
    let mut k = 0;
    while k < n {
        let Some(f) = next.peek() else {
            out.push(pairs[k]);
            k += 1;
            continue;
        };
        if at[k] < f.from {
            out.push(pairs[k]);
            k += 1;
            continue;
        }
        // The height along the pass at a position: linear between the pairs.
        let height = |pos: f64| {
            let j = at.partition_point(|&a| a < pos).clamp(1, n - 1);
            let span = at[j] - at[j - 1];
            let w = if span > 0.0 { (pos - at[j - 1]) / span } else { 0.0 };
            pairs[j - 1].path.z + (pairs[j].path.z - pairs[j - 1].path.z) * w.clamp(0.0, 1.0)
        };
        let (z0, z1) = (height(f.from), height(f.to));
        let chords = (f.turn.abs() / chord_turn).ceil().max(1.0) as usize;
        let side = f.turn.signum();
        let (before, after) = (pairs[k.saturating_sub(1)], pairs[at.partition_point(|&a| a <= f.to).min(n - 1)]);
        for q in 0..=chords {
            let w = q as f64 / chords as f64;
            let a = f.start + f.turn * w;
            let path =
                Point3::new(f.centre[0] + f.radius * a.cos(), f.centre[1] + f.radius * a.sin(), z0 + (z1 - z0) * w);
            let tangent = Vec3::new(-side * a.sin(), side * a.cos(), 0.0);
            let near = if w < 0.5 { before } else { after };
            // (A fillet starting on a kept pair's guide point does not repeat it.)
            if q == 0 && out.last().is_some_and(|l: &SyncPoint| (l.path - path).xy().norm() < tol::FILLET_MERGE) {
                continue;
            }
            out.push(SyncPoint { path, tangent, axis: Vec3::z(), ..near });
        }
        while k < n && (at[k] <= f.to || (at[k] - f.to < tol::FILLET_MERGE && k + 1 < n)) {
            k += 1;
        }
        next.next();
    }
    out
}

/// The translation of the guide point of a pair whose tool comes too close
/// to a flank that clears it, the axis kept (Jousselin 2020, Ch. 3 §3,
/// step 3, Eq. 3.33 as corrected: the axis moved along the flank normal N_f
/// by what it lacks): the part of N_f across the axis, by the intrusion plus
/// a margin, the tool placed again, at most [`TRANSLATION_TRIES`] times and
/// [`TRANSLATION_MAX`] in all. Zero for a clear pair and for one that cannot
/// be cleared.
fn translation(placer: &Placer, body: &BodyCheck, s: &SyncPoint) -> Vec3 {
    let mut shift = Vec3::zeros();
    for _ in 0..=TRANSLATION_TRIES {
        let Some(p) = placer.place(&(s.path + shift), &s.axis) else { return Vec3::zeros() };
        let Some((deficit, normal)) = body.intrusion(&p.tip, &p.axis) else { return shift };
        let across = normal - p.axis * normal.dot(&p.axis);
        let len = across.norm();
        if len < 1e-6 {
            return Vec3::zeros();
        }
        shift += across / len * (deficit + TRANSLATION_MARGIN);
        if shift.norm() > TRANSLATION_MAX {
            return Vec3::zeros();
        }
    }
    Vec3::zeros()
}

/// `pairs` with the colliding ones translated clear of the flanks
/// ([`translation`]) and their neighbours moved the same way by the
/// translation less [`TRANSLATION_SLOPE`] per mm along the pass (the largest
/// such move), so the pass bends away from the flank instead of jumping; and
/// how many pairs were translated by their own intrusion.
fn translated(placer: &Placer, body: &BodyCheck, pairs: Vec<SyncPoint>) -> (Vec<SyncPoint>, usize) {
    let shifts: Vec<Vec3> = pairs
        .par_iter()
        .map(|s| {
            let clear = placer.place(&s.path, &s.axis).is_some_and(|p| !body.collides(&p.tip, &p.axis));
            if clear { Vec3::zeros() } else { translation(placer, body, s) }
        })
        .collect();
    let moved: Vec<usize> = (0..pairs.len()).filter(|&j| shifts[j].norm() > 0.0).collect();
    if moved.is_empty() {
        return (pairs, 0);
    }
    let (at, lap) = arc_positions(&pairs);
    let out = pairs
        .into_iter()
        .enumerate()
        .map(|(i, s)| {
            let mut best = shifts[i];
            for &j in &moved {
                let len = shifts[j].norm() - TRANSLATION_SLOPE * along(&at, lap, i, j);
                if len > best.norm() {
                    best = shifts[j] * (len / shifts[j].norm());
                }
            }
            SyncPoint { path: s.path + best, ..s }
        })
        .collect();
    (out, moved.len())
}

/// The least upward component of the unit normal of a blank facet kept by
/// [`blank_beyond`].
const BEYOND_FACING: f64 = 0.1;

/// The facets of `blank` that face up and are not over `bottom` (their
/// centroid's vertical misses it): the top of the stock beyond the pocket,
/// which no pass cuts (an impeller channel's neighbours stay full up to the
/// blank's envelope in the proof). `None` when there is no such facet.
fn blank_beyond(blank: &TriMesh, bottom: &TriMesh) -> Option<TriMesh> {
    let query = scallop_mesh::MeshQuery::new(bottom);
    let top = blank.bounds().max.z.max(bottom.bounds().max.z) + 1.0;
    let soup: Vec<[Point3; 3]> = blank
        .triangles()
        .iter()
        .map(|t| t.map(|v| blank.vertices()[v as usize]))
        .filter(|t| {
            // Facing up: the envelope over the rest of the part (a shank
            // beside the blank's outer wall is in the air beyond it).
            let n = (t[1] - t[0]).cross(&(t[2] - t[0]));
            if n.z <= BEYOND_FACING * n.norm() || n.norm() == 0.0 {
                return false;
            }
            let c = Point3::from((t[0].coords + t[1].coords + t[2].coords) / 3.0);
            query.ray_cast(&Point3::new(c.x, c.y, top), &-Vec3::z()).is_none()
        })
        .collect();
    if soup.is_empty() {
        return None;
    }
    TriMesh::from_soup(&soup).ok().map(|(m, _)| m)
}

/// How far above the blank (mm) a tool's lowest point must be, everywhere
/// within its radius, for its CL point to be left out as air.
pub const AIR_MARGIN: f64 = 1.0;

/// Steps (mm) of the search along the axis for where the tool is above the
/// blank (the rapid approaches and retracts of [`plan_rough5_in`]), and up
/// its flutes.
pub const AIR_STEP: f64 = 1.0;

/// The blank a program cuts in, for [`plan_rough5_in`].
struct Air {
    blank: DexelPart,
    radius: f64,
    /// The flute length: the part of the tool a rapid must keep out of the
    /// stock.
    flutes: f64,
}

impl Air {
    /// The blank's top along the vertical through `(x, y)` (`-inf` off it).
    fn top(&self, x: f64, y: f64) -> f64 {
        let spans = self.blank.intervals(&Point3::new(x, y, 0.0), 2);
        spans.iter().map(|s| s.1).fold(f64::NEG_INFINITY, f64::max)
    }

    /// Whether the tool at `p` lies above the blank by [`AIR_MARGIN`] at its
    /// axis and at 16 points on the circles of its radius and half of it
    /// (the blank is a smooth envelope); its lowest point is taken `R sin
    /// tilt` under the tip.
    fn holds(&self, p: &Placement) -> bool {
        self.holds_at(&p.tip, &p.axis)
    }

    /// [`Air::holds`] for the tool's cross-section at `c` on the axis `axis`.
    fn holds_at(&self, c: &Point3, axis: &Vec3) -> bool {
        let low = c.z - self.radius * axis.angle(&Vec3::z()).sin() - AIR_MARGIN;
        let ring = (0..8).flat_map(|k| {
            let a = std::f64::consts::FRAC_PI_4 * f64::from(k);
            [1.0, 0.5].map(|f| (c.x + f * self.radius * a.cos(), c.y + f * self.radius * a.sin()))
        });
        std::iter::once((c.x, c.y)).chain(ring).all(|(x, y)| self.top(x, y) < low)
    }

    /// Whether the flutes of the tool with its tip at `tip` along `axis` lie
    /// above the blank ([`Air::holds_at`] every [`AIR_STEP`] mm up the
    /// flutes): the blank holds the in-process stock, so a rapid there meets
    /// no stock.
    fn clears(&self, tip: &Point3, axis: &Vec3) -> bool {
        let n = (self.flutes / AIR_STEP).ceil().max(1.0) as usize;
        (0..=n).all(|k| self.holds_at(&(tip + axis * (self.flutes * k as f64 / n as f64)), axis))
    }

    /// The lowest height `h` along `axis` over `tip`, from `from` down to
    /// `to`, such that the tool is above the blank ([`Air::clears`]) at
    /// every [`AIR_STEP`] from `from` down to `h`; `from` when it is not.
    fn clear_down_to(&self, tip: &Point3, axis: &Vec3, from: f64, to: f64) -> f64 {
        let mut h = from;
        while h - AIR_STEP >= to && self.clears(&(tip + axis * (h - AIR_STEP)), axis) {
            h -= AIR_STEP;
        }
        h
    }
}

/// Most legs of the ramp along an open run ([`open_ramp`]): out and back.
/// A ramp back and forth along a short run stops at every turn; on the
/// impeller's short open runs more legs cost more machine time than they
/// save over a plunge (docs/rough5.md, "Entries").
pub const OPEN_RAMP_LEGS: usize = 2;

/// The ramp entry of an open run (tool tips and axes, top first, ending at
/// its first point on the level): the tool goes along the run's first
/// points and back, lifted along their axes by `tan(ramp_angle)` per mm
/// travelled before it reaches the start, at most `lift`; the legs turn at
/// the run's end or where the one leg is long enough. `None` where a lifted
/// tool comes closer to a flank than `body` allows (a flank over the run),
/// the run has no length or [`OPEN_RAMP_LEGS`] legs do not reach `lift`.
fn open_ramp(run: &[Cl], lift: f64, ramp_angle: f64, body: &BodyCheck) -> Option<Vec<(Point3, Vec3)>> {
    let n = run.len();
    let length = run_length(run);
    if n < 2 || length <= 0.0 || lift <= 0.0 || !lift.is_finite() {
        return None;
    }
    let slope = ramp_angle.tan();
    let full = lift / slope;
    // Backwards in time from the start: out along the run and back.
    let (mut out, mut k, mut forward, mut travelled) = (vec![(run[0].place.tip, run[0].place.axis)], 0usize, true, 0.0);
    let mut legs = 0;
    while travelled * slope < lift {
        let next = if forward { k + 1 } else { k - 1 };
        travelled += (run[next].place.tip - run[k].place.tip).norm();
        k = next;
        let h = (travelled * slope).min(lift);
        let p = &run[k].place;
        let tip = p.tip + p.axis * h;
        if body.collides(&tip, &p.axis) {
            return None;
        }
        out.push((tip, p.axis));
        // Turn at the run's end, or where one leg is the whole ramp.
        let turn_at = if forward { k + 1 == n || travelled >= full } else { k == 0 };
        if turn_at {
            forward = !forward;
            legs += 1;
            if legs >= OPEN_RAMP_LEGS && travelled * slope < lift {
                return None;
            }
        }
    }
    out.reverse();
    Some(out)
}

/// How far (mm) beside the stock the tool's body keeps at the start of a
/// side entry, the margin of [`AIR_MARGIN`] too.
pub const SIDE_MARGIN: f64 = AIR_MARGIN;

/// The stock a side entry starts beside: its box, or the blank of
/// [`plan_rough5_in`], and the tool's body as (h0, h1, radius) above its tip
/// (flutes, shank, holder).
struct Sides {
    stock: Aabb3,
    pieces: Vec<(f64, f64, f64)>,
}

impl Sides {
    /// Whether the whole tool with its tip at `tip` along `axis` is at least
    /// [`SIDE_MARGIN`] clear of the stock, sampled every [`AIR_STEP`] up its
    /// body: beside the box (its cross-section's widest reach `rho / cos
    /// tilt`) or above it, or, in `air`, above the blank's top at the axis
    /// and at 16 points on each of the circles of radius `rho + margin`,
    /// `rho` and `rho / 2` (beside the blank its top is `-inf`).
    fn outside(&self, tip: &Point3, axis: &Vec3, air: Option<&Air>) -> bool {
        let tilt = axis.angle(&Vec3::z());
        let (sin, cos) = (tilt.sin(), tilt.cos().max(0.1));
        self.pieces.iter().all(|&(h0, h1, rho)| {
            let n = ((h1 - h0) / AIR_STEP).ceil().max(1.0) as usize;
            (0..=n).all(|k| {
                let c = tip + axis * (h0 + (h1 - h0) * k as f64 / n as f64);
                let low = c.z - rho * sin - SIDE_MARGIN;
                match air {
                    Some(air) => {
                        let ring = (0..16).flat_map(|j| {
                            let a = std::f64::consts::TAU * f64::from(j) / 16.0;
                            [rho + SIDE_MARGIN, rho, 0.5 * rho].map(|f| (c.x + f * a.cos(), c.y + f * a.sin()))
                        });
                        std::iter::once((c.x, c.y)).chain(ring).all(|(x, y)| air.top(x, y) < low)
                    }
                    None => {
                        let b = &self.stock;
                        let dx = (b.min.x - c.x).max(c.x - b.max.x).max(0.0);
                        let dy = (b.min.y - c.y).max(c.y - b.max.y).max(0.0);
                        low > b.max.z || dx.hypot(dy) >= rho / cos + SIDE_MARGIN
                    }
                }
            })
        })
    }
}

/// The tool's body as (h0, h1, radius) above its tip: the flutes, the
/// shank, the holder's segments.
fn body_pieces(cutter: &Cutter) -> Vec<(f64, f64, f64)> {
    let flutes = cutter.flute_length();
    let shank_top = flutes + cutter.shank_length();
    let mut pieces = vec![(0.0, flutes, cutter.radius()), (flutes, shank_top, cutter.shank_radius())];
    let mut h = shank_top;
    for s in cutter.holder() {
        pieces.push((h, h + s.length, s.bottom_radius.max(s.top_radius)));
        h += s.length;
    }
    pieces
}

/// The height where the tool of `c` (its axis kept) meets the level cut
/// before (`above`, placed along the axis through `c`'s guide point): the
/// material over it is gone where that level's passes ran. `None` where that
/// tool misses the level above or is not above `c`'s.
fn local_entry(above: &Placer, c: &Cl) -> Option<f64> {
    let p = above.place(&c.sync.path, &c.place.axis)?;
    let rise = (p.tip - c.place.tip).dot(&c.place.axis);
    (rise > 0.0).then(|| c.place.tip.z + rise * c.place.axis.z)
}

/// Axes tilted less than this (rad, 1 deg) from +Z are left as they are by
/// [`smooth_axes`], and their neighbours too: near the pole the C table's
/// azimuth is the machine's concern ([`Emitter::departs`]).
pub const SMOOTH_MIN_TILT: f64 = std::f64::consts::PI / 180.0;

/// Rounds of [`smooth_axes`].
pub const SMOOTH_ROUNDS: usize = 3;

/// Smooths the tool axes of a run of tools (`axes[k]`, each placed from its
/// guide point by `place`, which returns `None` for a tool that cannot be
/// placed or collides): in [`SMOOTH_ROUNDS`] rounds, each interior axis whose
/// own and neighbours' tilts are at least [`SMOOTH_MIN_TILT`] is replaced by
/// `(u[k-1] + 2 u[k] + u[k+1])` normalised when its tool is placed and clear
/// and it stays within one angular step ([`axis_steps`] of `max_angle_step`,
/// `max_azimuth_step`) of both neighbours. The ends are kept. Returns the new
/// axes and how many changed.
///
/// ```
/// use scallop_geom::Vec3;
/// use scallop_rough5::smooth_axes;
/// let tilt = |deg: f64, az: f64| {
///     let (t, a) = (deg.to_radians(), az.to_radians());
///     Vec3::new(t.sin() * a.cos(), t.sin() * a.sin(), t.cos())
/// };
/// // An axis at 8 deg whose azimuth zigzags by 4 deg.
/// let axes: Vec<Vec3> = (0..9).map(|k| tilt(8.0, if k % 2 == 0 { -5.0 } else { -9.0 })).collect();
/// let (out, changed) = smooth_axes(&axes, (2f64.to_radians(), 5f64.to_radians()), &|_, u| Some(*u));
/// assert!(changed > 0);
/// let swing = |a: &[Vec3]| a.windows(2).map(|w| (w[1].y.atan2(w[1].x) - w[0].y.atan2(w[0].x)).abs()).sum::<f64>();
/// assert!(swing(&out) < 0.5 * swing(&axes));
/// ```
#[must_use]
pub fn smooth_axes(
    axes: &[Vec3],
    (max_angle_step, max_azimuth_step): (f64, f64),
    place: &dyn Fn(usize, &Vec3) -> Option<Vec3>,
) -> (Vec<Vec3>, usize) {
    let mut out = axes.to_vec();
    let n = out.len();
    let tilted = |u: &Vec3| u.angle(&Vec3::z()) >= SMOOTH_MIN_TILT;
    let mut changed = vec![false; n];
    for _ in 0..SMOOTH_ROUNDS {
        for k in 1..n.saturating_sub(1) {
            let (a, u, b) = (out[k - 1], out[k], out[k + 1]);
            if !(tilted(&a) && tilted(&u) && tilted(&b)) {
                continue;
            }
            let v = (a + u * 2.0 + b).normalize();
            if !tilted(&v) || v.angle(&u) < 1e-9 {
                continue;
            }
            let within = |x: &Vec3| axis_steps(x, &v, max_angle_step, max_azimuth_step) <= 1;
            if !(within(&a) && within(&b)) {
                continue;
            }
            if let Some(placed) = place(k, &v) {
                out[k] = placed;
                changed[k] = true;
            }
        }
    }
    let count = changed.iter().filter(|c| **c).count();
    (out, count)
}

/// [`smooth_axes`] on a placed run but its point `keep` (where the tool
/// reached the level, which a closed run's lap starts and ends at): each new
/// axis placed from its pair's guide point and checked against the flanks.
fn smooth_run(placer: &Placer, body: &BodyCheck, run: &mut [Cl], keep: usize, settings: &Rough5Settings) {
    let axes: Vec<Vec3> = run.iter().map(|c| c.place.axis).collect();
    let placed = std::cell::RefCell::new(vec![None; run.len()]);
    let place = |k: usize, u: &Vec3| {
        if k == keep {
            return None;
        }
        let p = placer.place(&run[k].sync.path, u)?;
        if body.collides(&p.tip, &p.axis) {
            return None;
        }
        placed.borrow_mut()[k] = Some(p);
        Some(p.axis)
    };
    let (_, changed) = smooth_axes(&axes, (settings.max_angle_step, settings.max_azimuth_step), &place);
    if changed == 0 {
        return;
    }
    for (c, p) in run.iter_mut().zip(placed.into_inner()) {
        if let Some(p) = p {
            c.place = p;
            c.sync.axis = p.axis;
        }
    }
}

/// The corner radius r of a torus (R of a ball, 0 of a flat tool).
fn corner_radius(cutter: &Cutter) -> f64 {
    match *cutter.shape() {
        scallop_cutter::CutterShape::Bull { corner, .. } => corner,
        scallop_cutter::CutterShape::Ball { radius } => radius,
        _ => 0.0,
    }
}

/// The length of a run's tip polyline (mm).
fn run_length(run: &[Cl]) -> f64 {
    run.windows(2).map(|w| (w[1].place.tip - w[0].place.tip).norm()).sum()
}

/// The placed and checked CL points of the pairs of one pass, split into
/// runs where pairs were dropped.
fn place_pass(placer: &Placer, body: &BodyCheck, pairs: &[SyncPoint]) -> (Vec<Vec<Cl>>, PassReport) {
    place_pass_in(placer, body, None, pairs)
}

/// [`place_pass`], leaving out the CL points in `air` too.
fn place_pass_in(
    placer: &Placer,
    body: &BodyCheck,
    air: Option<&Air>,
    pairs: &[SyncPoint],
) -> (Vec<Vec<Cl>>, PassReport) {
    let in_air = std::sync::atomic::AtomicUsize::new(0);
    let placed: Vec<Option<Cl>> = pairs
        .par_iter()
        .map(|s| {
            let p = placer.place(&s.path, &s.axis())?;
            if air.is_some_and(|a| a.holds(&p)) {
                in_air.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                return None;
            }
            (!body.collides(&p.tip, &p.axis)).then_some(Cl { place: p, sync: *s })
        })
        .collect();
    let in_air = in_air.into_inner();
    let mut runs: Vec<Vec<Cl>> = Vec::new();
    let mut current: Vec<Cl> = Vec::new();
    for c in &placed {
        match c {
            Some(c) => current.push(*c),
            None if current.len() >= 2 => runs.push(std::mem::take(&mut current)),
            None => current.clear(),
        }
    }
    if current.len() >= 2 {
        runs.push(current);
    }
    let kept: Vec<&Cl> = runs.iter().flatten().collect();
    let pitches: Vec<f64> = kept.iter().map(|c| pitch_angle(&c.place.axis, &c.sync.tangent, &c.sync.normal)).collect();
    let n = pitches.len().max(1) as f64;
    let pitch = [
        pitches.iter().copied().fold(f64::INFINITY, f64::min),
        pitches.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        pitches.iter().sum::<f64>() / n,
    ];
    let max_tilt = kept.iter().map(|c| c.place.axis.angle(&Vec3::z())).fold(0.0, f64::max);
    let report = PassReport {
        level: 0,
        pass: 0,
        points: kept.len(),
        dropped: placed.len() - kept.len() - in_air,
        air: in_air,
        corrected: 0,
        spatial: 0,
        translated: 0,
        runs: runs.len(),
        pitch,
        max_tilt,
    };
    (runs, report)
}

/// A tool axis within this of +Z (rad, its tilt) is on the pole of a
/// table-table machine, where the machine holds its C table.
const POLE_TILT: f64 = 1e-6;
/// Largest azimuth change (rad) allowed where a cutting move leaves the pole:
/// the C table turns by it within the first instant of the move, which the
/// tip follows by a chord of at most `r (1 - cos(d / 2))` at `r` mm from the
/// table axis (0.001 mm at 100 mm).
const POLE_DEPARTURE: f64 = 0.5 * std::f64::consts::PI / 180.0;

/// The tilt (rad) at which the axis turns its azimuth before leaving the
/// pole ([`Emitter::pole_turn`]): half a degree, the tool body within 0.4 mm
/// of the vertical one over its 41 mm stick-out.
const POLE_TURN_TILT: f64 = 0.5 * std::f64::consts::PI / 180.0;

/// The azimuth of a tilted axis about +Z, `None` on the pole.
fn azimuth(axis: &Vec3) -> Option<f64> {
    (axis.angle(&Vec3::z()) > POLE_TILT).then(|| axis.y.atan2(axis.x))
}

/// How [`Emitter::enter`] enters a closed run that a helix fits.
#[derive(Debug, Clone, PartialEq)]
enum ClosedEntry {
    /// Down the helix of this index.
    Helix(usize),
    /// Down the ramp along the run.
    Ramp,
    /// Down a ramp back and forth along the run ([`Emitter::shuttle`]): its
    /// tools, top first, and the run's index where it reaches the level.
    Shuttle(Vec<(Point3, Vec3)>, usize),
}

/// Most legs of a ramp back and forth along a closed run tried against its
/// helix and the ramp along it, when the entries are chosen against the
/// machine's dynamics ([`Rough5Settings::entry_dynamics`]).
pub const SHUTTLE_LEGS: usize = 6;

/// Writes the runs as moves.
struct Emitter {
    path: Toolpath,
    safe_z: f64,
    stock_top: f64,
    last: Option<Cl>,
    settings: Rough5Settings,
    /// The radius of the flat of the tool's end (0: no ramp is shortened).
    flat: f64,
    /// The tool's radius (0: no helix).
    radius: f64,
    retracts: usize,
    links: usize,
    entries: EntryCount,
    plunged_at: Vec<Point3>,
    /// The stock box and the tool's body, for the side entries (none
    /// without).
    sides: Option<Sides>,
    /// The azimuth of the last tilted axis written: where a table-table
    /// machine holds its C table while the axis is on the pole.
    held: Option<f64>,
    /// The blank, when the program cuts in one: the approaches and retracts
    /// go at the rapid rate down to and up from where the tool's flutes are
    /// above it.
    air: Option<Air>,
    /// Whether the runs' axes are smoothed ([`Rough5Settings::smooth_axes`]
    /// in [`plan_rough5_in`]; not for a single pass).
    smooth: bool,
    /// The role of the moves pushed now, and of every move pushed.
    role: MoveRole,
    roles: Vec<MoveRole>,
}

impl Emitter {
    fn new(stock_top: f64, safe_z: f64, settings: &Rough5Settings) -> Emitter {
        Emitter {
            path: Toolpath::new(settings.feed),
            safe_z,
            stock_top: stock_top + settings.clearance,
            last: None,
            settings: *settings,
            flat: 0.0,
            radius: 0.0,
            retracts: 0,
            links: 0,
            entries: EntryCount::default(),
            plunged_at: Vec::new(),
            sides: None,
            held: None,
            air: None,
            smooth: false,
            role: MoveRole::Cut,
            roles: Vec::new(),
        }
    }

    fn push(&mut self, kind: MoveKind, to: Point3, axis: Vec3) {
        if let Some(a) = azimuth(&axis) {
            self.held = Some(a);
        }
        self.path.push_with_axis(Move::new(kind, to), axis);
        self.roles.push(self.role);
    }

    /// Sets the role of the moves pushed next; returns the one before.
    fn set_role(&mut self, role: MoveRole) -> MoveRole {
        std::mem::replace(&mut self.role, role)
    }

    /// Whether a cutting move from the pose `from_axis` to `axis` leaves the
    /// pole in another azimuth than the one the machine holds: a table-table
    /// machine would turn its C table within the first instant of the move
    /// (the machine layer refuses it: "joint-space interpolation still
    /// deviates"). Such a move is made through a retract and a rapid, where
    /// the table turns freely.
    fn departs(&self, from_axis: &Vec3, axis: &Vec3) -> bool {
        if azimuth(from_axis).is_some() {
            return false;
        }
        match (azimuth(axis), self.held) {
            (None, _) => false,
            (Some(_), None) => true,
            (Some(a), Some(h)) => {
                let d = (a - h).rem_euclid(std::f64::consts::TAU);
                d.min(std::f64::consts::TAU - d) > POLE_DEPARTURE
            }
        }
    }

    /// The tip and axis of the last move written.
    fn current(&self) -> Option<(Point3, Vec3)> {
        let n = self.path.moves().len();
        (n > 0).then(|| (self.path.moves()[n - 1].to, self.path.axis(n - 1)))
    }

    /// A cutting move to `to` along `axis`: a feed, or, where it would leave
    /// the pole in another azimuth ([`Emitter::departs`]), a retract along
    /// the current axis, a rapid to above `to` along `axis` and a plunge.
    fn feed_to(&mut self, to: Point3, axis: Vec3) {
        match self.current() {
            Some((tip, from_axis)) if self.departs(&from_axis, &axis) => {
                let role = self.set_role(MoveRole::Retract);
                let out = Emitter::above_at(&tip, &from_axis, self.stock_top);
                self.push(MoveKind::Link, out, from_axis);
                let up = self.above(&tip, &from_axis);
                self.push(MoveKind::Retract, up, from_axis);
                self.retracts += 1;
                self.set_role(MoveRole::Approach);
                self.push(MoveKind::Rapid, self.above(&to, &axis), axis);
                self.set_role(MoveRole::Entry);
                self.push(MoveKind::Plunge, to, axis);
                self.set_role(role);
            }
            _ => self.push(MoveKind::Feed, to, axis),
        }
    }

    /// The point of the axis through `tip` at height `z`.
    fn above_at(tip: &Point3, axis: &Vec3, z: f64) -> Point3 {
        let lift = if axis.z > 0.0 { ((z - tip.z) / axis.z).max(0.0) } else { 0.0 };
        tip + axis * lift
    }

    /// The point of the axis through `tip` at the safe height.
    fn above(&self, tip: &Point3, axis: &Vec3) -> Point3 {
        Emitter::above_at(tip, axis, self.safe_z)
    }

    /// Leaves the material along the axis at the cutting feed up to the
    /// stock top (material the levels above could not reach may be left
    /// over the tool), or in a blank until the flutes are above it, then
    /// retracts to the safe height.
    fn retract(&mut self, a: &Placement) {
        let role = self.set_role(MoveRole::Retract);
        let mut out = Emitter::above_at(&a.tip, &a.axis, self.stock_top);
        if let Some(air) = &self.air {
            // At the feed only until the flutes are above the blank.
            let h = air.clear_down_to(&a.tip, &a.axis, (out - a.tip).dot(&a.axis), 0.0);
            out = a.tip + a.axis * h;
        }
        // (In a blank a tool already above it goes up at the rapid rate.)
        if self.air.is_none() || (out - a.tip).norm() > 0.0 {
            self.push(MoveKind::Link, out, a.axis);
        }
        let up = self.above(&a.tip, &a.axis);
        self.push(MoveKind::Retract, up, a.axis);
        self.set_role(role);
    }

    /// Cuts `run`: linked from the previous run when possible (never for
    /// the first run of a level), else entered from the safe height.
    fn cut_run(&mut self, run: &[Cl], entry_z: f64, first_of_level: bool, (placer, body): (&Placer, &BodyCheck)) {
        let linked = !first_of_level && self.last.is_some_and(|a| self.try_link(&a, &run[0], placer, body));
        // The tool is now at run[start].
        let start = if linked { 0 } else { self.enter(run, entry_z, (placer, body)) };
        self.set_role(MoveRole::Cut);
        // The axes smoothed but where the tool stands now (the lap's start and
        // end, and the tool the next link leaves from).
        let smoothed;
        let run = if self.smooth {
            let mut copy = run.to_vec();
            smooth_run(placer, body, &mut copy, start, &self.settings);
            smoothed = copy;
            &smoothed[..]
        } else {
            run
        };
        let n = run.len();
        let closed = n > 2 && (run[0].place.tip - run[n - 1].place.tip).norm() < 1e-9;
        if closed {
            // A full lap from where the tool reached the level.
            for k in 1..n {
                let (b, c) = (&run[(start + k - 1) % (n - 1)], &run[(start + k) % (n - 1)]);
                self.turn_if_leaving(b, c, (placer, body));
                self.feed_to(c.place.tip, c.place.axis);
            }
            self.last = Some(run[start % (n - 1)]);
        } else {
            for k in (start + 1).min(n)..n {
                self.turn_if_leaving(&run[k - 1], &run[k], (placer, body));
                self.feed_to(run[k].place.tip, run[k].place.axis);
            }
            self.last = Some(run[n - 1]);
        }
    }

    /// Where the move from `a` (the tool is there, on the pole) to `b` would
    /// leave the pole in another azimuth than the one held, turns the axis to
    /// `b`'s azimuth first at a small tilt ([`Emitter::pole_turn`]), when it
    /// can; else the move is left to [`Emitter::feed_to`] (a retract).
    fn turn_if_leaving(&mut self, a: &Cl, b: &Cl, checks: (&Placer, &BodyCheck)) {
        if self.departs(&a.place.axis, &b.place.axis)
            && let Some(turn) = self.pole_turn(a, &b.place.axis, checks)
        {
            let role = self.set_role(MoveRole::Turn);
            for p in turn {
                self.push(MoveKind::Feed, p.tip, p.axis);
            }
            self.set_role(role);
        }
    }

    /// The turn of the axis at `a` (on the pole) from the azimuth held to
    /// that of `to`, at the tilt [`POLE_TURN_TILT`]: the axis leaves the pole
    /// in the held azimuth, then its azimuth turns by at most the azimuth
    /// step per move, each axis placed on the level from `a`'s guide point
    /// and checked against the flanks; `None` when no azimuth is held or a
    /// turned tool meets a flank.
    fn pole_turn(&self, a: &Cl, to: &Vec3, (placer, body): (&Placer, &BodyCheck)) -> Option<Vec<Placement>> {
        let (held, target) = (self.held?, azimuth(to)?);
        let d = (target - held + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
        let n = (d.abs() / self.settings.max_azimuth_step).ceil().max(1.0) as usize;
        let t = POLE_TURN_TILT.min(self.settings.max_angle_step);
        (0..=n)
            .map(|k| {
                let f = held + d * (k as f64 / n as f64);
                let axis = Vec3::new(t.sin() * f.cos(), t.sin() * f.sin(), t.cos());
                let p = placer.place(&a.sync.path, &axis)?;
                (!body.collides(&p.tip, &p.axis)).then_some(p)
            })
            .collect()
    }

    /// Retracts along the axis, goes over at the safe height and enters the
    /// run from `entry_z` ([`EntryMode`]): down a helix inside a closed run
    /// ([`Emitter::helix`]), from beside the stock ([`Emitter::side`]), down
    /// a ramp along a closed run, or by a plunge along the axis. In a blank
    /// the tool goes down at the rapid rate to where its flutes reach the
    /// blank. Returns the index of the run where the tool reached the level.
    fn enter(&mut self, run: &[Cl], entry_z: f64, (placer, body): (&Placer, &BodyCheck)) -> usize {
        if let Some(a) = self.last {
            self.retract(&a.place);
            self.retracts += 1;
        }
        let s = run[0].place;
        let lift = Emitter::lift(&s, entry_z);
        let closed = run.len() > 2 && (s.tip - run[run.len() - 1].place.tip).norm() < 1e-9;
        let mode = self.settings.entry;
        if lift > 0.0 {
            if closed && matches!(mode, EntryMode::Auto | EntryMode::Helix) {
                let helices = self.helices(run, entry_z, placer, body);
                match self.cheapest_closed_entry(run, (entry_z, lift), &helices, body) {
                    Some(ClosedEntry::Helix(i)) => {
                        let (start, tips) = &helices[i];
                        let axis = run[*start].place.axis;
                        let tips = &tips[self.above_blank(tips.iter().map(|t| (t, &axis)))..];
                        self.approach(&tips[0], &axis, 0.0);
                        self.set_role(MoveRole::Entry);
                        for tip in &tips[1..] {
                            self.push(MoveKind::Feed, *tip, axis);
                        }
                        self.entries.helix += 1;
                        return *start;
                    }
                    Some(ClosedEntry::Ramp) => {
                        let top = s.tip + s.axis * lift;
                        self.approach(&top, &s.axis, lift);
                        self.set_role(MoveRole::Entry);
                        self.entries.ramp += 1;
                        return self.ramp(run, lift);
                    }
                    Some(ClosedEntry::Shuttle(tools, end)) => return self.shuttle_entry(run, &tools, end, entry_z),
                    None => {}
                }
            }
            if matches!(mode, EntryMode::Auto | EntryMode::Side)
                && let Some(from) = self.side(run, placer, body)
            {
                // Down beside the stock at the rapid rate (in the air all the way).
                let over = self.above(&from, &s.axis);
                self.set_role(MoveRole::Approach);
                self.push(MoveKind::Rapid, over, s.axis);
                self.push(MoveKind::Rapid, from, s.axis);
                self.set_role(MoveRole::Entry);
                self.push(MoveKind::Feed, s.tip, s.axis);
                self.entries.side += 1;
                return 0;
            }
        }
        // An open run is entered down a ramp along its first points where the
        // lifted tool clears the flanks: the approach goes to the ramp's top.
        let ramp = (lift > 0.0 && !closed).then(|| open_ramp(run, lift, self.settings.ramp_angle, body)).flatten();
        if let Some(ramp) = ramp.filter(|r| r.len() > 1) {
            let ramp = &ramp[self.above_blank(ramp.iter().map(|(t, u)| (t, u)))..];
            let (top, axis) = ramp[0];
            self.approach(&top, &axis, lift);
            self.set_role(MoveRole::Entry);
            for (tip, axis) in &ramp[1..] {
                self.push(MoveKind::Feed, *tip, *axis);
            }
            self.entries.ramp += 1;
            return 0;
        }
        // A closed run: down the ramp along it, or back and forth where that
        // takes less time on the machine.
        if closed
            && lift > 0.0
            && let (Some(ClosedEntry::Shuttle(tools, end)), _) = self.cheapest_ramp(run, (entry_z, lift), body)
        {
            return self.shuttle_entry(run, &tools, end, entry_z);
        }
        let start = s.tip + s.axis * lift;
        self.approach(&start, &s.axis, lift);
        self.set_role(MoveRole::Entry);
        if lift <= 0.0 {
            return 0;
        }
        if closed {
            self.entries.ramp += 1;
            return self.ramp(run, lift);
        }
        self.push(MoveKind::Plunge, s.tip, s.axis);
        self.entries.plunge += 1;
        self.plunged_at.push(s.tip);
        0
    }

    /// How many of the first tools of an entry (tips and axes, top first) to
    /// leave out because the next one's flutes are still above the blank
    /// ([`Air::clears`]): the approach comes down at the rapid rate to the
    /// last of them, and the entry starts there. On the impeller the first
    /// level is entered from the blank's highest point, and a helix where the
    /// turned blank is low circled down through the air for 28 mm
    /// (docs/rough5.md, "Where the machine time goes"). At most all but the
    /// last two (an entry keeps one move); none without a blank.
    fn above_blank<'a>(&self, tools: impl Iterator<Item = (&'a Point3, &'a Vec3)>) -> usize {
        let Some(air) = &self.air else { return 0 };
        let tools: Vec<_> = tools.collect();
        let clear = tools.iter().take_while(|(t, u)| air.clears(t, u)).count();
        clear.saturating_sub(1).min(tools.len().saturating_sub(2))
    }

    /// How far (mm) along its axis the tool at `s` is lifted to reach the
    /// height `entry_z` (zero where it is above it).
    fn lift(s: &Placement, entry_z: f64) -> f64 {
        if s.axis.z > 0.0 { ((entry_z - s.tip.z) / s.axis.z).max(0.0) } else { 0.0 }
    }

    /// A rapid to the safe height over `to` along `axis`, then (in a blank)
    /// at the rapid rate down to where the flutes reach the blank, but not
    /// below `to`, then a plunge to `to`. `low` (mm) is how far `to` is above
    /// the level along the axis: in a blank the rapid stops that far above
    /// the tool on the level at the most.
    fn approach(&mut self, to: &Point3, axis: &Vec3, low: f64) {
        self.set_role(MoveRole::Approach);
        let over = self.above(to, axis);
        self.push(MoveKind::Rapid, over, *axis);
        if let Some(air) = &self.air {
            let level = to - axis * low;
            let h = air.clear_down_to(&level, axis, (over - level).dot(axis), low);
            let down = level + axis * h;
            if (down - over).norm() > 0.0 {
                self.push(MoveKind::Rapid, down, *axis);
            }
        }
        // (In a blank the rapid may have reached `to`.)
        if self.air.is_none() || self.current().is_none_or(|(at, _)| (at - to).norm() > 0.0) {
            self.push(MoveKind::Plunge, *to, *axis);
        }
    }

    /// The helix entries of a closed run ([`helix_entry`]): first where the
    /// ramp along the run would reach the level (the lap, and the passes
    /// synchronised from its end, are then those of the ramp's program: a
    /// helix at the run's own start moved them, and with them the runs the
    /// next passes split into; docs/rough5.md, "Entries"), then
    /// at [`HELIX_STARTS`] evenly spaced points from there, each with the
    /// radii of [`HELIX_RADII`] largest first; at the first start where one
    /// fits, the run's index where the helix ends and its tips: the largest
    /// only, or with [`Rough5Settings::entry_dynamics`] every radius that fits
    /// there (largest first). Empty where none fits.
    fn helices(&self, run: &[Cl], entry_z: f64, placer: &Placer, body: &BodyCheck) -> Vec<(usize, Vec<Point3>)> {
        let n = run.len() - 1;
        let tips: Vec<Point3> = run.iter().map(|c| c.place.tip).collect();
        let starts = HELIX_STARTS.min(n);
        let radius = self.radius;
        let first = self.ramp_end(run, Emitter::lift(&run[0].place, entry_z));
        let all = self.settings.entry_dynamics.is_some();
        for j in 0..starts {
            let start = (first + j * n / starts) % n;
            let s = &run[start].place;
            let lift = Emitter::lift(s, entry_z);
            let mut found = Vec::new();
            for f in HELIX_RADII {
                let h = HelixSettings {
                    radius: f * radius,
                    ramp_angle: self.settings.ramp_angle,
                    step: self.settings.step,
                };
                if let Some(helix) = helix_entry(placer, body, (&tips, start), &s.axis, lift, &h) {
                    found.push((start, helix));
                    if !all {
                        break;
                    }
                }
            }
            if !found.is_empty() {
                return found;
            }
        }
        Vec::new()
    }

    /// How a closed run with the helices `helices` ([`Emitter::helices`]) is
    /// entered from `entry_z` (the lift at its start `lift`): `None` without a
    /// helix; the first helix without [`Rough5Settings::entry_dynamics`]; with
    /// them, of the helices, the ramp along the run and the ramps back and
    /// forth along it ([`Emitter::shuttle`], 2 to [`SHUTTLE_LEGS`] legs), the
    /// one whose path takes the least time ([`path_time_estimate`]; a helix
    /// from where it reaches the blank, [`Emitter::above_blank`]), a helix on
    /// a tie. The ramps are candidates only at the ramp angle (not on a loop
    /// within the flat of the tool's end, where [`Emitter::ramp_length`] makes
    /// the ramp steeper), and every ramp ends where the ramp along the run
    /// reaches the level, so the lap is the ramp program's.
    fn cheapest_closed_entry(
        &self,
        run: &[Cl],
        (entry_z, lift): (f64, f64),
        helices: &[(usize, Vec<Point3>)],
        body: &BodyCheck,
    ) -> Option<ClosedEntry> {
        if helices.is_empty() {
            return None;
        }
        let Some(dynamics) = self.settings.entry_dynamics else { return Some(ClosedEntry::Helix(0)) };
        let feed = self.settings.feed;
        let (mut best, mut best_time) = (ClosedEntry::Helix(0), f64::INFINITY);
        for (i, (start, tips)) in helices.iter().enumerate() {
            let axis = run[*start].place.axis;
            let tips = &tips[self.above_blank(tips.iter().map(|t| (t, &axis)))..];
            let t = path_time_estimate(tips, feed, &dynamics);
            if t < best_time {
                (best, best_time) = (ClosedEntry::Helix(i), t);
            }
        }
        match self.cheapest_ramp(run, (entry_z, lift), body) {
            (Some(ramp), t) if t < best_time => Some(ramp),
            _ => Some(best),
        }
    }

    /// Of the ramp along the closed `run` from `lift` above its start and the
    /// ramps back and forth along it ([`Emitter::shuttle`], 2 to
    /// [`SHUTTLE_LEGS`] legs, ending where the ramp along it reaches the
    /// level), the one whose path takes the least time under
    /// [`Rough5Settings::entry_dynamics`] ([`path_time_estimate`]) and its
    /// time; `(None, inf)` without them, or where the ramp along the run is
    /// steeper than the ramp angle (a loop within the flat of the tool's end,
    /// [`Emitter::ramp_length`]).
    fn cheapest_ramp(&self, run: &[Cl], (entry_z, lift): (f64, f64), body: &BodyCheck) -> (Option<ClosedEntry>, f64) {
        let Some(dynamics) = self.settings.entry_dynamics else { return (None, f64::INFINITY) };
        let full = lift / self.settings.ramp_angle.tan();
        if self.ramp_length(run, lift) < full {
            return (None, f64::INFINITY);
        }
        let feed = self.settings.feed;
        let (ramp, end) = self.ramp_tips(run, lift);
        let (mut best, mut best_time) = (ClosedEntry::Ramp, path_time_estimate(&ramp, feed, &dynamics));
        let end_lift = Emitter::lift(&run[end].place, entry_z);
        for legs in 2..=SHUTTLE_LEGS {
            if let Some(tools) = self.shuttle(run, (end, end_lift), legs, body) {
                let from = self.above_blank(tools.iter().map(|(t, u)| (t, u)));
                let tips: Vec<Point3> = tools[from..].iter().map(|(p, _)| *p).collect();
                let t = path_time_estimate(&tips, feed, &dynamics);
                if t < best_time {
                    (best, best_time) = (ClosedEntry::Shuttle(tools, end), t);
                }
            }
        }
        (Some(best), best_time)
    }

    /// Enters `run` down the ramp back and forth `tools` (top first, from
    /// where the tool reaches the blank) ending at the run's point `end`;
    /// returns `end`.
    fn shuttle_entry(&mut self, run: &[Cl], tools: &[(Point3, Vec3)], end: usize, entry_z: f64) -> usize {
        let tools = &tools[self.above_blank(tools.iter().map(|(t, u)| (t, u)))..];
        let (top, axis) = tools[0];
        self.approach(&top, &axis, Emitter::lift(&run[end].place, entry_z));
        self.set_role(MoveRole::Entry);
        for (tip, axis) in &tools[1..] {
            self.push(MoveKind::Feed, *tip, *axis);
        }
        self.entries.ramp += 1;
        end
    }

    /// A ramp back and forth along the closed `run` in `legs` legs of equal
    /// length, from `lift` above its point `end` down to it (tools, top
    /// first): the last leg runs along the run's direction into `end`, each
    /// tool is the run's lifted along its axis by `tan(ramp_angle)` per mm
    /// travelled before `end`; `None` where a lifted tool comes closer to a
    /// flank than `body` allows or a leg has no length. As the open runs'
    /// ramps ([`open_ramp`]): on a long narrow loop whose helix fits only on a
    /// small circle, straight legs at the feed cost less than the circle at
    /// the linear axes' jerk (docs/rough5.md, "Entries against the machine's
    /// dynamics").
    fn shuttle(
        &self,
        run: &[Cl],
        (end, lift): (usize, f64),
        legs: usize,
        body: &BodyCheck,
    ) -> Option<Vec<(Point3, Vec3)>> {
        let n = run.len() - 1;
        let slope = self.settings.ramp_angle.tan();
        if n < 2 || lift <= 0.0 || !lift.is_finite() || legs == 0 {
            return None;
        }
        let leg = lift / slope / legs as f64;
        // Backwards in time from `end`: against the run's direction first.
        let mut out = vec![(run[end].place.tip, run[end].place.axis)];
        let (mut k, mut backward, mut travelled, mut in_leg) = (end, true, 0.0, 0.0);
        let mut steps = 0;
        while travelled * slope < lift {
            let next = if backward { (k + n - 1) % n } else { (k + 1) % n };
            let d = (run[next].place.tip - run[k].place.tip).norm();
            travelled += d;
            in_leg += d;
            k = next;
            let h = (travelled * slope).min(lift);
            let p = &run[k].place;
            let tip = p.tip + p.axis * h;
            if body.collides(&tip, &p.axis) {
                return None;
            }
            out.push((tip, p.axis));
            if in_leg >= leg {
                backward = !backward;
                in_leg = 0.0;
            }
            steps += 1;
            if steps > tol::MAX_PASS_POINTS {
                return None;
            }
        }
        out.reverse();
        Some(out)
    }

    /// The start of a side entry of `run` ([`side_entry`]): within
    /// [`SIDE_REACH_RADII`] tool radii of its first point, the whole tool
    /// outside the stock ([`Sides`]); `None` without a stock.
    fn side(&self, run: &[Cl], placer: &Placer, body: &BodyCheck) -> Option<Point3> {
        let sides = self.sides.as_ref()?;
        let s = &run[0].place;
        let back = run.get(1).map(|c| s.tip - c.place.tip);
        let reach = SIDE_REACH_RADII * self.radius;
        let rise = (self.above(&s.tip, &s.axis) - s.tip).dot(&s.axis);
        let outside = |p: &Point3, u: &Vec3| sides.outside(p, u, self.air.as_ref());
        side_entry(placer, body, &outside, (&s.tip, &s.axis), back, self.settings.step, reach, rise)
    }

    /// The radius of the flat of `cutter`'s end: R for a flat end mill, R - r
    /// for a torus, 0 otherwise.
    fn flat_radius(cutter: &Cutter) -> f64 {
        match *cutter.shape() {
            scallop_cutter::CutterShape::Flat { radius } => radius,
            scallop_cutter::CutterShape::Bull { radius, corner } => radius - corner,
            _ => 0.0,
        }
    }

    /// Ramps down along a closed run from `lift` above it ([`Emitter::ramp_tips`]);
    /// returns the index where the lift reaches zero.
    fn ramp(&mut self, run: &[Cl], lift: f64) -> usize {
        let (tips, end) = self.ramp_tips(run, lift);
        let n = run.len() - 1;
        for (k, tip) in tips.iter().enumerate().skip(1) {
            self.feed_to(*tip, run[k % n].place.axis);
        }
        end
    }

    /// The tips of the ramp along the closed `run` from `lift` above its
    /// start (the top first; the tool at the run's point `k` is lifted along
    /// its axis by the lift left there, which falls linearly over
    /// [`Emitter::ramp_length`]) and the run's index where it reaches the
    /// level.
    fn ramp_tips(&self, run: &[Cl], lift: f64) -> (Vec<Point3>, usize) {
        let n = run.len() - 1;
        let ramp_len = self.ramp_length(run, lift);
        let s0 = &run[0].place;
        let mut tips = vec![s0.tip + s0.axis * lift];
        let (mut s, mut k) = (0.0, 0usize);
        loop {
            let (a, b) = (&run[k % n].place, &run[(k + 1) % n].place);
            s += (b.tip - a.tip).norm();
            k += 1;
            let h = lift * (1.0 - s / ramp_len);
            if h <= 0.0 {
                tips.push(b.tip);
                return (tips, k % n);
            }
            tips.push(b.tip + b.axis * h);
        }
    }

    /// The length (mm) of the ramp along the closed `run` from `lift`: at
    /// most one lap on a loop within the flat of the tool's end round its
    /// centre (the fitting's smallest inner loops, 15 mm long): there the
    /// ramp circled it up to 4 times, the flat covering the loop whatever
    /// the ramp; it is steeper instead.
    fn ramp_length(&self, run: &[Cl], lift: f64) -> f64 {
        let n = run.len() - 1;
        let full = lift / self.settings.ramp_angle.tan();
        let tips = || run[..n].iter().map(|c| c.place.tip.coords);
        let centre = tips().sum::<Vec3>() / n as f64;
        let lap: f64 = (0..n).map(|k| (run[k + 1].place.tip - run[k].place.tip).norm()).sum();
        let within = tips().all(|p| (p - centre).norm() <= self.flat);
        if within && lap > 0.0 { full.min(lap) } else { full }
    }

    /// The index of the closed `run` where its ramp from `lift` reaches the
    /// level ([`Emitter::ramp`]).
    fn ramp_end(&self, run: &[Cl], lift: f64) -> usize {
        let n = run.len() - 1;
        let ramp_len = self.ramp_length(run, lift);
        let (mut s, mut k) = (0.0, 0usize);
        while k < tol::MAX_PASS_POINTS {
            s += (run[(k + 1) % n].place.tip - run[k % n].place.tip).norm();
            k += 1;
            if s >= ramp_len {
                break;
            }
        }
        k % n
    }

    /// Links `a` to `b` on the level when the link is short, every point of
    /// it placed and clear of the flanks; pushes the link moves.
    fn try_link(&mut self, a: &Cl, b: &Cl, placer: &Placer, body: &BodyCheck) -> bool {
        let dist = (b.place.tip - a.place.tip).norm();
        if dist > self.settings.link_max {
            return false;
        }
        // Leaving the pole in another azimuth: the turn at `a` first.
        let turn = if self.departs(&a.place.axis, &b.place.axis) {
            let Some(turn) = self.pole_turn(a, &b.place.axis, (placer, body)) else { return false };
            turn
        } else {
            Vec::new()
        };
        let s = &self.settings;
        let turns = axis_steps(&a.place.axis, &b.place.axis, s.max_angle_step, s.max_azimuth_step);
        let n = ((dist / s.step).ceil() as usize).max(turns);
        let mut moves = Vec::with_capacity(n);
        for i in 1..=n {
            let w = i as f64 / n as f64;
            let guide = a.sync.path + (b.sync.path - a.sync.path) * w;
            let axis = interpolate_axis(&a.place.axis, &b.place.axis, w);
            let Some(p) = placer.place(&guide, &axis) else { return false };
            if body.collides(&p.tip, &p.axis) {
                return false;
            }
            moves.push(p);
        }
        // A vertical link within the thinning's chord of its chord is one block.
        let chord = tol::THIN_CHORD_ALLOWANCES * s.guides.flank_allowance;
        let straight = s.round_corners
            && moves.iter().all(|p| p.axis.angle(&Vec3::z()) <= tol::ANGLE_EPS)
            && moves
                .last()
                .is_some_and(|end| moves.iter().all(|p| off_segment(&p.tip, &a.place.tip, &end.tip) <= chord));
        if straight {
            moves.drain(..moves.len() - 1);
        }
        self.set_role(MoveRole::Turn);
        for p in turn {
            self.push(MoveKind::Feed, p.tip, p.axis);
        }
        self.set_role(MoveRole::Link);
        for p in moves {
            self.push(MoveKind::Link, p.tip, p.axis);
        }
        self.links += 1;
        true
    }

    fn finish(&mut self) {
        if let Some(a) = self.last {
            self.retract(&a.place);
        }
    }
}
