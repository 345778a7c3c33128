//! `scallop simulate`: cut a stock with a G-code program or a cutter-location
//! file and verify it against the part, on a z-map (3-axis) or a tri-dexel
//! stock (any tool axis).

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use scallop_engine::{Budget, prepare_part};
use scallop_geom::{Aabb3, Point3, Tolerances, Vec3};
use scallop_io::cl::read_cl;
use scallop_io::gcode::{GcodeOptions, read_gcode_lines};
use scallop_sim::{
    DexelOptions, DexelPart, DexelStock, PartField, ToolMove, VerifyOptions, ZMap, verify_dexel, verify_in,
};
use scallop_toolpath::Toolpath;
use serde::Serialize;

use crate::drop::CutterArgs;
use crate::input::read_text;
use crate::output::{print_json, print_text, progress_bar, write_atomic};
use crate::part::{UnitsArg, load};
use crate::{CliResult, Failure};
use scallop_report::png::{Image, ramp};
use scallop_report::{DeviationMap, Figure, ReportData};

/// Arguments of `scallop simulate`.
#[derive(Args, Debug)]
pub struct SimulateArgs {
    /// The design part: mesh file, surface file (.toml) or built-in name (choi, rubio).
    #[arg(long)]
    part: String,
    /// The program: plain 3-axis G-code (G0/G1/G2/G3, G20/G21, G90/G91).
    #[arg(long, conflicts_with = "toolpath", required_unless_present = "toolpath")]
    program: Option<PathBuf>,
    /// The program as cutter locations: the CSV `scallop run` writes
    /// (`kind,x,y,z` and optionally the tool axis `i,j,k` and `feed`).
    #[arg(long)]
    toolpath: Option<PathBuf>,
    /// Stock model: `auto` takes the tri-dexel stock when any tool axis is
    /// not +Z, else the z-map.
    #[arg(long, value_enum, default_value = "auto")]
    stock_model: StockModel,
    /// Largest distance (mm) between the simulated and the true swept solid
    /// of a simultaneous 5-axis move (tri-dexel stock; 3+2 moves are exact).
    #[arg(long, default_value_t = 0.01, allow_hyphen_values = true)]
    axis_tolerance: f64,
    #[command(flatten)]
    tool: CutterArgs,
    /// Stock cell size (mm).
    #[arg(long, default_value_t = 0.1, allow_hyphen_values = true)]
    resolution: f64,
    /// Stock box XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX (mm); default: the part's box grown by
    /// the cutter radius in X and Y, from 1 mm below to 1 mm above the part.
    #[arg(long, allow_hyphen_values = true)]
    stock: Option<String>,
    /// Allowed penetration below the part (mm), as `tolerances.gouge` of a job; the
    /// path tolerance and, for surfaces, the tessellation's chordal error are added
    /// (the allowance `scallop run` proves its programs with).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    gouge_tolerance: f64,
    /// The path tolerance the program was planned with (mm), as `tolerances.path`
    /// of a job (default 0.01, the job default): chords between cutter locations
    /// may dip below the CL surface by this much.
    #[arg(long, default_value_t = 0.01, allow_hyphen_values = true)]
    path_tolerance: f64,
    /// Unit of mesh coordinates.
    #[arg(long, value_enum, default_value = "mm")]
    units: UnitsArg,
    /// Output folder for `sim.json`, `deviation.png` and `report.html`.
    #[arg(short, long, default_value = "out/simulate")]
    output: PathBuf,
    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
}

/// The stock representation of `scallop simulate`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum StockModel {
    /// Tri-dexels when any tool axis is not +Z, else the z-map.
    Auto,
    /// Height field (3-axis programs only).
    Zmap,
    /// Rays along X, Y and Z (any tool axis, undercuts).
    Dexel,
}

