//! `scallop post`: a part-frame cutter-location file (the `toolpath.csv` that `scallop run`
//! writes, optionally with tool axes and feeds) into a program for a machine and a
//! dialect, proven by replaying it through the forward kinematics, with a machine-aware
//! time report (per-axis peak speeds and the time each axis's limits cost).

use std::path::{Path, PathBuf};

use clap::{Args, ValueEnum};
use scallop_io::cl::read_cl;
use scallop_machine::program::{ProgramOptions, records_of, to_program};
use scallop_machine::{Kinematics, Machine};
use scallop_post::{Dialect, OutputMode, PostParams, check_replay, program_text, replay};
use serde::Serialize;

use crate::input::read_text;
use crate::output::{print_json, print_text, write_atomic};
use crate::{CliResult, Failure};

/// Output form of `scallop post`.
#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum ModeArg {
    /// Joint-space words, inverse-time feeds where the dialect has them.
    Joint,
    /// Tool-centre-point control (G43.4, TRAORI, M128/TCPM).
    Tcp,
    /// 3+2: tilted work planes (G68.2, CYCLE800, PLANE SPATIAL).
    TiltedPlane,
}

/// Arguments of `scallop post`.
#[derive(Args, Debug)]
pub struct PostArgs {
    /// Cutter-location CSV: header `kind,x,y,z[,i,j,k][,feed]` (part frame, mm, mm/min).
    cl_file: PathBuf,
    /// 5-axis machine: a shipped name (see `machines/`, e.g. ucp710, mx330, linuxcnc-xyzac-trt) or a TOML
    /// file (a 3-axis machine is refused: jobs name those, docs/job.md).
    #[arg(long)]
    machine: String,
    /// Dialect: linuxcnc, fanuc, siemens840d, heidenhain, heidenhain-iso, grbl, plain, or a TOML file.
    #[arg(long)]
    dialect: String,
    /// Output form.
    #[arg(long, value_enum, default_value = "joint")]
    mode: ModeArg,
    /// Feed for rows without a `feed` column value (mm/min).
    #[arg(long, default_value_t = 2000.0, allow_hyphen_values = true)]
    feed: f64,
    /// Tool length used by the kinematics (mm; 0 when the controller applies it).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    tool_length: f64,
    /// Tool number.
    #[arg(long, default_value_t = 1)]
    tool: u32,
    /// Spindle speed (1/min).
    #[arg(long, default_value_t = 12000.0, allow_hyphen_values = true)]
    spindle: f64,
    /// Tip tolerance of joint-space interpolation (mm).
    #[arg(long, default_value_t = 0.01, allow_hyphen_values = true)]
    tolerance: f64,
    /// Retract distance along the tool axis of a link that changes branch or unwinds (mm):
    /// the tool backs off this far, the rotaries turn, and it comes back.
    #[arg(long, default_value_t = 10.0, allow_hyphen_values = true)]
    retract: f64,
    /// Rapids bring the pole axis (C) back to its winding nearest zero, the long way if
    /// need be (instead of the shortest move).
    #[arg(long)]
    unwind_rapids: bool,
    /// Program file to write (default: the CL file's name with .nc).
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Time report file to write (JSON; default: beside the program, `post.json`).
    #[arg(long)]
    report: Option<PathBuf>,
    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
}

/// Per-axis figures of the time report.
#[derive(Serialize, Debug)]
pub struct AxisTime {
    /// Axis name.
    pub axis: String,
    /// Peak speed over the feed moves (mm/s or deg/s).
    pub peak_speed: f64,
    /// Its velocity limit (same unit).
    pub max_speed: f64,
    /// Time lost to this axis's velocity, acceleration and jerk limits (s).
    pub time_lost_s: f64,
}

/// `post.json`.
#[derive(Serialize, Debug)]
pub struct PostReport {
    /// Machine name.
    pub machine: String,
    /// Dialect name.
    pub dialect: String,
    /// CL records read.
    pub cl_records: usize,
    /// Program blocks written (after subdivision).
    pub blocks: usize,
    /// Total predicted time (s): feed moves by the look-ahead model, rapids per axis.
    pub total_time_s: f64,
    /// Feed-move time (s).
    pub feed_time_s: f64,
    /// Feed-move time at the programmed feed alone (s).
    pub feed_floor_s: f64,
    /// Rapid time (s).
    pub rapid_time_s: f64,
    /// Per-axis figures.
    pub axes: Vec<AxisTime>,
    /// Largest tip deviation of the replayed program from the CL path (mm).
    pub replay_tip_deviation_mm: f64,
    /// Largest tool-axis deviation of the replayed program (deg).
    pub replay_axis_deviation_deg: f64,
    /// Planner events (branch flips, unwinds, pole holds), as text.
    pub events: Vec<String>,
}

/// A 5-axis machine by shipped name or by TOML file (a relative path taken from
/// `folder`: the job file's folder, or the working folder for `--machine`);
/// `what` names the flag or key in messages.
pub(crate) fn load_machine(name: &str, folder: &Path, what: &str) -> CliResult<Machine> {
    crate::machine::load_five_axis(name, folder, what)
}

pub(crate) fn load_dialect(name: &str) -> CliResult<Dialect> {
    if name.ends_with(".toml") || Path::new(name).is_file() {
        let text = read_text(Path::new(name), "the file")?;
        Dialect::from_toml_str(&text).map_err(|e| Failure::rejected(format!("{name}: {e}")))
    } else {
        Dialect::builtin(name).map_err(|e| Failure::rejected(format!("--dialect {name}: {e}")))
    }
}

