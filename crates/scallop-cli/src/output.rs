//! Writing results: atomic files, JSON and text on stdout, progress bars.

use std::io::Write;
use std::path::{Path, PathBuf};

use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use scallop_engine::{DemoSettings, run_demo};
use serde::Serialize;

use crate::outset::{OutputSet, remove_stale_temporaries};
use crate::{CliResult, Failure};

/// Writes `bytes` to `path` atomically: a temporary file beside it, then a
/// rename, so a failure never leaves a half-written output.
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> std::io::Result<()>,
) -> CliResult<()> {
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir)
        .map_err(|e| Failure::Io(anyhow::anyhow!("{}: cannot create the folder: {e}", dir.display())))?;
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| "output".into());
    // Temporaries of earlier killed runs go first.
    remove_stale_temporaries(dir);
    let tmp: PathBuf = dir.join(format!(".{name}.tmp-{}", std::process::id()));
    let result = (|| -> std::io::Result<()> {
        let file = std::fs::File::create(&tmp)?;
        let mut w = std::io::BufWriter::new(file);
        write(&mut w)?;
        w.flush()?;
        w.get_ref().sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    result.map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        Failure::Io(anyhow::anyhow!("{}: cannot write: {e}", path.display()))
    })
}

/// `value` as a JSON object with a `written` list of the files written (paths as given).
pub(crate) fn with_written(value: &impl Serialize, written: &[PathBuf]) -> CliResult<serde_json::Value> {
    let mut v = serde_json::to_value(value).map_err(|e| Failure::Io(e.into()))?;
    if let Some(map) = v.as_object_mut() {
        let files = written.iter().map(|p| serde_json::Value::from(p.display().to_string())).collect();
        map.insert("written".into(), serde_json::Value::Array(files));
    }
    Ok(v)
}

/// Prints one JSON object on stdout.
pub fn print_json(value: &impl Serialize) -> CliResult<()> {
    let text = serde_json::to_string_pretty(value).map_err(|e| Failure::Io(e.into()))?;
    print_text(&format!("{text}\n"))
}

/// Prints `report` as JSON, or else the text `human` makes of it.
pub fn print_report<T: Serialize>(report: &T, json: bool, human: impl FnOnce(&T) -> String) -> CliResult<()> {
    if json { print_json(report) } else { print_text(&human(report)) }
}

/// Prints text on stdout; a closed pipe is not an error.
pub fn print_text(text: &str) -> CliResult<()> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(Failure::Io(e.into())),
        _ => Ok(()),
    }
}

/// A progress bar on stderr when it is a terminal and not under CI; hidden otherwise.
pub fn progress_bar(total: u64, what: &str) -> ProgressBar {
    use std::io::IsTerminal;
    let visible = std::io::stderr().is_terminal() && std::env::var_os("CI").is_none();
    if !visible {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(total);
    let style = ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} {per_sec} eta {eta}")
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .progress_chars("=> ");
    bar.set_style(style);
    bar.set_message(what.to_string());
    bar
}

/// Arguments of `scallop demo`.
#[derive(Args, Debug)]
pub struct DemoArgs {
    /// Output folder: `program.nc`, `report.json`, `toolpath.csv`, `report.html`, `scene.glb` (with --raster:
    /// `demo.nc` and `summary.json`).
    #[arg(short, long, default_value = "out/demo")]
    output: PathBuf,
    /// Run the first, simpler job instead: a ball cutter on a fixed-stepover raster.
    #[arg(long, conflicts_with = "rough")]
    raster: bool,
    /// Run the roughing demo instead: a block with a pocket roughed, rest-roughed in its
    /// corners and finished on one stock (three tools, one program; the job of
    /// `examples/jobs/pocket-rest.toml`, embedded).
    #[arg(long)]
    rough: bool,
    /// Print the summary as JSON.
    #[arg(long)]
    json: bool,
}

/// `scallop demo`.
pub fn demo(args: &DemoArgs) -> CliResult<()> {
    if args.raster {
        return raster_demo(args);
    }
    if args.rough {
        return crate::run::rough_demo(&args.output, args.json);
    }
    let job = scallop_engine::FinishJob::choi_demo();
    let spinner = progress_bar(0, "planning and verifying the finishing of the Choi surface");
    spinner.enable_steady_tick(std::time::Duration::from_millis(120));
    let start = std::time::Instant::now();
    let out = scallop_engine::run_finishing(&job)
        .map_err(|e| Failure::Io(anyhow::anyhow!("the built-in demo failed: {e}")))?;
    let seconds = start.elapsed().as_secs_f64();
    spinner.finish_and_clear();
    write_finishing(&job, &out, seconds, &args.output, args.json, "scallop demo")
}

