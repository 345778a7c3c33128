//! `scallop guides`: the guide curves of 5-axis roughing by guide curves
//! (docs/guides.md, docs/guides-curves.md) on one of the test parts: the
//! axial levels, the limit, path and tilt curves, written as OBJ meshes, a
//! CSV of curve points, a JSON summary and a report page with a picture.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

use clap::{Args, ValueEnum};
use scallop_geom::Point3;
use scallop_guides::{Curve, GuideSet, GuideSettings, build_guides};
use scallop_mesh::TriMesh;
use scallop_parts::{FaceTag, TestPart, closed_pocket, fitting_pocket, impeller_channel, svg_view_with_lines};
use serde::Serialize;

use crate::output::{print_json, print_text, with_written};
use crate::outset::OutputSet;
use crate::{CliResult, Failure};

/// The test parts (docs/guides.md).
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum PartArg {
    /// The closed pocket with drafts and undercuts, 100 x 100 x 35 mm.
    Pocket,
    /// The impeller channel between two twisted blades (open pocket).
    Impeller,
    /// The closed non-convex fitting pocket with ribs.
    Fitting,
}

/// The level and curve steps, shared by `scallop guides` and `scallop rough5`.
#[derive(Args, Debug)]
pub struct LevelArgs {
    /// Axial depth of cut a_p between levels (mm).
    #[arg(long, default_value_t = 4.0)]
    pub ap: f64,
    /// Radial engagement a_e between path curves (mm).
    #[arg(long, default_value_t = 4.5)]
    pub ae: f64,
    /// Voxel size of the level fields (mm).
    #[arg(long, default_value_t = 1.0)]
    pub voxel: f64,
}

/// Arguments of `scallop guides`.
#[derive(Args, Debug)]
pub struct GuidesArgs {
    /// Test part.
    #[arg(long, value_enum, default_value = "pocket")]
    part: PartArg,
    /// Tool radius R (mm; the thesis's torus R 5 r 1.5).
    #[arg(long, default_value_t = 5.0)]
    tool_radius: f64,
    /// Material left on the flanks (mm).
    #[arg(long, default_value_t = 0.5)]
    flank_allowance: f64,
    #[command(flatten)]
    levels: LevelArgs,
    /// Output folder.
    #[arg(short, long)]
    output: PathBuf,
    /// Print a JSON summary on stdout.
    #[arg(long)]
    json: bool,
}

#[derive(Serialize)]
struct LevelSummary {
    distance_mm: f64,
    triangles: usize,
    limit_loops: usize,
    limit_open: usize,
    path_curves: usize,
    splits: usize,
    /// Degeneracy zones of the offsets (1: no split).
    zones: usize,
    /// Limit loops closed by virtual flanks (open pocket).
    closed_by_virtual_flanks: usize,
    /// Why an open pocket could not be closed, if so.
    closing_error: Option<String>,
}

#[derive(Serialize)]
struct PairSummary {
    lower_level: usize,
    /// Degeneracy zone on the lower and on the upper level (null: no partner).
    zones: [Option<usize>; 2],
    paired: bool,
    error: Option<String>,
    steps: usize,
    path_spacing_mm: f64,
    tilt_spacing_mm: f64,
}

#[derive(Serialize)]
struct GuidesSummary {
    command: &'static str,
    part: String,
    triangles: usize,
    settings: [f64; 5],
    levels: Vec<LevelSummary>,
    pairs: Vec<PairSummary>,
    seconds: f64,
}

/// Runs `scallop guides`.
///
/// # Errors
/// Bad settings or a part whose levels cannot be extracted (exit 1); I/O.
pub fn run(args: &GuidesArgs) -> CliResult<()> {
    let clock = Instant::now();
    let (name, part) = test_part(args.part)?;
    let faces = |tags: &[FaceTag]| part.faces(tags).map_err(|e| Failure::rejected(format!("{name}: {e}")));
    let bottom = faces(&[FaceTag::Bottom])?;
    let flanks = faces(&[FaceTag::Flank])?;
    let top = faces(&[FaceTag::Top])?;
    let settings = GuideSettings {
        tool_radius: args.tool_radius,
        flank_allowance: args.flank_allowance,
        axial_step: args.levels.ap,
        radial_step: args.levels.ae,
        voxel: args.levels.voxel,
        depth: pocket_depth(&bottom, &top),
    };
    let set = build_guides(&bottom, &flanks, &settings)
        .map_err(|e| Failure::rejected(format!("{name}: {e} (settings: --tool-radius, --ap, --ae, --voxel)")))?;
    let summary = summarise(name, &part, &settings, &set, clock.elapsed().as_secs_f64());
    let mut out = OutputSet::begin(&args.output, "guides")?;
    for (k, level) in set.levels.iter().enumerate() {
        out.write(&format!("level_{k:02}.obj"), obj_text(level.support.mesh()).as_bytes())?;
    }
    out.write("flank_offset.obj", obj_text(&set.flank_offset).as_bytes())?;
    out.write("curves.csv", curves_csv(&set).as_bytes())?;
    let json = serde_json::to_string_pretty(&summary).map_err(|e| Failure::Io(e.into()))?;
    out.write("guides.json", json.as_bytes())?;
    let picture = picture(&part, &set);
    out.write("guides.svg", picture.as_bytes())?;
    out.write("report.html", report_html(&summary, &picture).as_bytes())?;
    let written = out.commit()?;
    if args.json {
        return print_json(&with_written(&summary, &written)?);
    }
    let mut text = format!("{name}: {} levels in {:.2} s\n", summary.levels.len(), summary.seconds);
    for (k, l) in summary.levels.iter().enumerate() {
        let _ = writeln!(
            text,
            "  level {k} at {:.1} mm: {} limit loop(s) ({} closed by virtual flanks), {} open chains, {} path curves, {} zones",
            l.distance_mm, l.limit_loops, l.closed_by_virtual_flanks, l.limit_open, l.path_curves, l.zones
        );
    }
    for p in &summary.pairs {
        let _ = writeln!(
            text,
            "  levels {} and {}, zones {:?}: {}",
            p.lower_level,
            p.lower_level + 1,
            p.zones,
            p.error.clone().unwrap_or_else(|| format!("{} steps paired", p.steps))
        );
    }
    let _ = writeln!(text, "  written to {}", args.output.display());
    print_text(&text)
}

