//! `scallop analyze`: PCA of the part and the tool-choice advice, before any toolpath.

use std::path::PathBuf;

use clap::Args;
use scallop_analysis::{
    AnalysisReport, GridOptions, MachineLimits, Recommendation, ToolOptions, analyze, critical_slope, plot_svg,
    sample_mesh, sample_surface_set,
};
use scallop_engine::Part;

use crate::output::{print_json, print_text, write_atomic};
use crate::part::{UnitsArg, load};
use crate::{CliResult, Failure};
use scallop_io::job::ShapeWord;

/// Arguments of `scallop analyze`.
#[derive(Args, Debug)]
pub struct AnalyzeArgs {
    /// Part: mesh file (.stl .obj .ply .3mf), surface file (.toml), built-in name (choi, rubio),
    /// or a job file (.toml with a [part]): its part with its first operation's cutter, scallop
    /// height and [machine] limits (the cutter and machine flags are then not used).
    part: String,
    /// Unit of mesh coordinates.
    #[arg(long, value_enum, default_value = "mm")]
    units: UnitsArg,
    /// Ball cutter radius compared (mm).
    #[arg(long, default_value_t = 5.0, allow_hyphen_values = true)]
    ball_radius: f64,
    /// Bull-nose (toroidal) cutter radius R compared (mm).
    #[arg(long, default_value_t = 5.0, allow_hyphen_values = true)]
    bull_radius: f64,
    /// Bull-nose corner radius r (mm).
    #[arg(long, default_value_t = 2.0, allow_hyphen_values = true)]
    corner_radius: f64,
    /// Scallop height sh (mm).
    #[arg(long, default_value_t = 0.01, allow_hyphen_values = true)]
    scallop: f64,
    /// Feed rate V (m/min).
    #[arg(long, default_value_t = 5.0, allow_hyphen_values = true)]
    feed: f64,
    /// Maximum acceleration A (m/s²).
    #[arg(long, default_value_t = 6.0, allow_hyphen_values = true)]
    acceleration: f64,
    /// Maximum jerk J (m/s³).
    #[arg(long, default_value_t = 40.0, allow_hyphen_values = true)]
    jerk: f64,
    /// Sample cells per parameter direction on surfaces.
    #[arg(long, default_value_t = 80)]
    cells: usize,
    /// Write the (mu, s) decision plot: SVG, or PNG when the name ends in .png.
    #[arg(long)]
    plot: Option<PathBuf>,
    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
}

/// `scallop analyze`.
pub fn run(args: &AnalyzeArgs) -> CliResult<()> {
    crate::input::positive_flags(&[
        ("--ball-radius", args.ball_radius),
        ("--bull-radius", args.bull_radius),
        ("--corner-radius", args.corner_radius),
        ("--scallop", args.scallop),
        ("--feed", args.feed),
        ("--acceleration", args.acceleration),
        ("--jerk", args.jerk),
    ])?;
    if args.cells == 0 {
        return Err(Failure::rejected("--cells 0: give at least 1"));
    }
    if let Some(job_args) = job_args(args)? {
        return run(&job_args);
    }
    let loaded = load(&args.part, args.units)?;
    let samples = match &loaded.part {
        Part::Surfaces(set) => sample_surface_set(set, &GridOptions { cells_u: args.cells, cells_v: args.cells })
            .map_err(|e| Failure::rejected(format!("{}: {e}", args.part)))?,
        Part::Mesh(mesh) => sample_mesh(mesh),
    };
    let tools = ToolOptions {
        ball_radius: args.ball_radius,
        toroidal_radius: args.bull_radius,
        corner_radius: args.corner_radius,
    };
    let machine = MachineLimits::from_thesis_units(args.feed, args.acceleration, args.jerk);
    let report = analyze(&samples, &tools, &machine, args.scallop)
        .map_err(|e| Failure::rejected(format!("{}: {e}", args.part)))?;
    if let Some(path) = &args.plot {
        let is_png = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("png"));
        let bytes = if is_png { plot_png(&report) } else { plot_svg(&report).into_bytes() };
        write_atomic(path, |w| std::io::Write::write_all(w, &bytes))?;
    }
    if args.json {
        return print_json(&report);
    }
    print_text(&human(&loaded.description, &report))
}

/// The arguments that analyse a job file's part with its first operation's
/// cutter, scallop height and machine limits; `None` when `args.part` is not a
/// job file (a `.toml` with a `[part]` table).
fn job_args(args: &AnalyzeArgs) -> CliResult<Option<AnalyzeArgs>> {
    let path = std::path::Path::new(&args.part);
    if !path.extension().is_some_and(|e| e.eq_ignore_ascii_case("toml")) {
        return Ok(None);
    }
    let is_job =
        std::fs::read_to_string(path).ok().is_some_and(|t| t.lines().any(|l| l.trim_start().starts_with("[part]")));
    if !is_job {
        return Ok(None);
    }
    let (name, job) = crate::run::read_job(path)?;
    let part = match (&job.part.file, &job.part.builtin) {
        (Some(file), _) => path.parent().unwrap_or(std::path::Path::new(".")).join(file).to_string_lossy().into_owned(),
        (None, Some(builtin)) => builtin.clone(),
        (None, None) => return Err(Failure::rejected(format!("{name}: part: give `file` or `builtin`"))),
    };
    let (c, radius) = (&job.cutter, job.cutter.diameter / 2.0);
    let (ball_radius, bull_radius, corner_radius) = match c.shape {
        ShapeWord::Ball => (radius, radius, args.corner_radius.min(radius)),
        ShapeWord::Bull => (radius, radius, c.corner_radius.unwrap_or(radius)),
        other => {
            return Err(Failure::rejected(format!(
                "{name}: cutter.shape = \"{}\": the analysis compares ball and bull-nose cutters",
                other.word()
            )));
        }
    };
    Ok(Some(AnalyzeArgs {
        part,
        units: UnitsArg::from(job.part.units),
        ball_radius,
        bull_radius,
        corner_radius,
        scallop: job.finishing.scallop_height,
        feed: job.operations[0].feed.map_or(job.machine.feed, |f| f / 1000.0),
        acceleration: job.machine.acceleration,
        jerk: job.machine.jerk,
        cells: args.cells,
        plot: args.plot.clone(),
        json: args.json,
    }))
}