/// Writes `program.nc`, `report.json`, `toolpath.csv`, `report.html` and
/// `scene.glb` into `folder`: staged, then replacing the previous set in one
/// step (`outset.rs`). Returns the program's final path and the files written.
fn write_program_set(
    folder: &Path,
    kind: &'static str,
    gcode: &str,
    report: &impl serde::Serialize,
    toolpath: &scallop_toolpath::Toolpath,
    data: &scallop_report::ReportData,
) -> CliResult<(std::path::PathBuf, Vec<std::path::PathBuf>)> {
    let mut set = OutputSet::begin(folder, kind)?;
    let nc = set.final_path("program.nc");
    set.write("program.nc", gcode.as_bytes())?;
    let text = serde_json::to_string_pretty(report).map_err(|e| Failure::Io(e.into()))?;
    set.write("report.json", text.as_bytes())?;
    set.write("toolpath.csv", scallop_io::cl::write_cl(toolpath).as_bytes())?;
    set.write("report.html", scallop_report::html::report_html(data).as_bytes())?;
    let glb = scallop_report::glb::scene_glb(data).map_err(|e| Failure::Io(anyhow::anyhow!("scene.glb: {e}")))?;
    set.write("scene.glb", &glb)?;
    Ok((nc, set.commit()?))
}

/// Writes the five files of a job of several operations into `folder` and
/// prints the summary (or the report as JSON).
pub fn write_job(
    job: &scallop_engine::Job,
    out: &scallop_engine::JobOutput,
    seconds: f64,
    folder: &Path,
    json: bool,
    command: &str,
) -> CliResult<()> {
    let data = scallop_report::ReportData::from_job(job, out, seconds, command);
    let (nc, written) = write_program_set(folder, "job", &out.gcode, &out.report, &out.toolpath, &data)?;
    if json {
        return print_json(&with_written(&out.report, &written)?);
    }
    let r = &out.report;
    let mut text = format!(
        "{} operation{} on one stock, {}\n  stock      [{:.2}, {:.2}, {:.2}] to [{:.2}, {:.2}, {:.2}] mm\n",
        r.operations.len(),
        if r.operations.len() == 1 { "" } else { "s" },
        r.part,
        r.stock_mm[0][0],
        r.stock_mm[0][1],
        r.stock_mm[0][2],
        r.stock_mm[1][0],
        r.stock_mm[1][1],
        r.stock_mm[1][2]
    );
    for (k, (op, spec)) in r.operations.iter().zip(&job.operations).enumerate() {
        let what = match &spec.rough {
            Some(s) => format!("roughing, {} mm levels, stepover {} D", s.stepdown, s.stepover),
            None => {
                format!(
                    "scallop height {} mm, feed at {:.2}° from X",
                    op.scallop_height_mm,
                    shown_deg(op.direction_deg)
                )
            }
        };
        text.push_str(&format!(
            "  {}. {} (T{}): {}, {what}; {} passes, {} + {:.1} s rapids; \
             removed {:.0} mm³ of the {:.0} mm³ it met, {:.0} % of its feed length in air; planned in {}\n",
            k + 1,
            op.name,
            op.tool,
            op.cutter,
            op.plan.passes,
            hms(op.plan.machining_time_s),
            op.plan.rapid_time_s,
            op.stock.removed_mm3,
            op.stock.volume_before_mm3,
            100.0 * op.stock.air_length_share,
            hms(op.plan.planning_time_s)
        ));
        if let Some(e) = &op.engagement {
            text.push_str(&format!(
                "     engagement (simulated) median {:.0}°, p95 {:.0}°, max {:.0}° (target {:.0}°; entries apart, \
                 up to {:.0}°); {:.0} mm above 1.2 x target, {:.0} mm full slot; {:.0} % of the length at depth \
                 in links\n",
                e.p50_deg,
                e.p95_deg,
                e.max_deg,
                e.target_deg,
                e.entry_max_deg,
                e.over_length_mm,
                e.slot_length_mm,
                100.0 * e.link_share
            ));
        }
        if let Some(l) = &op.left {
            let place = l.places.first().map_or(String::new(), |p| {
                format!(", the largest {:.0} mm² at ({:.1}, {:.1}) mm", p.area_mm2, p.at[0], p.at[1])
            });
            text.push_str(&format!(
                "     left above {:.2} mm: {:.0} mm³ (the most {:.2} mm thick where the tool reaches); \
                 {:.0} mm³ on {:.0} mm² where it cannot reach, up to {:.2} mm, in {} places{place}\n",
                l.limit_mm,
                l.volume_mm3,
                l.reached_max_mm,
                l.unreachable_volume_mm3,
                l.unreachable_area_mm2,
                l.unreachable_depth_mm,
                l.places.len()
            ));
        }
    }
    let left = if job.operations.last().is_some_and(|o| o.rough.is_some()) {
        format!(
            "most material left on the part {:.4} mm (the last operation roughs: its allowance and steps)",
            r.sim_max_scallop_mm
        )
    } else {
        format!(
            "scallop on the machined surface {:.4} mm along the normal beyond R from the edge (last operation's limit: sh + {:.5} mm)",
            r.sim_max_scallop_mm, r.sim_resolution_bound_mm
        )
    };
    text.push_str(&format!(
        "  time       {} in all (stop-to-stop, rapids included)\n\
         \x20 simulated  no gouge on the final {} mm stock; deepest {:+.4} mm (tolerance {:.4} mm); {left}\n\
         {}\
         \x20 ran        in {} (planning, cutting, proof)\n\
         \x20 wrote      {}, report.json, toolpath.csv, report.html, scene.glb\n",
        hms(r.total_time_s),
        r.sim_resolution_mm,
        r.sim_min_deviation_mm,
        r.sim_gouge_tolerance_mm,
        rest_text(&r.rest),
        hms(seconds),
        nc.display()
    ));
    print_text(&text)
}