pub(crate) fn test_part(which: PartArg) -> CliResult<(&'static str, TestPart)> {
    let made = match which {
        PartArg::Pocket => ("closed pocket", closed_pocket(&Default::default())),
        PartArg::Impeller => ("impeller channel", impeller_channel(&Default::default())),
        PartArg::Fitting => ("fitting pocket", fitting_pocket(&Default::default())),
    };
    let (name, part) = made;
    Ok((name, part.map_err(|e| Failure::Io(anyhow::anyhow!("{name}: {e}")))?))
}

/// The height of the pocket above its bottom: the largest distance from a
/// vertex of the (crossable) top faces to the bottom faces.
fn pocket_depth(bottom: &TriMesh, top: &TriMesh) -> f64 {
    let q = scallop_mesh::MeshQuery::new(bottom);
    top.vertices().iter().map(|v| (q.closest_point(v).point - v).norm()).fold(0.0, f64::max)
}

fn summarise(name: &str, part: &TestPart, s: &GuideSettings, set: &GuideSet, seconds: f64) -> GuidesSummary {
    let levels = set
        .levels
        .iter()
        .map(|l| LevelSummary {
            distance_mm: l.distance,
            triangles: l.support.mesh().triangles().len(),
            limit_loops: l.limit.loops.len(),
            limit_open: l.limit.open.len(),
            path_curves: l.offsets.iter().map(|o| o.curves.len()).sum(),
            splits: l.offsets.iter().filter(|o| o.split).count(),
            zones: l.zones.len(),
            closed_by_virtual_flanks: l.limit.closed_by_virtual_flanks,
            closing_error: l.closing.as_ref().map(ToString::to_string),
        })
        .collect();
    let pairs = set
        .pairs
        .iter()
        .zip(&set.pair_zones)
        .map(|((k, p), &zones)| match p {
            Ok(p) => PairSummary {
                lower_level: *k,
                zones,
                paired: true,
                error: None,
                steps: p.steps,
                path_spacing_mm: p.path_spacing,
                tilt_spacing_mm: p.tilt_spacing,
            },
            Err(e) => PairSummary {
                lower_level: *k,
                zones,
                paired: false,
                error: Some(e.to_string()),
                steps: 0,
                path_spacing_mm: 0.0,
                tilt_spacing_mm: 0.0,
            },
        })
        .collect();
    GuidesSummary {
        command: "guides",
        part: name.into(),
        triangles: part.mesh.triangles().len(),
        settings: [s.tool_radius, s.flank_allowance, s.axial_step, s.radial_step, s.voxel],
        levels,
        pairs,
        seconds,
    }
}