#[derive(Serialize)]
struct SimReport {
    /// "z-map" or "tri-dexel".
    stock_model: &'static str,
    part: String,
    program: String,
    cutter: String,
    resolution_mm: f64,
    cells: [usize; 2],
    moves: usize,
    feed_moves: usize,
    air_cut_share: f64,
    removed_volume_mm3: f64,
    remaining_volume_mm3: f64,
    max_scallop_mm: f64,
    max_scallop_at: Option<[f64; 2]>,
    min_deviation_mm: f64,
    gouge_tolerance_mm: f64,
    /// Tri-dexel only: rays along X, Y and Z.
    #[serde(skip_serializing_if = "Option::is_none")]
    rays: Option<[usize; 3]>,
    /// Tri-dexel only: the largest material thickness along the part normal (mm).
    #[serde(skip_serializing_if = "Option::is_none")]
    max_thickness_mm: Option<f64>,
    /// Tri-dexel only: the 5-axis sub-step tolerance (mm) and the number of fixed-axis sweeps.
    #[serde(skip_serializing_if = "Option::is_none")]
    axis_tolerance_mm: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    sweeps: Option<usize>,
    /// "ok", or the safety problems found (each an error).
    verdict: Vec<String>,
}

/// The program in both forms: moves with tool axes, and the 3-axis toolpath
/// (tips; arcs kept when read from G-code).
struct Program {
    name: String,
    moves: Vec<ToolMove>,
    path: Toolpath,
    /// The G-code line of each move (G-code programs only).
    lines: Option<Vec<usize>>,
}

impl Program {
    /// `text` with the G-code line added after every "move N of operation 0"
    /// it names, so a fault points at the program's line, not a move index.
    fn with_lines(&self, text: &str) -> String {
        let Some(lines) = &self.lines else { return text.to_string() };
        let (marker, tail) = ("move ", " of operation 0");
        let mut out = String::with_capacity(text.len() + 32);
        let mut rest = text;
        while let Some(at) = rest.find(marker) {
            let after = &rest[at + marker.len()..];
            let digits = after.bytes().take_while(u8::is_ascii_digit).count();
            out.push_str(&rest[..at + marker.len() + digits]);
            rest = &after[digits..];
            let line = after[..digits].parse::<usize>().ok().and_then(|k| lines.get(k));
            if let (Some(line), true) = (line, rest.starts_with(tail)) {
                out.push_str(tail);
                out.push_str(&format!(" (G-code line {line})"));
                rest = &rest[tail.len()..];
            }
        }
        out.push_str(rest);
        out
    }
}

fn read_program(args: &SimulateArgs) -> CliResult<Program> {
    let file = args.program.as_ref().or(args.toolpath.as_ref()).ok_or_else(|| {
        Failure::rejected("give the program with --program FILE.nc (G-code) or --toolpath FILE.csv (cutter locations)")
    })?;
    let name = file.display().to_string();
    let text = &read_text(file, "the program")?;
    if args.program.is_some() {
        // Arcs stay arcs: the z-map cuts them exactly.
        let path =
            read_gcode_lines(text, &GcodeOptions::default()).map_err(|e| Failure::rejected(format!("{name}: {e}")))?;
        let (path, lines) = path;
        let moves = ToolMove::from_toolpath(&path);
        return Ok(Program { name, moves, path, lines: Some(lines) });
    }
    let path = read_cl(text, DEFAULT_CL_FEED).map_err(|e| Failure::rejected(format!("{name}: {e}")))?;
    let moves = ToolMove::from_toolpath(&path);
    Ok(Program { name, moves, path, lines: None })
}

/// Cutting feed of CL rows without a feed of their own (mm/min); the
/// simulation's verdict does not depend on feeds.
const DEFAULT_CL_FEED: f64 = 1000.0;

fn parse_stock(text: &str) -> CliResult<Aabb3> {
    let v: Vec<f64> =
        text.split(',').map(|t| t.trim().parse::<f64>()).collect::<Result<_, _>>().map_err(|_| {
            Failure::rejected(format!("--stock '{text}': give six numbers XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX"))
        })?;
    let [x0, y0, z0, x1, y1, z1] = v.as_slice() else {
        return Err(Failure::rejected(format!("--stock '{text}': give six numbers XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX")));
    };
    Ok(Aabb3 { min: Point3::new(*x0, *y0, *z0), max: Point3::new(*x1, *y1, *z1) })
}