/// The summary's lines on material the cutter cannot reach (empty without any).
#[must_use]
pub fn rest_text(rest: &scallop_engine::RestReport) -> String {
    if rest.area_mm2 <= 0.0 {
        return String::new();
    }
    let mut text = format!(
        "  unreachable {:.1} mm2 of material the cutter cannot remove, in {} place(s), up to {:.4} mm thick \
         (not scallop: a corner or slot tighter than the cutter; finish it with a smaller one)\n",
        rest.area_mm2,
        rest.places.len(),
        rest.depth_mm
    );
    for p in rest.places.iter().take(3) {
        text.push_str(&format!(
            "             at ({:.3}, {:.3}) mm: {:.1} mm2, up to {:.4} mm\n",
            p.at[0], p.at[1], p.area_mm2, p.depth_mm
        ));
    }
    text
}

/// A duration as people read it: seconds under a minute, else h:mm:ss.
#[must_use]
pub fn hms(seconds: f64) -> String {
    if !seconds.is_finite() || seconds < 60.0 {
        return format!("{seconds:.1} s");
    }
    // Rounded to whole seconds: far below 2^52.
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let s = seconds.round() as u64;
    format!("{}:{:02}:{:02}", s / 3600, (s / 60) % 60, s % 60)
}

/// Writes `program.nc`, `report.json`, `toolpath.csv`, `report.html` and
/// `scene.glb` of a finishing job into `folder` and prints the summary (or the
/// report as JSON).
pub fn write_finishing(
    job: &scallop_engine::FinishJob,
    out: &scallop_engine::FinishOutput,
    seconds: f64,
    folder: &Path,
    json: bool,
    command: &str,
) -> CliResult<()> {
    let mut report = out.report.clone();
    report.plan.planning_time_s = seconds;
    let data = scallop_report::ReportData::from_finishing(job, out, seconds, command);
    let (nc, written) = write_program_set(folder, "finishing", &out.gcode, &report, &out.toolpath, &data)?;
    if json {
        return print_json(&with_written(&report, &written)?);
    }
    let (r, p) = (&report, &report.plan);
    print_text(&format!(
        "finishing the {part}\n\
         \x20 analysis   PCA slope {slope:.2}°, critical slope {crit:.2}°: {rec}; feed at {dir:.2}° from X\n\
         \x20 cutter     {cutter}, scallop height {sh} mm, {chord}\n\
         \x20 toolpath   {passes} passes on {planes} planes, {points} points, {links} links, {retracts} retracts{refined}\n\
         \x20 scallop    verified max {smax:.5} mm (<= {sh} mm{by_sim}), mean material left {smean:.5} mm\n\
         \x20 time       {t1} stop-to-stop, {t2} look-ahead, + {tr} rapids\n\
         \x20 lengths    feed {feed:.0} mm, links {link:.0} mm, rapid {rapid:.0} mm\n\
         \x20 simulated  no gouge on a {res} mm stock; deepest {dev:+.4} mm (tolerance {gt:.4} mm), most material left {mat:.4} mm;\n\
         \x20            scallop on the machined surface {ssim:.4} mm along the normal beyond R from the edge (<= sh + {bound:.5} mm), {sedge:.4} mm within it\n\
         {rest}\
         \x20 planned    in {secs:.2} s\n\
         \x20 wrote      {nc}, report.json, toolpath.csv, report.html, scene.glb\n",
        part = r.part,
        slope = r.slope_deg,
        crit = r.critical_slope_deg,
        dir = shown_deg(r.direction_deg),
        rec = match r.recommendation {
            scallop_analysis::Recommendation::BallAlongPrincipal => "a ball along the principal direction is faster",
            scallop_analysis::Recommendation::ToroidalAlongSlope => "a bull-nose along the steepest slope is faster",
        },
        cutter = r.cutter,
        sh = r.scallop_height_mm,
        chord = if r.chordal_error_mm > 0.0 {
            format!("surface tessellated within {:.4} mm", r.chordal_error_mm)
        } else {
            "a mesh, machined as given".to_string()
        },
        refined = p.refinement.map_or(String::new(), |f| format!(
            "\n\x20            refined in {} round(s): {} planes and {} levels added where the simulation of the first program found more than sh",
            f.rounds, f.planes_added, f.levels_added
        )),
        passes = p.passes,
        planes = p.planes,
        points = p.points,
        links = p.links,
        retracts = p.retracts,
        smax = p.max_scallop_mm,
        smean = p.mean_scallop_mm,
        t1 = hms(p.machining_time_s),
        t2 = hms(p.machining_time_lookahead_s),
        tr = hms(p.rapid_time_s),
        feed = p.feed_length_mm,
        link = p.link_length_mm,
        rapid = p.rapid_length_mm,
        res = r.sim_resolution_mm,
        dev = r.sim_min_deviation_mm,
        gt = r.sim_gouge_tolerance_mm,
        mat = r.sim_max_material_mm,
        ssim = r.sim_max_scallop_mm,
        bound = r.sim_resolution_bound_mm,
        sedge = r.sim_edge_max_scallop_mm,
        rest = rest_text(&r.rest),
        by_sim = if p.max_scallop_mm > r.scallop_height_mm {
            format!(" + {:.5} mm, the simulation's bound", r.sim_resolution_bound_mm)
        } else {
            String::new()
        },
        secs = seconds,
        nc = nc.display(),
    ))
}