/// `scallop post`.
pub fn run(args: &PostArgs) -> CliResult<()> {
    crate::input::positive_flags(&[
        ("--feed", args.feed),
        ("--tolerance", args.tolerance),
        ("--spindle", args.spindle),
        ("--retract", args.retract),
    ])?;
    if !(args.tool_length.is_finite() && args.tool_length >= 0.0) {
        return Err(Failure::rejected(format!("--tool-length {}: must be a finite number >= 0", args.tool_length)));
    }
    let machine = load_machine(&args.machine, Path::new(""), "--machine")?;
    let dialect = load_dialect(&args.dialect)?;
    let text = read_text(&args.cl_file, "the file")?;
    let path = read_cl(&text, args.feed).map_err(|e| Failure::rejected(format!("{}: {e}", args.cl_file.display())))?;
    let records = records_of(&path);
    let kin = Kinematics::new(&machine, args.tool_length);
    let mut options = ProgramOptions { tol_pos: args.tolerance, retract: args.retract, ..ProgramOptions::default() };
    options.plan.unwind_rapids = args.unwind_rapids;
    let program = to_program(&kin, &records, None, &options)
        .map_err(|e| Failure::rejected(format!("{} on {}: {e}", args.cl_file.display(), machine.name())))?;
    let time = program_time(&kin, &program.blocks.iter().map(|b| (b.motion, b.joints, b.feed)).collect::<Vec<_>>())
        .map_err(|e| Failure::rejected(format!("time model: {e}")))?;
    let mode = match args.mode {
        ModeArg::Joint => OutputMode::Joint,
        ModeArg::Tcp => OutputMode::Tcp,
        ModeArg::TiltedPlane => OutputMode::TiltedPlane,
    };
    let params = PostParams {
        program: "1000".into(),
        mode,
        tool: args.tool,
        tool_length: args.tool_length,
        spindle: args.spindle,
        tol_pos: options.tol_pos,
        tol_ang: options.tol_ang,
        predicted_time: Some(time.total),
    };
    let nc = program_text(&program, &kin, &dialect, &params)
        .map_err(|e| Failure::rejected(format!("{} in {}: {e}", args.cl_file.display(), dialect.name)))?;
    // The proof: parse our own output back into joint motion, replay the kinematics.
    // Failures name the program (not yet written) and its block, and the CL file.
    let output = args.output.clone().unwrap_or_else(|| args.cl_file.with_extension("nc"));
    let place = format!("{} (program for {}, block = line of the program)", output.display(), args.cl_file.display());
    let blocks = replay(&nc, &dialect, &kin)
        .map_err(|e| Failure::Io(anyhow::anyhow!("{place}: our output does not read back: {e}")))?;
    let trip = check_replay(&blocks, &records, &kin, &dialect, options.tol_pos, options.tol_ang)
        .map_err(|e| Failure::Io(anyhow::anyhow!("{place}: the program does not replay to the CL path: {e}")))?;
    let axes = machine
        .axes()
        .iter()
        .enumerate()
        .map(|(i, a)| {
            let deg = |v: f64| if a.kind == scallop_machine::AxisKind::Rotary { v.to_degrees() } else { v };
            AxisTime {
                axis: a.name.clone(),
                peak_speed: deg(time.peak[i]),
                max_speed: deg(a.dynamics.vmax),
                time_lost_s: time.lost[i],
            }
        })
        .collect();
    let report = PostReport {
        machine: machine.name().to_string(),
        dialect: dialect.name.clone(),
        cl_records: records.len(),
        blocks: program.blocks.len(),
        total_time_s: time.total,
        feed_time_s: time.feed,
        feed_floor_s: time.floor,
        rapid_time_s: time.rapid,
        axes,
        replay_tip_deviation_mm: trip.max_tip_deviation,
        replay_axis_deviation_deg: trip.max_axis_deviation.to_degrees(),
        events: program.events.iter().map(|e| format!("{e:?}")).collect(),
    };
    let report_path = args.report.clone().unwrap_or_else(|| {
        output.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new(".")).join("post.json")
    });
    let json = serde_json::to_string_pretty(&report).map_err(|e| Failure::Io(e.into()))?;
    write_atomic(&output, |w| std::io::Write::write_all(w, nc.as_bytes()))?;
    write_atomic(&report_path, |w| std::io::Write::write_all(w, format!("{json}\n").as_bytes()))?;
    if args.json {
        print_json(&report)
    } else {
        let mut s = format!(
            "{} -> {} ({}, {}): {} CL records, {} blocks, replay within {:.2e} mm\n\
             predicted time {} (feed {}, floor at the programmed feed {}, rapid {})\n",
            args.cl_file.display(),
            output.display(),
            report.machine,
            report.dialect,
            report.cl_records,
            report.blocks,
            report.replay_tip_deviation_mm,
            crate::output::hms(report.total_time_s),
            crate::output::hms(report.feed_time_s),
            crate::output::hms(report.feed_floor_s),
            crate::output::hms(report.rapid_time_s)
        );
        for a in &report.axes {
            s.push_str(&format!(
                "  {:>2}: peak {:>10.3} of {:>10.3}, time lost {:.3} s\n",
                a.axis, a.peak_speed, a.max_speed, a.time_lost_s
            ));
        }
        print_text(&s)
    }
}

use scallop_engine::program_time;