/// `scallop simulate`.
pub fn run(args: &SimulateArgs) -> CliResult<()> {
    let (cutter, cutter_text) = args.tool.build()?;
    let tolerances = Tolerances { path: args.path_tolerance, gouge: args.gouge_tolerance };
    let budget = Budget::new(tolerances, false).map_err(|_| {
        Failure::rejected(format!(
            "--path-tolerance {} / --gouge-tolerance {}: need a path tolerance > 0 and a gouge tolerance >= 0 (mm)",
            args.path_tolerance, args.gouge_tolerance
        ))
    })?;
    let loaded = load(&args.part, args.units)?;
    let prepared =
        prepare_part(&loaded.part, &tolerances).map_err(|e| Failure::rejected(format!("{}: {e}", args.part)))?;
    let program = read_program(args)?;
    let name = program.name.clone();
    let tilted = program.moves.iter().any(|m| m.axis != Vec3::z());
    let dexel = match args.stock_model {
        StockModel::Auto => tilted,
        StockModel::Dexel => true,
        StockModel::Zmap if tilted => {
            return Err(Failure::rejected(format!(
                "{name}: the program tilts the tool axis; a z-map holds 3-axis programs only: use --stock-model dexel"
            )));
        }
        StockModel::Zmap => false,
    };
    let stock = match &args.stock {
        Some(s) => parse_stock(s)?,
        None => scallop_engine::stock_box(&prepared.mesh, cutter.radius()),
    };
    let options =
        VerifyOptions { gouge_tolerance: budget.gouge_allowance(prepared.chordal_error), ..VerifyOptions::default() };
    let run = Run {
        args,
        program: &program,
        cutter: &cutter,
        cutter_text: &cutter_text,
        stock,
        prepared: &prepared,
        options: &options,
        part_name: &loaded.description,
    };
    let (report, zmap, dev, max_dev) = if dexel { simulate_dexel(&run)? } else { simulate_zmap(&run)? };
    let verdict = if report.verdict == ["ok"] { Vec::new() } else { report.verdict.clone() };
    let program = program.path;
    let json = serde_json::to_string_pretty(&report).map_err(|e| Failure::Io(e.into()))?;
    write_atomic(&args.output.join("sim.json"), |w| std::io::Write::write_all(w, json.as_bytes()))?;
    let png = deviation_picture(&zmap, &dev, max_dev, options.gouge_tolerance).to_png();
    write_atomic(&args.output.join("deviation.png"), |w| std::io::Write::write_all(w, &png))?;
    let page = scallop_report::html::report_html(&report_data(&report, &prepared.mesh, &zmap, dev, &program));
    write_atomic(&args.output.join("report.html"), |w| std::io::Write::write_all(w, page.as_bytes()))?;

    if args.json {
        print_json(&report)?;
    } else {
        print_text(&format!(
            "{} on {}: {} stock, {} x {} cells of {} mm, {} moves ({:.1} % of feed moves in air)\n\
             \x20 material left up to {:.4} mm, deepest {:+.4} mm (gouge tolerance {:.4} mm)\n\
             \x20 removed {:.0} mm³, remaining {:.0} mm³\n  wrote {}\n",
            report.program,
            report.part,
            report.stock_model,
            report.cells[0],
            report.cells[1],
            report.resolution_mm,
            report.moves,
            100.0 * report.air_cut_share,
            report.max_scallop_mm,
            report.min_deviation_mm,
            report.gouge_tolerance_mm,
            report.removed_volume_mm3,
            report.remaining_volume_mm3,
            args.output.display()
        ))?;
    }
    if verdict.is_empty() { Ok(()) } else { Err(Failure::rejected(format!("{name}: {}", verdict.join("; ")))) }
}

/// What both simulations return: the report, a z-map of the stock's grid
/// (the cut z-map, or an uncut one on the Z rays' grid for the picture), the
/// deviation `stock top - part top` per cell and its largest value.
type Outcome = (SimReport, ZMap, Vec<f64>, f64);