/// `scallop demo --raster`: the first end-to-end job.
fn raster_demo(args: &DemoArgs) -> CliResult<()> {
    let settings = DemoSettings::standard();
    let bar = progress_bar(0, "drop-cutter raster");
    let start = std::time::Instant::now();
    let out = run_demo(&settings, &|done, total| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
    })
    .map_err(|e| Failure::Io(anyhow::anyhow!("the built-in demo failed: {e}")))?;
    bar.finish_and_clear();
    let seconds = start.elapsed().as_secs_f64();
    let mut set = OutputSet::begin(&args.output, "raster")?;
    let nc = set.final_path("demo.nc");
    set.write("demo.nc", out.gcode.as_bytes())?;
    let json = serde_json::to_string_pretty(&out.summary).map_err(|e| Failure::Io(e.into()))?;
    set.write("summary.json", json.as_bytes())?;
    let written = set.commit()?;
    if args.json {
        return print_json(&with_written(&out.summary, &written)?);
    }
    let s = &out.summary;
    let text = format!(
        "scallop demo: finishing the built-in {part} surface\n\
         \x20 part       {tris} triangles, within {chord:.4} mm of the surface\n\
         \x20 cutter     {cutter}, stepover {so} mm (scallop {sc:.4} mm on a flat)\n\
         \x20 toolpath   {passes} passes, {moves} moves, {cl} drop-cutter queries in {seconds:.2} s\n\
         \x20 lengths    feed {feed:.0} mm, links {link:.0} mm, plunge {plunge:.0} mm, rapid {rapid:.0} mm\n\
         \x20 tip z      {z0:.3} .. {z1:.3} mm\n\
         \x20 verified   no gouge on a {res} mm stock simulation; max material left {ms:.4} mm, \
         deepest {md:+.4} mm; {air:.1} % of feed moves cut air\n\
         \x20 time       {t:.0} s at the programmed feeds (no acceleration limits yet)\n\
         \x20 program    {nc}\n",
        part = s.part,
        tris = s.triangles,
        chord = s.chordal_error_mm,
        cutter = s.cutter,
        so = s.stepover_mm,
        sc = s.flat_scallop_mm,
        passes = s.passes,
        moves = s.moves,
        cl = s.cl_points_dropped,
        feed = s.feed_length_mm,
        link = s.link_length_mm,
        plunge = s.plunge_length_mm,
        rapid = s.rapid_length_mm,
        z0 = s.tip_z_range_mm[0],
        z1 = s.tip_z_range_mm[1],
        t = s.naive_time_s,
        res = s.sim_resolution_mm,
        ms = s.verified_max_scallop_mm,
        md = s.verified_min_deviation_mm,
        air = 100.0 * s.air_cut_share,
        nc = nc.display(),
    );
    print_text(&text)
}

/// An angle as the summary prints it with two decimals: no "-0.00".
fn shown_deg(deg: f64) -> f64 {
    if deg.abs() < 0.005 { 0.0 } else { deg }
}
