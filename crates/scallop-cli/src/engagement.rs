//! `scallop engagement`: evaluates a 2.5D pocket program (G-code or cutter
//! locations) on its pocket with the simulator's engagement measure
//! (docs/simulation.md, "Engagement"), the same way for any planner's output.

use std::path::{Path, PathBuf};

use clap::Args;
use scallop_analysis::MachineLimits;
use scallop_geom::Point2;
use scallop_io::cl::read_cl;
use scallop_io::gcode::{GcodeOptions, read_gcode, read_gcode_arcs};
use scallop_sim::{EngagementOptions, EngagementReport, Pocket, engagement_angle, pocket_engagement};
use scallop_strategy::{Boundary, FinishingParams, Pattern, lookahead_profile, lookahead_time};
use scallop_toolpath::{MoveKind, Toolpath};
use serde::{Deserialize, Serialize};

use crate::input::read_text;
use crate::output::{print_json, print_text, write_atomic};
use crate::{CliResult, Failure};

/// Arguments of `scallop engagement`.
#[derive(Args, Debug)]
pub struct EngagementArgs {
    /// The pocket: JSON `{"units":"mm","rings":[[[x,y],...],...]}`, the outer boundary first, then islands.
    #[arg(long)]
    pocket: PathBuf,
    /// The program: G-code (.nc, .ngc, .gcode, .tap) or cutter locations (.csv).
    #[arg(long)]
    program: PathBuf,
    /// Tool diameter D (mm).
    #[arg(long)]
    tool_diameter: f64,
    /// Target radial depth as a fraction of D: the target angle is arccos(1 - 2 F).
    #[arg(long)]
    stepover: f64,
    /// Moves whose ends lie at or below this Z cut (mm); default: every move but rapids.
    #[arg(long, allow_hyphen_values = true)]
    cut_below: Option<f64>,
    /// Cutting feed of the cycle time (mm/min), the same for every program compared; the
    /// acceleration and jerk are those of scallop's default machine.
    #[arg(long, default_value_t = 5000.0)]
    feed: f64,
    /// Rapid rate of the cycle time (mm/min).
    #[arg(long, default_value_t = 10_000.0)]
    rapid: f64,
    /// Corner blending tolerance of the look-ahead time model (mm).
    #[arg(long, default_value_t = 0.01)]
    blend_tolerance: f64,
    /// Cell side of the raster of older cuts and of the uncut area (mm).
    #[arg(long, default_value_t = EngagementOptions::default().resolution)]
    resolution: f64,
    /// Tool reaching beyond a wall by more than this is a gouge (mm).
    #[arg(long, default_value_t = EngagementOptions::default().gouge_tolerance)]
    gouge_tolerance: f64,
    /// Strip along the walls not counted as reachable (mm).
    #[arg(long, default_value_t = EngagementOptions::default().uncut_margin)]
    uncut_margin: f64,
    /// Also write each move's largest engagement as CSV (`move,kind,x0,y0,x1,y1,z,phi_deg`),
    /// for plotting the program coloured by engagement.
    #[arg(long)]
    moves: Option<PathBuf>,
    /// Also write each move of the program as read (its XY arcs kept) with the
    /// jerk-limited model's time and speeds as CSV
    /// (`move,kind,x0,y0,x1,y1,z,seconds,entry_mm_s,peak_mm_s,exit_mm_s`): where the
    /// cycle time goes.
    #[arg(long)]
    feeds: Option<PathBuf>,
    /// Print JSON on stdout.
    #[arg(long)]
    json: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PocketFile {
    units: String,
    rings: Vec<Vec<[f64; 2]>>,
}

/// The figures, in degrees, mm, mm^2, shares in percent, seconds.
#[derive(Serialize)]
struct Figures {
    command: &'static str,
    pocket: String,
    program: String,
    tool_diameter_mm: f64,
    stepover: f64,
    target_deg: f64,
    phi_p50_deg: f64,
    phi_p95_deg: f64,
    phi_p99_deg: f64,
    phi_max_deg: f64,
    phi_max_at: Option<[f64; 2]>,
    entry_phi_max_deg: f64,
    over_mm: f64,
    over_percent: f64,
    slot_mm: f64,
    air_percent: f64,
    link_percent: f64,
    cutting_mm: f64,
    link_mm: f64,
    retracts: usize,
    entries: usize,
    max_penetration_mm: f64,
    pocket_area_mm2: f64,
    reachable_area_mm2: f64,
    uncut_mm2: f64,
    feed_mm_min: f64,
    time_length_over_feed_s: f64,
    time_jerk_limited_s: f64,
    samples: usize,
    moves: usize,
    seconds: f64,
}

fn read_pocket(path: &Path) -> CliResult<Pocket> {
    let text = read_text(path, "the pocket")?;
    let name = path.display();
    let file: PocketFile = serde_json::from_str(&text).map_err(|e| {
        Failure::rejected(format!("{name}: {e}; give {{\"units\":\"mm\",\"rings\":[[[x,y],...],...]}}"))
    })?;
    if file.units != "mm" {
        return Err(Failure::rejected(format!("{name}: units \"{}\": only \"mm\" is read", file.units)));
    }
    let rings = file.rings.iter().map(|r| r.iter().map(|p| Point2::new(p[0], p[1])).collect()).collect();
    Pocket::new(rings).map_err(|e| Failure::rejected(format!("{name}: {e}")))
}

/// The program's moves with its arcs as chords (for the engagement), and
/// with its XY arcs kept (for the cycle time: an arc is one move along its
/// circle, not hundreds of chords).
fn read_program(path: &Path) -> CliResult<(Toolpath, Toolpath)> {
    let text = read_text(path, "the program")?;
    let name = path.display();
    let csv = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("csv"));
    let read = if csv {
        read_cl(&text, 1000.0).map(|p| (p.clone(), p)).map_err(|e| e.to_string())
    } else {
        read_gcode(&text, &GcodeOptions::default())
            .and_then(|chords| Ok((chords, read_gcode_arcs(&text, &GcodeOptions::default())?)))
            .map_err(|e| e.to_string())
    };
    read.map_err(|e| Failure::rejected(format!("{name}: {e}")))
}