/// Deviation per cell from the stock tops, for the picture and the figures
/// when verify refused.
fn deviation(tops: &[f64], field: &PartField) -> (Vec<f64>, f64, f64) {
    let dev: Vec<f64> =
        tops.iter().zip(field.heights()).map(|(s, p)| if p.is_finite() { s - p } else { f64::NAN }).collect();
    let finite = || dev.iter().copied().filter(|d| d.is_finite());
    let max_dev = finite().fold(0.0f64, f64::max);
    let min_dev = finite().fold(f64::INFINITY, f64::min);
    (dev, max_dev, min_dev)
}

/// Moves the progress bar to `done` of `total` bands (the library calls this
/// from its worker threads, in any order: the bar only moves forward).
pub(crate) fn show(bar: &indicatif::ProgressBar, done: usize, total: usize) {
    // Counts far below 2^64: exact conversions.
    bar.set_length(total as u64);
    if done as u64 > bar.position() {
        bar.set_position(done as u64);
    }
}

/// The pieces of one simulation, whichever the stock model.
struct Run<'a> {
    args: &'a SimulateArgs,
    program: &'a Program,
    cutter: &'a scallop_cutter::Cutter,
    cutter_text: &'a str,
    stock: Aabb3,
    prepared: &'a scallop_engine::PreparedPart,
    options: &'a VerifyOptions,
    part_name: &'a str,
}

/// What a cut measured, whichever the stock model: moves, volumes, and the
/// largest scallop (mm, XY) and deepest deviation (mm) of the verification,
/// else of the deviation map.
struct Measured {
    stock_model: &'static str,
    cells: [usize; 2],
    feed_moves: usize,
    air_cut_share: f64,
    volumes_mm3: [f64; 2],
    scallop: (f64, Option<[f64; 2]>, f64),
}

impl Run<'_> {
    /// Maps a library error to a rejection naming the program.
    fn rejected(&self, e: impl std::fmt::Display) -> Failure {
        Failure::rejected(format!("{}: {e}", self.program.name))
    }

    /// The report of a cut; the tri-dexel stock's own figures are left out.
    fn report(&self, m: Measured, verdict: &[String]) -> SimReport {
        let (max_scallop_mm, max_scallop_at, min_deviation_mm) = m.scallop;
        SimReport {
            stock_model: m.stock_model,
            part: self.part_name.to_string(),
            program: self.program.name.clone(),
            cutter: self.cutter_text.to_string(),
            resolution_mm: self.args.resolution,
            cells: m.cells,
            moves: self.program.path.moves().len(),
            feed_moves: m.feed_moves,
            air_cut_share: m.air_cut_share,
            removed_volume_mm3: m.volumes_mm3[0],
            remaining_volume_mm3: m.volumes_mm3[1],
            max_scallop_mm,
            max_scallop_at,
            min_deviation_mm,
            gouge_tolerance_mm: self.options.gouge_tolerance,
            rays: None,
            max_thickness_mm: None,
            axis_tolerance_mm: None,
            sweeps: None,
            verdict: if verdict.is_empty() {
                vec!["ok".into()]
            } else {
                verdict.iter().map(|v| self.program.with_lines(v)).collect()
            },
        }
    }
}

/// `result`'s value, or `None` with its error added to the verdict.
fn noted<T, E: std::fmt::Display>(result: Result<T, E>, verdict: &mut Vec<String>) -> Option<T> {
    result.map_err(|e| verdict.push(e.to_string())).ok()
}

