//! `scallop analyze`: PCA of the part and the tool-choice advice, before any toolpath.

use std::path::PathBuf;

use clap::Args;
use scallop_analysis::{
    AnalysisReport, GridOptions, MachineLimits, Recommendation, ToolOptions, analyze, plot_svg, sample_mesh,
    sample_surface_set,
};
use scallop_engine::Part;

use crate::output::{print_json, print_text, write_atomic};
use crate::part::{UnitsArg, load};
use crate::{CliResult, Failure};

/// Arguments of `scallop analyze`.
#[derive(Args, Debug)]
pub struct AnalyzeArgs {
    /// Part: mesh file (.stl .obj .ply .3mf), surface file (.toml) or built-in name (choi, rubio).
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
    /// Write the (mu, s) decision plot as SVG.
    #[arg(long)]
    plot: Option<PathBuf>,
    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
}

/// `scallop analyze`.
pub fn run(args: &AnalyzeArgs) -> CliResult<()> {
    for (flag, v) in [
        ("--ball-radius", args.ball_radius),
        ("--bull-radius", args.bull_radius),
        ("--corner-radius", args.corner_radius),
        ("--scallop", args.scallop),
        ("--feed", args.feed),
        ("--acceleration", args.acceleration),
        ("--jerk", args.jerk),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(Failure::rejected(format!("{flag} {v}: must be a finite number > 0")));
        }
    }
    if args.cells == 0 {
        return Err(Failure::rejected("--cells 0: give at least 1"));
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
        let svg = plot_svg(&report);
        write_atomic(path, |w| std::io::Write::write_all(w, svg.as_bytes()))?;
    }
    if args.json {
        return print_json(&report);
    }
    print_text(&human(&loaded.description, &report))
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
            "{:.1} s, {:.0} mm, step-over {:.3} mm, feed at {:.1}°",
            o.estimate.time,
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
