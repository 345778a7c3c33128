//! `scallop pocket`: the clearing of a 2D pocket (docs/roughing.md), written
//! as G-code (`program.nc`, XY arcs as G2/G3) and a CL file (`toolpath.csv`).
//!
//! The region file is JSON: `{"units": "mm", "rings": [[[x, y], ...], ...]}`,
//! the first ring the pocket's wall (the boundary of the material to clear),
//! the others islands; the tool centre stays R inside the wall and R outside
//! the islands.

use std::io::Write;
use std::path::PathBuf;

use clap::{Args, ValueEnum};
use scallop_contour::{Contour, Region};
use scallop_post::{Dialect, ProgramInfo, write_fitted};
use scallop_rough::{ClearOptions, Direction, Motion, Pattern, pocket_toolpath};
use scallop_toolpath::{FittedPath, MoveKind};
use serde::{Deserialize, Serialize};

use crate::output::{print_report, write_atomic};
use crate::{CliResult, Failure};

/// Clearing patterns of `scallop pocket`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum PatternArg {
    /// Contour-parallel offsets, inside-out, then the wall contour.
    Offset,
    /// Contour-parallel offsets with loops where a ring would cut a slot.
    OffsetLoops,
    /// Engagement-controlled clearing: a front grown from the deepest point.
    Adaptive,
}