/// The 3-axis simulation on a z-map.
fn simulate_zmap(run: &Run) -> CliResult<Outcome> {
    let (program, cutter) = (run.program, run.cutter);
    let mut zmap = ZMap::new(run.stock, run.args.resolution).map_err(|e| Failure::rejected(format!("stock: {e}")))?;
    let bar = progress_bar(0, "cutting the z-map stock");
    let cut = zmap
        .cut_with_progress(cutter, &program.path, &|done, total| show(&bar, done, total))
        .map_err(|e| run.rejected(e))?;
    bar.finish_and_clear();
    let mut verdict = Vec::new();
    noted(cut.check(), &mut verdict);
    // The part rasterised once: collisions, verification and the picture.
    let field = PartField::new(&zmap, &run.prepared.index);
    let collisions =
        zmap.part_collisions_in(&field, cutter, &program.path, cut.operation).map_err(|e| run.rejected(e))?;
    if !collisions.is_empty() {
        verdict.push(scallop_sim::SimError::PartCollision { collisions }.to_string());
    }
    let verification = noted(verify_in(&zmap, &field, run.options), &mut verdict);
    let (dev, max_dev, min_dev) = deviation(zmap.heights(), &field);
    let verified = verification.map(|v| (v.max_scallop, v.max_scallop_at.map(|p| [p.x, p.y]), v.min_deviation));
    let measured = Measured {
        stock_model: "z-map",
        cells: [zmap.nx(), zmap.ny()],
        feed_moves: cut.feed_moves,
        air_cut_share: cut.air_cut_share(),
        volumes_mm3: [cut.removed_volume, zmap.volume()],
        scallop: verified.unwrap_or((max_dev, None, min_dev)),
    };
    Ok((run.report(measured, &verdict), zmap, dev, max_dev))
}

/// The multi-axis simulation on a tri-dexel stock.
fn simulate_dexel(run: &Run) -> CliResult<Outcome> {
    let (program, cutter, args) = (run.program, run.cutter, run.args);
    let mut dexels =
        DexelStock::new(run.stock, args.resolution).map_err(|e| Failure::rejected(format!("stock: {e}")))?;
    let dexel_options = DexelOptions { axis_tolerance: args.axis_tolerance, ..DexelOptions::default() };
    let bar = progress_bar(0, "cutting the tri-dexel stock");
    let cut = dexels
        .cut_with_progress(cutter, &program.moves, &dexel_options, &|done, total| show(&bar, done, total))
        .map_err(|e| run.rejected(e))?;
    bar.finish_and_clear();
    let mut verdict = Vec::new();
    noted(cut.check(), &mut verdict);
    let part = DexelPart::new(&run.prepared.mesh);
    let collisions = dexels
        .part_collisions(&part, cutter, &program.moves, &dexel_options, cut.operation)
        .map_err(|e| run.rejected(e))?;
    if !collisions.is_empty() {
        verdict.push(scallop_sim::SimError::DexelPartCollision { collisions }.to_string());
    }
    let verification = noted(verify_dexel(&dexels, &part, run.options), &mut verdict);
    // An uncut z-map on the Z rays' grid: the same cells, for the picture.
    let grid = ZMap::new(run.stock, args.resolution).map_err(|e| Failure::rejected(format!("stock: {e}")))?;
    let (dev, max_dev, min_dev) = deviation(&dexels.top_heights(), &PartField::new(&grid, &run.prepared.index));
    let counts = dexels.counts();
    let rays = [0, 1, 2].map(|k| {
        let (nu, nv) = dexels.grid(k);
        nu * nv
    });
    let verified = verification.map(|v| (v.max_scallop, v.max_scallop_at.map(|p| [p.x, p.y]), v.min_deviation));
    let measured = Measured {
        stock_model: "tri-dexel",
        cells: [counts[0], counts[1]],
        feed_moves: cut.feed_moves,
        air_cut_share: cut.air_cut_share(),
        volumes_mm3: [cut.removed_volume, dexels.volume()],
        scallop: verified.unwrap_or((max_dev, None, min_dev)),
    };
    let report = SimReport {
        rays: Some(rays),
        max_thickness_mm: verification.map(|v| v.max_thickness),
        axis_tolerance_mm: Some(args.axis_tolerance),
        sweeps: Some(cut.sweeps),
        ..run.report(measured, &verdict)
    };
    Ok((report, grid, dev, max_dev))
}