/// Cycle time of the look-ahead jerk-limited model (scallop-strategy's model
/// (b)) at one feed for every cutting move on `arcs` (the program with its
/// XY arcs kept), and the plain length / feed on `path` (its arcs as chords).
fn cycle_times(path: &Toolpath, arcs: &Toolpath, args: &EngagementArgs) -> CliResult<(f64, f64)> {
    let params = time_params(args)?;
    let plain: f64 = path
        .moves()
        .windows(2)
        .map(|w| {
            let rate = if matches!(w[1].kind, MoveKind::Rapid | MoveKind::Retract) { args.rapid } else { args.feed };
            (w[1].to - w[0].to).norm() / rate * 60.0
        })
        .sum();
    Ok((plain, lookahead_time(arcs, &params).total()))
}

/// The time model's settings at the command's feed, rapid rate and blend tolerance.
fn time_params(args: &EngagementArgs) -> CliResult<FinishingParams> {
    let machine = MachineLimits { feed: args.feed / 60.0, ..MachineLimits::default() };
    let params = FinishingParams {
        direction: 0.0,
        pattern: Pattern::Zigzag,
        scallop_height: 0.01,
        boundary: Boundary::ContactInside,
        max_step: 1.0,
        clearance: 1.0,
        machine,
        plunge_feed: args.feed / 60.0,
        rapid_rate: args.rapid / 60.0,
        sharp_corner: 0.5,
        blend_tolerance: args.blend_tolerance,
    };
    params.validate().map_err(|e| Failure::rejected(format!("--feed, --rapid, --blend-tolerance: {e}")))?;
    Ok(params)
}

fn figures(args: &EngagementArgs, r: &EngagementReport, times: (f64, f64), path: &Toolpath, seconds: f64) -> Figures {
    let share = |part: f64, all: f64| if all > 0.0 { 100.0 * part / all } else { 0.0 };
    Figures {
        command: "engagement",
        pocket: args.pocket.display().to_string(),
        program: args.program.display().to_string(),
        tool_diameter_mm: args.tool_diameter,
        stepover: args.stepover,
        target_deg: r.target.to_degrees(),
        phi_p50_deg: r.p50.to_degrees(),
        phi_p95_deg: r.p95.to_degrees(),
        phi_p99_deg: r.p99.to_degrees(),
        phi_max_deg: r.max.to_degrees(),
        phi_max_at: r.max_at.map(|(p, _)| [p.x, p.y]),
        entry_phi_max_deg: r.entry_max.to_degrees(),
        over_mm: r.over_length,
        over_percent: share(r.over_length, r.cutting_length),
        slot_mm: r.slot_length,
        air_percent: 100.0 * r.air_share(),
        link_percent: 100.0 * r.link_share(),
        cutting_mm: r.cutting_length,
        link_mm: r.link_length,
        retracts: r.retracts,
        entries: r.entries,
        max_penetration_mm: r.max_penetration,
        pocket_area_mm2: r.pocket_area,
        reachable_area_mm2: r.reachable_area,
        uncut_mm2: r.uncut_area,
        feed_mm_min: args.feed,
        time_length_over_feed_s: times.0,
        time_jerk_limited_s: times.1,
        samples: r.samples,
        moves: path.moves().len(),
        seconds,
    }
}