/// Arguments of `scallop pocket`.
#[derive(Args, Debug)]
pub struct PocketArgs {
    /// Region file (JSON): `{"units": "mm", "rings": [[[x, y], ...], ...]}`, the wall first, then islands.
    #[arg(long)]
    region: PathBuf,
    /// Flat end mill diameter D (mm).
    #[arg(long, allow_hyphen_values = true)]
    tool_diameter: f64,
    /// Radial depth of cut as a fraction of D, in (0, 0.5].
    #[arg(long, default_value_t = 0.2, allow_hyphen_values = true)]
    stepover: f64,
    /// Clearing pattern.
    #[arg(long, value_enum, default_value = "offset")]
    pattern: PatternArg,
    /// Depth of the pocket below z = 0 (mm).
    #[arg(long, default_value_t = 1.0, allow_hyphen_values = true)]
    depth: f64,
    /// Cutting feed (mm/min).
    #[arg(long, default_value_t = 1000.0, allow_hyphen_values = true)]
    feed: f64,
    /// Height of rapids above z = 0 (mm).
    #[arg(long, default_value_t = 5.0, allow_hyphen_values = true)]
    clearance: f64,
    /// Chord tolerance of region booleans and link checks (mm).
    #[arg(long, default_value_t = 1e-3, allow_hyphen_values = true)]
    tolerance: f64,
    /// Conventional milling instead of climb.
    #[arg(long, conflicts_with = "both_ways")]
    conventional: bool,
    /// Adaptive pattern: passes both ways, climb and conventional in turn
    /// where a pass can go back along the frontier the last one left (the
    /// rings climb).
    #[arg(long)]
    both_ways: bool,
    /// Output folder for `program.nc` and `toolpath.csv`.
    #[arg(short, long)]
    output: PathBuf,
    /// Print a JSON summary.
    #[arg(long)]
    json: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RegionFile {
    units: String,
    rings: Vec<Vec<[f64; 2]>>,
}

#[derive(Serialize)]
struct PocketReport {
    command: &'static str,
    region: String,
    tool_diameter_mm: f64,
    stepover: f64,
    passes: usize,
    links: usize,
    retracts: usize,
    helical_entries: usize,
    arcs: usize,
    feed_length_mm: f64,
    link_length_mm: f64,
    planning_seconds: f64,
    written: Vec<String>,
}

/// The tool-centre region of the pocket in `file` for a tool of radius `r`.
fn tool_centre_region(text: &str, r: f64) -> CliResult<Region> {
    let file: RegionFile = serde_json::from_str(text)
        .map_err(|e| Failure::rejected(format!("region file: {e} (see scallop pocket --help)")))?;
    let scale = match file.units.as_str() {
        "mm" => 1.0,
        "in" => 25.4,
        other => return Err(Failure::rejected(format!("region file: units `{other}`: give \"mm\" or \"in\""))),
    };
    let mut rings = Vec::with_capacity(file.rings.len());
    for (k, ring) in file.rings.iter().enumerate() {
        if ring.len() < 3 {
            return Err(Failure::rejected(format!("region file: ring {k} has fewer than 3 points")));
        }
        let pts: Vec<[f64; 2]> = ring.iter().map(|p| [p[0] * scale, p[1] * scale]).collect();
        let c = Contour::polygon(&pts, true).map_err(|e| Failure::rejected(format!("region file: ring {k}: {e}")))?;
        rings.push(c);
    }
    let mut it = rings.into_iter();
    let outer = it.next().ok_or_else(|| Failure::rejected("region file: no ring; give the pocket's wall first"))?;
    let wall = Region::with_holes(outer, it.collect())
        .map_err(|e| Failure::rejected(format!("region file: the wall (ring 0): {e}")))?;
    Ok(wall.offset(r))
}

/// `scallop pocket`.
pub fn run(args: &PocketArgs) -> CliResult<()> {
    let d = args.tool_diameter;
    let positive = |v: f64| v.is_finite() && v > 0.0;
    if !(positive(d) && positive(args.stepover) && args.stepover <= 0.5 && positive(args.depth)) {
        return Err(Failure::rejected(
            "--tool-diameter and --depth must be > 0 mm and --stepover in (0, 0.5] (a fraction of D)",
        ));
    }
    if !positive(args.feed) || !positive(args.clearance) || !positive(args.tolerance) {
        return Err(Failure::rejected("--feed, --clearance and --tolerance must be > 0"));
    }
    let text = std::fs::read_to_string(&args.region)
        .map_err(|e| Failure::Io(anyhow::anyhow!("{}: {e}", args.region.display())))?;
    let start = std::time::Instant::now();
    let region = tool_centre_region(&text, d / 2.0)?;
    if region.is_empty() {
        return Err(Failure::rejected(format!(
            "{}: the tool (D {d} mm) fits nowhere in the pocket; give a smaller --tool-diameter",
            args.region.display()
        )));
    }
    let direction = if args.conventional {
        Direction::Conventional
    } else if args.both_ways {
        Direction::Both
    } else {
        Direction::Climb
    };
    let pattern = match args.pattern {
        PatternArg::Offset => Pattern::Offset,
        PatternArg::OffsetLoops => Pattern::OffsetLoops,
        PatternArg::Adaptive => Pattern::Adaptive,
    };
    let options = ClearOptions {
        tool_radius: d / 2.0,
        stepover: args.stepover * d,
        direction,
        chord_tolerance: args.tolerance,
        pattern,
    };
    let motion = Motion { clearance_z: args.clearance, feed: args.feed };
    let plan = pocket_toolpath(&region, &options, -args.depth, 0.0, &motion)
        .map_err(|e| Failure::rejected(format!("{}: {e}", args.region.display())))?;
    let planning_seconds = start.elapsed().as_secs_f64();
    let fitted = FittedPath::with_xy_arcs(&plan.toolpath);
    let (program, cl) = (args.output.join("program.nc"), args.output.join("toolpath.csv"));
    let name = if pattern == Pattern::Adaptive { "adaptive" } else { "offset" };
    let comments =
        [format!("pocket {}: flat D{d} mm, stepover {} D, {name} clearing", args.region.display(), args.stepover)];
    let refs: Vec<&str> = comments.iter().map(String::as_str).collect();
    let info = ProgramInfo { program: "1".into(), tool: 1, spindle: 0.0, indexed_rotaries: Vec::new() };
    let dialect = Dialect::builtin("linuxcnc").map_err(|e| Failure::Io(anyhow::anyhow!("{e}")))?;
    write_atomic(&program, |w| write_fitted(&fitted, &dialect, &info, &refs, w))?;
    write_atomic(&cl, |w| w.write_all(scallop_io::cl::write_cl(&plan.toolpath).as_bytes()))?;
    let report = PocketReport {
        command: "pocket",
        region: args.region.display().to_string(),
        tool_diameter_mm: d,
        stepover: args.stepover,
        passes: plan.passes,
        links: plan.links,
        retracts: plan.retracts,
        helical_entries: plan.helices,
        arcs: fitted.arcs(),
        feed_length_mm: plan.toolpath.length(MoveKind::Feed),
        link_length_mm: plan.toolpath.length(MoveKind::Link),
        planning_seconds,
        written: vec![program.display().to_string(), cl.display().to_string()],
    };
    print_report(&report, args.json, |r| {
        format!(
            "{} passes, {} tool-down links, {} retracts, {} helical entries, {} arcs; feed {:.1} mm, links {:.1} mm; planned in {:.3} s\n  wrote {}\n",
            r.passes,
            r.links,
            r.retracts,
            r.helical_entries,
            r.arcs,
            r.feed_length_mm,
            r.link_length_mm,
            r.planning_seconds,
            r.written.join(", ")
        )
    })
}