/// The HTML report of a simulation: part, stock, program, deviation and figures.
fn report_data(
    r: &SimReport,
    mesh: &scallop_mesh::TriMesh,
    zmap: &ZMap,
    dev: Vec<f64>,
    program: &scallop_toolpath::Toolpath,
) -> ReportData {
    let c0 = zmap.cell_center(0, 0);
    let (cx, cy) = zmap.cell_size();
    let mut data = ReportData::new(&format!("Simulation of {} on {}", r.program, r.part));
    data.command = format!("scallop simulate --program {}", r.program);
    data.part = Some(mesh.clone());
    data.stock = Some(zmap.stock());
    data.toolpath = Some(program.clone());
    data.deviation = Some(DeviationMap {
        origin: [c0.x, c0.y],
        cell: [cx, cy],
        nx: zmap.nx(),
        ny: zmap.ny(),
        values: dev,
        gouge_tolerance: r.gouge_tolerance_mm,
    });
    data.figures = vec![
        Figure::text("verdict", r.verdict.join("; ")),
        Figure::count("moves", r.moves),
        Figure::count("feed moves", r.feed_moves),
        Figure::number("feed moves in air", 100.0 * r.air_cut_share, 1, "%"),
        Figure::number("material left, max", r.max_scallop_mm, 4, "mm"),
        Figure::number("deepest deviation", r.min_deviation_mm, 4, "mm"),
        Figure::number("gouge tolerance", r.gouge_tolerance_mm, 4, "mm"),
        Figure::number("removed volume", r.removed_volume_mm3, 0, "mm³"),
        Figure::number("remaining volume", r.remaining_volume_mm3, 0, "mm³"),
        Figure::number("nominal time at the programmed feeds", data.move_durations().iter().sum(), 1, "s"),
    ];
    data.settings = vec![
        Figure::text("part", r.part.clone()),
        Figure::text("program", r.program.clone()),
        Figure::text("cutter", r.cutter.clone()),
        Figure::text("stock model", r.stock_model.to_string()),
        Figure::number("cell size", r.resolution_mm, 3, "mm"),
        Figure::text("cells", format!("{} x {}", r.cells[0], r.cells[1])),
    ];
    data
}

/// Top view of the stock: material left from 0 (blue) to `max_dev` (red),
/// gouges magenta, cells without part dark grey; a colour bar on the right.
fn deviation_picture(zmap: &ZMap, dev: &[f64], max_dev: f64, gouge_tol: f64) -> Image {
    let (nx, ny) = (zmap.nx(), zmap.ny());
    // At most MAX_PICTURE pixels across: nearest-cell sampling.
    let step = nx.max(ny).div_ceil(MAX_PICTURE).max(1);
    let (w, h) = (nx.div_ceil(step), ny.div_ceil(step));
    let bar = 120;
    let mut img = Image::new(w + bar, h.max(160), [255, 255, 255]);
    let scale = if max_dev > 0.0 { max_dev } else { 1.0 };
    for py in 0..h {
        for px in 0..w {
            let (i, j) = (px * step, py * step);
            let d = dev[j * nx + i];
            let rgb = if d.is_nan() {
                [70, 70, 70]
            } else if d < -gouge_tol {
                [230, 0, 230]
            } else {
                ramp(d.max(0.0) / scale)
            };
            // Image rows go down, y goes up.
            img.set(px, h - 1 - py, rgb);
        }
    }
    let (x0, top, height) = (w + 12, 20, h.max(160) - 40);
    for k in 0..height {
        #[allow(clippy::cast_precision_loss)]
        img.fill(x0, top + k, 16, 1, ramp(1.0 - k as f64 / height.max(1) as f64));
    }
    img.text(x0 + 20, top, &format!("{max_dev:.4}"), 2, [0, 0, 0]);
    img.text(x0 + 20, top + height - 14, "0", 2, [0, 0, 0]);
    img.text(x0 + 20, top + height / 2, "mm", 2, [0, 0, 0]);
    img
}

/// Largest picture side in pixels.
const MAX_PICTURE: usize = 1600;