/// A mesh as Wavefront OBJ text.
fn obj_text(mesh: &TriMesh) -> String {
    let mut s = String::new();
    for v in mesh.vertices() {
        let _ = writeln!(s, "v {} {} {}", v.x, v.y, v.z);
    }
    for t in mesh.triangles() {
        let _ = writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s
}

/// Every curve point: `level,family,step,curve,point,x,y,z` (family `limit`,
/// `path`, or `pair_path` / `pair_tilt` for the curves paired with the level
/// above).
fn curves_csv(set: &GuideSet) -> String {
    let mut s = String::from("level,family,step,curve,point,x,y,z\n");
    let mut put = |level: usize, family: &str, step: usize, k: usize, c: &Curve| {
        for (i, p) in c.line.points.iter().enumerate() {
            let _ = writeln!(s, "{level},{family},{step},{k},{i},{},{},{}", p.x, p.y, p.z);
        }
    };
    for (n, level) in set.levels.iter().enumerate() {
        for (k, c) in level.limit.loops.iter().chain(&level.limit.open).enumerate() {
            put(n, "limit", 0, k, c);
        }
        for (m, step) in level.offsets.iter().enumerate() {
            for (k, c) in step.curves.iter().enumerate() {
                put(n, "path", m + 1, k, c);
            }
        }
    }
    for ((n, pair), zones) in set.pairs.iter().zip(&set.pair_zones) {
        if let Ok(p) = pair {
            let zone = zones[0].unwrap_or(0);
            for (m, c) in p.path.iter().enumerate() {
                put(*n, "pair_path", m, zone, c);
            }
            for (m, c) in p.tilt.iter().enumerate() {
                put(*n, "pair_tilt", m, zone, c);
            }
        }
    }
    s
}

/// Colours of the degeneracy zones' path curves: zone 0 blue, then green,
/// purple, teal, brown, olive.
const ZONE_COLOURS: [[u8; 3]; 6] =
    [[30, 60, 200], [20, 140, 60], [140, 40, 170], [0, 140, 150], [150, 90, 20], [110, 120, 0]];

/// The part's inside with the limit curves (red) and path curves (blue,
/// other colours for the degeneracy branches).
fn picture(part: &TestPart, set: &GuideSet) -> String {
    let mut lines: Vec<(Vec<Point3>, bool, [u8; 3])> = Vec::new();
    for level in &set.levels {
        // Open chains closed by virtual flanks are drawn as their loops.
        let open: &[Curve] = if level.limit.closed_by_virtual_flanks > 0 { &[] } else { &level.limit.open };
        for c in level.limit.loops.iter().chain(open) {
            lines.push((c.line.points.clone(), c.line.closed, [200, 30, 30]));
        }
        // Zone 0 in blue, each degeneracy branch in a colour of its own.
        for (z, zone) in level.zones.iter().enumerate() {
            let colour = ZONE_COLOURS[z % ZONE_COLOURS.len()];
            let outer = (z > 0).then_some(&zone.outer);
            for c in outer.into_iter().chain(zone.offsets.iter().flat_map(|s| &s.curves)) {
                lines.push((c.line.points.clone(), c.line.closed, colour));
            }
        }
    }
    let grey = |t: usize| match part.tags[t] {
        FaceTag::Bottom => Some([190, 190, 170]),
        FaceTag::Flank => Some([170, 180, 190]),
        FaceTag::Top => None,
    };
    svg_view_with_lines(&part.mesh, 720.0, grey, &lines)
}

fn report_html(summary: &GuidesSummary, picture: &str) -> String {
    let mut rows = String::new();
    for (k, l) in summary.levels.iter().enumerate() {
        let _ = write!(
            rows,
            "<tr><td>{k}</td><td>{:.1}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            l.distance_mm, l.triangles, l.limit_loops, l.limit_open, l.path_curves, l.zones
        );
    }
    let mut pairs = String::new();
    for p in &summary.pairs {
        let what = p.error.clone().unwrap_or_else(|| {
            format!("{} steps; spacing {:.2} / {:.2} mm", p.steps, p.path_spacing_mm, p.tilt_spacing_mm)
        });
        let zone = |z: Option<usize>| z.map_or_else(|| "-".to_string(), |z| z.to_string());
        let _ = write!(
            pairs,
            "<tr><td>{} / {}</td><td>{} / {}</td><td>{}</td></tr>",
            p.lower_level,
            p.lower_level + 1,
            zone(p.zones[0]),
            zone(p.zones[1]),
            html_escape(&what)
        );
    }
    format!(
        "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>scallop guides: {part}</title>\
         <style>body{{font-family:sans-serif;margin:2em}}table{{border-collapse:collapse}}td,th{{border:1px solid #bbb;padding:2px 8px}}</style>\
         </head><body><h1>Guide curves: {part}</h1>\
         <p>R {r} mm, flank allowance {sf} mm, a<sub>p</sub> {ap} mm, a<sub>e</sub> {ae} mm, voxel {h} mm; {t:.2} s. \
         Limit curves in red, path curves in blue, the path curves of each degeneracy branch in a colour of its own (docs/guides-curves.md).</p>{picture}\
         <h2>Levels</h2><table><tr><th>level</th><th>mm above the bottom</th><th>triangles</th><th>limit loops</th><th>open chains</th><th>path curves</th><th>zones</th></tr>{rows}</table>\
         <h2>Tilt curves (pairs of levels, per degeneracy zone)</h2><table><tr><th>levels</th><th>zones</th><th>result</th></tr>{pairs}</table></body></html>\n",
        part = html_escape(&summary.part),
        r = summary.settings[0],
        sf = summary.settings[1],
        ap = summary.settings[2],
        ae = summary.settings[3],
        h = summary.settings[4],
        t = summary.seconds,
    )
}

fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}