/// The (mu, s) decision plane as a PNG: the ball region (s > s_c) blue, the
/// bull-nose region orange, the critical curve black, the part a red dot;
/// ticks every 15 degrees and every unit of mu, labelled.
fn plot_png(r: &AnalysisReport) -> Vec<u8> {
    use scallop_report::png::Image;
    let (w, h, left, top, pw, ph) = (720usize, 480usize, 60usize, 20usize, 620usize, 400usize);
    let mu_max = (1.15 * r.shape_factor).ceil().max(5.0);
    let mut img = Image::new(w, h, [255, 255, 255]);
    #[allow(clippy::cast_precision_loss)]
    let mu_of = |px: usize| 1.0 + (mu_max - 1.0) * px as f64 / (pw - 1) as f64;
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let row_of = |deg: f64| ((1.0 - deg.clamp(0.0, 90.0) / 90.0) * (ph - 1) as f64).round() as usize;
    for px in 0..pw {
        let s_c = critical_slope(mu_of(px), r.size_mm2, &r.tools, r.scallop_height_mm, &r.machine).to_degrees();
        let curve = row_of(s_c);
        for py in 0..ph {
            let rgb = if py < curve { [214, 229, 245] } else { [253, 228, 204] };
            img.set(left + px, top + py, rgb);
        }
        img.fill(left + px, top + curve.saturating_sub(1), 1, 3, [0, 0, 0]);
    }
    // Axes, ticks and labels (degrees on the left, mu below).
    img.fill(left, top, 2, ph, [0, 0, 0]);
    img.fill(left, top + ph - 1, pw, 2, [0, 0, 0]);
    for deg in (0..=90).step_by(15) {
        let y = top + row_of(f64::from(deg));
        img.fill(left - 6, y, 6, 1, [0, 0, 0]);
        img.text(8, y.saturating_sub(7), &format!("{deg:>2}"), 2, [0, 0, 0]);
    }
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    for mu in 1..=(mu_max as usize) {
        #[allow(clippy::cast_precision_loss)]
        let x = left + ((mu as f64 - 1.0) / (mu_max - 1.0) * (pw - 1) as f64).round() as usize;
        img.fill(x, top + ph, 1, 6, [0, 0, 0]);
        img.text(x.saturating_sub(5), top + ph + 10, &mu.to_string(), 2, [0, 0, 0]);
    }
    // The part.
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, clippy::cast_precision_loss)]
    let px = left + (((r.shape_factor.clamp(1.0, mu_max) - 1.0) / (mu_max - 1.0)) * (pw - 1) as f64).round() as usize;
    let py = top + row_of(r.slope_deg);
    for dy in 0..11usize {
        for dx in 0..11usize {
            let (ex, ey) = (dx.abs_diff(5), dy.abs_diff(5));
            if ex * ex + ey * ey <= 25 {
                img.set((px + dx).saturating_sub(5), (py + dy).saturating_sub(5), [200, 0, 0]);
            }
        }
    }
    img.to_png()
}

/// An XY direction (mod 180 degrees) shown in (-90, 90] without "-0.00" or "-90.00".
fn direction(deg: f64) -> f64 {
    let d = if deg < -89.995 { deg + 180.0 } else { deg };
    if d.abs() < 0.005 { 0.0 } else { d }
}

fn human(part: &str, r: &AnalysisReport) -> String {
    let rec = match r.recommendation {
        Recommendation::BallAlongPrincipal => "ball cutter along the principal direction",
        Recommendation::ToroidalAlongSlope => "bull-nose cutter along the steepest slope",
    };
    let side = if r.slope_deg > r.critical_slope_deg { "steeper" } else { "flatter" };
    let option = |o: &scallop_analysis::ToolOption| {
        format!(
            "{}, {:.0} mm, step-over {:.3} mm, feed at {:.1}°",
            crate::output::hms(o.estimate.time),
            o.estimate.length,
            o.estimate.step_over,
            direction(o.feed_angle_deg)
        )
    };
    let mut text = format!(
        "{part}: {} samples\n\
         \x20 PCA plane      λ = {:.2}, {:.2}, {:.2} mm²; rectangle {:.1} x {:.1} mm\n\
         \x20 shape factor   μ = {:.3}   size χ = {:.1} mm²\n\
         \x20 slope          s = {:.2}° (critical s_c(μ) = {:.2}°: the part is {side})\n\
         \x20 directions     principal {:.2}°, steepest slope {:.2}° (from X)\n\
         \x20 recommended    {rec}\n\
         \x20 bull-nose along the slope      {}\n\
         \x20 ball along the principal dir.  {}\n",
        r.samples,
        r.plane.eigenvalues[0],
        r.plane.eigenvalues[1],
        r.plane.eigenvalues[2],
        r.plane.width,
        r.plane.height,
        r.shape_factor,
        r.size_mm2,
        r.slope_deg,
        r.critical_slope_deg,
        direction(r.principal_direction_deg),
        direction(r.slope_direction_deg),
        option(&r.toroidal_along_slope),
        option(&r.ball_along_principal),
    );
    for note in &r.notes {
        text.push_str(&format!("  note: {note:?}\n"));
    }
    text
}