fn text(f: &Figures) -> String {
    format!(
        "engagement of {} on {} (D {} mm, target {:.1} deg)\n\
         phi p50 / p95 / p99 / max: {:.1} / {:.1} / {:.1} / {:.1} deg (entries: max {:.1} deg)\n\
         over 1.2 x target: {:.1} mm ({:.2} %), full slot: {:.1} mm\n\
         air cut: {:.2} % of {:.0} mm cutting; tool-down links: {:.1} % ({:.0} mm); retracts {}, entries {}\n\
         uncut reachable: {:.2} mm2 of {:.0} mm2 reachable; deepest reach beyond a wall: {:.3} mm\n\
         cycle time at {} mm/min: {:.1} s jerk-limited ({:.1} s length / feed)\n",
        f.program,
        f.pocket,
        f.tool_diameter_mm,
        f.target_deg,
        f.phi_p50_deg,
        f.phi_p95_deg,
        f.phi_p99_deg,
        f.phi_max_deg,
        f.entry_phi_max_deg,
        f.over_mm,
        f.over_percent,
        f.slot_mm,
        f.air_percent,
        f.cutting_mm,
        f.link_percent,
        f.link_mm,
        f.retracts,
        f.entries,
        f.uncut_mm2,
        f.reachable_area_mm2,
        f.max_penetration_mm,
        f.feed_mm_min,
        f.time_jerk_limited_s,
        f.time_length_over_feed_s,
    )
}

/// One CSV row per move after the first: its kind, XY ends, end height and
/// largest engagement (degrees, 0 where it cuts nothing).
fn write_moves(w: &mut impl std::io::Write, path: &Toolpath, report: &EngagementReport) -> std::io::Result<()> {
    writeln!(w, "move,kind,x0,y0,x1,y1,z,phi_deg")?;
    let moves = path.moves();
    for (i, pair) in moves.windows(2).enumerate() {
        let phi = report.move_phi.get(i + 1).copied().unwrap_or(0.0).to_degrees();
        let (a, b) = (pair[0].to, pair[1].to);
        writeln!(w, "{},{:?},{},{},{},{},{},{:.2}", i + 1, pair[1].kind, a.x, a.y, b.x, b.y, b.z, phi)?;
    }
    Ok(())
}

/// One CSV row per move of `arcs` after the first: its kind, XY ends, end
/// height, and the look-ahead model's duration and entry, peak and exit
/// speeds (`scallop_strategy::lookahead_profile`).
fn write_feeds(w: &mut impl std::io::Write, arcs: &Toolpath, params: &FinishingParams) -> std::io::Result<()> {
    writeln!(w, "move,kind,x0,y0,x1,y1,z,seconds,entry_mm_s,peak_mm_s,exit_mm_s")?;
    let moves = arcs.moves();
    let profile = lookahead_profile(arcs, params);
    for (i, pair) in moves.windows(2).enumerate() {
        let f = profile.get(i + 1).copied().unwrap_or_default();
        let (a, b) = (pair[0].to, pair[1].to);
        writeln!(
            w,
            "{},{:?},{},{},{},{},{},{:.5},{:.2},{:.2},{:.2}",
            i + 1,
            pair[1].kind,
            a.x,
            a.y,
            b.x,
            b.y,
            b.z,
            f.duration,
            f.entry,
            f.peak,
            f.exit
        )?;
    }
    Ok(())
}

/// `scallop engagement`.
pub fn run(args: &EngagementArgs) -> CliResult<()> {
    let start = std::time::Instant::now();
    if !(args.tool_diameter.is_finite() && args.tool_diameter > 0.0) {
        return Err(Failure::rejected(format!("--tool-diameter {}: give a diameter > 0 mm", args.tool_diameter)));
    }
    if !(args.stepover > 0.0 && args.stepover <= 1.0) {
        return Err(Failure::rejected(format!("--stepover {}: give a fraction of D in (0, 1]", args.stepover)));
    }
    let pocket = read_pocket(&args.pocket)?;
    let (path, arcs) = read_program(&args.program)?;
    let radius = args.tool_diameter / 2.0;
    let options = EngagementOptions {
        resolution: args.resolution,
        cut_below: args.cut_below,
        gouge_tolerance: args.gouge_tolerance,
        uncut_margin: args.uncut_margin,
        ..EngagementOptions::default()
    };
    let target = engagement_angle(args.stepover * args.tool_diameter, radius);
    let report = pocket_engagement(&pocket, radius, &path, target, &options)
        .map_err(|e| Failure::rejected(format!("{}: {e}", args.program.display())))?;
    let times = cycle_times(&path, &arcs, args)?;
    let f = figures(args, &report, times, &path, start.elapsed().as_secs_f64());
    if let Some(file) = &args.moves {
        write_atomic(file, |w| write_moves(w, &path, &report))?;
    }
    if let Some(file) = &args.feeds {
        let params = time_params(args)?;
        write_atomic(file, |w| write_feeds(w, &arcs, &params))?;
    }
    if args.json { print_json(&f) } else { print_text(&text(&f)) }
}
