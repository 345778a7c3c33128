//! `scallop rough5`: 5-axis roughing of a test part by guide curves (or the
//! zero-tilt baseline), proven on a tri-dexel stock and posted for a 5-axis
//! machine (docs/rough5.md): `program.nc`, `toolpath.cl` and `report.json`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::{Args, ValueEnum};
use scallop_cutter::{Cutter, CutterShape, HolderSegment};
use scallop_guides::GuideSettings;
use scallop_machine::Kinematics;
use scallop_machine::program::{ProgramOptions, records_of, to_program};
use scallop_parts::FaceTag;
use scallop_post::{OutputMode, PostParams, check_replay, program_text, replay};
use scallop_rough5::{Proof, ProofSettings, Rough5Plan, Rough5Settings, TiltMode, plan_rough5, prove};
use serde::Serialize;

use crate::guides::{LevelArgs, PartArg, test_part};
use crate::output::{print_json, print_text, progress_bar, with_written};
use crate::outset::OutputSet;
use crate::post::{load_dialect, load_machine, program_time};
use crate::{CliResult, Failure};

/// The tool-axis variant.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum TiltArg {
    /// Tool axis +Z on every offset level (the zero-tilt baseline).
    Zero,
    /// Tool axis from the path curve to the tilt curve on the level above (SPU).
    Guides,
}

/// Arguments of `scallop rough5`.
#[derive(Args, Debug)]
pub struct Rough5Args {
    /// Test part.
    #[arg(long, value_enum, default_value = "pocket")]
    part: PartArg,
    /// Tool-axis variant.
    #[arg(long, value_enum, default_value = "guides")]
    tilt: TiltArg,
    /// Torus radius R (mm; the thesis's FRAISA torus R 5 r 1.5).
    #[arg(long, default_value_t = 5.0)]
    tool_radius: f64,
    /// Corner radius r (mm).
    #[arg(long, default_value_t = 1.5)]
    corner: f64,
    /// Flute length (mm; not given in the thesis: 30 mm keeps the shank above the 35 mm block).
    #[arg(long, default_value_t = 30.0)]
    flutes: f64,
    /// Stick-out from the holder (mm).
    #[arg(long, default_value_t = 41.0)]
    stick_out: f64,
    /// Holder diameter and length (mm; the thesis's slender collet chuck).
    #[arg(long, num_args = 2, default_values_t = [27.0, 192.0])]
    holder: Vec<f64>,
    /// Material left on the flanks and on the bottom (mm).
    #[arg(long, num_args = 2, default_values_t = [0.5, 0.5])]
    allowance: Vec<f64>,
    #[command(flatten)]
    levels: LevelArgs,
    /// Spacing of the CL points along a pass (mm).
    #[arg(long, default_value_t = 1.0)]
    step: f64,
    /// Largest tool-axis change between CL points (degrees).
    #[arg(long, default_value_t = 2.0)]
    max_angle_step: f64,
    /// Largest change of the axis's azimuth about Z between CL points (degrees): the C table turns evenly.
    #[arg(long, default_value_t = 5.0)]
    max_azimuth_step: f64,
    /// Cutting feed (mm/min) and spindle speed (1/min): f_z 0.08, z 2, N 15000.
    #[arg(long, num_args = 2, default_values_t = [2400.0, 15000.0])]
    cutting: Vec<f64>,
    /// Tri-dexel resolution of the proof (mm).
    #[arg(long, default_value_t = 0.5)]
    resolution: f64,
    /// Largest deviation of the simulated 5-axis sweeps from the true ones (mm).
    #[arg(long, default_value_t = 0.05)]
    sim_tolerance: f64,
    /// Machine (shipped name or .toml file) and its tool length (mm: stick-out plus holder).
    #[arg(long, default_value = "ucp710")]
    machine: String,
    /// Tool length used by the kinematics (mm).
    #[arg(long, default_value_t = 233.0)]
    tool_length: f64,
    /// Post dialect (shipped name or .toml file).
    #[arg(long, default_value = "siemens840d")]
    dialect: String,
    /// Output folder.
    #[arg(short, long)]
    output: PathBuf,
    /// Print the report as JSON on stdout.
    #[arg(long)]
    json: bool,
}

#[derive(Serialize)]
struct PassJson {
    level: usize,
    pass: usize,
    points: usize,
    dropped: usize,
    runs: usize,
    pitch_deg: [f64; 3],
    max_tilt_deg: f64,
}

#[derive(Serialize)]
struct LevelJson {
    distance_mm: f64,
    passes: usize,
    untilted: Option<String>,
}

#[derive(Serialize)]
struct Metrics {
    volume_to_remove_mm3: f64,
    remaining_volume_mm3: f64,
    remaining_percent: f64,
    removed_volume_mm3: f64,
    gouge_volume_mm3: f64,
    gouge_depth_mm: f64,
    path_length_dm: f64,
    out_of_material_percent: f64,
    machining_time_s: f64,
    /// Time lost to each axis's velocity, acceleration and jerk limits (s).
    axis_time_lost_s: Vec<(String, f64)>,
    feed_time_s: f64,
    rapid_time_s: f64,
    estimated_time_at_feed_s: f64,
    removal_rate_mm3_s: f64,
    removal_rate_percent_s: f64,
}

#[derive(Serialize)]
struct Report {
    command: &'static str,
    part: String,
    tilt: String,
    machine: String,
    dialect: String,
    /// Why the machine or the post refused the program (no `program.nc` then).
    post_error: Option<String>,
    cl_points: usize,
    blocks: usize,
    replay_tip_deviation_mm: f64,
    retracts: usize,
    links: usize,
    ramps: usize,
    metrics: Metrics,
    levels: Vec<LevelJson>,
    passes: Vec<PassJson>,
    plan_seconds: f64,
    proof_seconds: f64,
}

fn check_args(a: &Rough5Args) -> CliResult<()> {
    crate::input::positive_flags(&[
        ("--tool-radius", a.tool_radius),
        ("--corner", a.corner),
        ("--flutes", a.flutes),
        ("--stick-out", a.stick_out),
        ("--step", a.step),
        ("--max-angle-step", a.max_angle_step),
        ("--max-azimuth-step", a.max_azimuth_step),
        ("--resolution", a.resolution),
        ("--sim-tolerance", a.sim_tolerance),
        ("--tool-length", a.tool_length),
    ])?;
    if a.stick_out < a.flutes {
        return Err(Failure::rejected(format!("--stick-out {} is shorter than --flutes {}", a.stick_out, a.flutes)));
    }
    Ok(())
}

fn cutter(a: &Rough5Args) -> CliResult<Cutter> {
    let bad = |e: scallop_cutter::CutterError| {
        Failure::rejected(format!("the tool: {e} (--tool-radius, --corner, --flutes, --holder)"))
    };
    let shape = CutterShape::Bull { radius: a.tool_radius, corner: a.corner };
    let holder = HolderSegment { length: a.holder[1], bottom_radius: a.holder[0] / 2.0, top_radius: a.holder[0] / 2.0 };
    Cutter::new(shape, a.flutes)
        .and_then(|c| c.with_shank(a.tool_radius, a.stick_out - a.flutes))
        .and_then(|c| c.with_holder(vec![holder]))
        .map_err(bad)
}

/// Runs `scallop rough5`.
///
/// # Errors
/// Bad settings, a part without passes, an unsafe program or one the machine
/// cannot run (exit 1); I/O.
pub fn run(args: &Rough5Args) -> CliResult<()> {
    check_args(args)?;
    let clock = Instant::now();
    let (name, part) = test_part(args.part)?;
    let faces = |tags: &[FaceTag]| part.faces(tags).map_err(|e| Failure::rejected(format!("{name}: {e}")));
    let (bottom, flanks) = (faces(&[FaceTag::Bottom])?, faces(&[FaceTag::Flank])?);
    let tool = cutter(args)?;
    let settings = Rough5Settings {
        tilt: match args.tilt {
            TiltArg::Zero => TiltMode::Zero,
            TiltArg::Guides => TiltMode::Guides,
        },
        guides: GuideSettings {
            tool_radius: args.tool_radius,
            flank_allowance: args.allowance[0],
            axial_step: args.levels.ap,
            radial_step: args.levels.ae,
            voxel: args.levels.voxel,
            depth: part.stock.max.z - bottom.bounds().min.z,
        },
        bottom_allowance: args.allowance[1],
        step: args.step,
        max_angle_step: args.max_angle_step.to_radians(),
        max_azimuth_step: args.max_azimuth_step.to_radians(),
        ramp_angle: 5f64.to_radians(),
        clearance: 1.0,
        link_max: 2.0 * args.levels.ae,
        feed: args.cutting[0],
        rapid_rate: 20_000.0,
    };
    let bar = progress_bar(0, "levels");
    let plan = plan_rough5(&bottom, &flanks, &part.stock, &tool, &settings, &|d, t| crate::simulate::show(&bar, d, t))
        .map_err(|e| Failure::rejected(format!("{name}: {e}")))?;
    bar.finish_and_clear();
    let plan_seconds = clock.elapsed().as_secs_f64();
    let bar = progress_bar(0, "tri-dexel proof");
    let proof_settings = ProofSettings { resolution: args.resolution, axis_tolerance: args.sim_tolerance };
    let proof = prove(&plan.toolpath, &tool, &part.stock, &part.mesh, &proof_settings, &|d, t| {
        crate::simulate::show(&bar, d, t);
    })
    .map_err(|e| Failure::rejected(format!("{name}: the program is not safe: {e}")))?;
    bar.finish_and_clear();
    let proof_seconds = clock.elapsed().as_secs_f64() - plan_seconds;
    let posted = post_program(args, &plan);
    let post = posted.as_ref().map(|(_, p)| p).map_err(|e| match e {
        Failure::Rejected(e) | Failure::Io(e) => e.to_string(),
    });
    let report = report(args, name, &plan, &proof, post, [plan_seconds, proof_seconds]);
    let mut out = OutputSet::begin(&args.output, "rough5")?;
    if let Ok((nc, _)) = &posted {
        out.write("program.nc", nc.as_bytes())?;
    }
    out.write("toolpath.cl", scallop_io::cl::write_cl(&plan.toolpath).as_bytes())?;
    let json = serde_json::to_string_pretty(&report).map_err(|e| Failure::Io(e.into()))?;
    out.write("report.json", format!("{json}\n").as_bytes())?;
    let written = out.commit()?;
    // The toolpath and the report are written for inspection; no program.
    posted?;
    if args.json {
        return print_json(&with_written(&report, &written)?);
    }
    print_text(&summary_text(&report, &args.output))
}

/// What the post and the machine said.
struct Posted {
    /// Time lost to each axis's limits (s), by axis name.
    lost: Vec<(String, f64)>,
    blocks: usize,
    replay: f64,
    total: f64,
    feed: f64,
    rapid: f64,
}

/// The program through the machine's kinematics (joint limits checked) and
/// the dialect in TCP form (TRAORI on the 840D), replayed against the CL path.
fn post_program(args: &Rough5Args, plan: &Rough5Plan) -> CliResult<(String, Posted)> {
    let machine = load_machine(&args.machine, Path::new(""), "--machine")?;
    let dialect = load_dialect(&args.dialect)?;
    let kin = Kinematics::new(&machine, args.tool_length);
    let records = records_of(&plan.toolpath);
    let options = ProgramOptions::default();
    let program = to_program(&kin, &records, None, &options)
        .map_err(|e| Failure::rejected(format!("the program on {}: {e}", machine.name())))?;
    let blocks: Vec<_> = program.blocks.iter().map(|b| (b.motion, b.joints, b.feed)).collect();
    let time = program_time(&kin, &blocks).map_err(|e| Failure::rejected(format!("time model: {e}")))?;
    let params = PostParams {
        program: "1000".into(),
        mode: OutputMode::Tcp,
        tool: 1,
        tool_length: args.tool_length,
        spindle: args.cutting[1],
        tol_pos: options.tol_pos,
        tol_ang: options.tol_ang,
        predicted_time: Some(time.total),
    };
    let nc = program_text(&program, &kin, &dialect, &params)
        .map_err(|e| Failure::rejected(format!("{}: {e}", dialect.name)))?;
    let replayed =
        replay(&nc, &dialect, &kin).map_err(|e| Failure::Io(anyhow::anyhow!("our output does not read back: {e}")))?;
    let trip = check_replay(&replayed, &records, &kin, &dialect, options.tol_pos, options.tol_ang)
        .map_err(|e| Failure::Io(anyhow::anyhow!("the program does not replay to the CL path: {e}")))?;
    let lost = machine.axes().iter().zip(time.lost).map(|(a, t)| (a.name.clone(), t)).collect();
    let posted = Posted {
        lost,
        blocks: program.blocks.len(),
        replay: trip.max_tip_deviation,
        total: time.total,
        feed: time.feed,
        rapid: time.rapid,
    };
    Ok((nc, posted))
}

fn report(
    args: &Rough5Args,
    name: &str,
    plan: &Rough5Plan,
    proof: &Proof,
    post: Result<&Posted, String>,
    seconds: [f64; 2],
) -> Report {
    // Without a machine program, the time at the programmed feeds.
    let (t, feed, rapid) =
        post.as_ref().map_or((plan.estimated_time, plan.estimated_time, 0.0), |p| (p.total, p.feed, p.rapid));
    let metrics = Metrics {
        volume_to_remove_mm3: proof.volume_to_remove,
        remaining_volume_mm3: proof.remaining_volume,
        remaining_percent: proof.remaining_percent,
        removed_volume_mm3: proof.removed_volume,
        gouge_volume_mm3: proof.gouge_volume,
        gouge_depth_mm: proof.gouge_depth,
        path_length_dm: proof.cutting_length / 100.0,
        out_of_material_percent: proof.air_percent,
        machining_time_s: t,
        axis_time_lost_s: post.as_ref().map_or_else(|_| Vec::new(), |p| p.lost.clone()),
        feed_time_s: feed,
        rapid_time_s: rapid,
        estimated_time_at_feed_s: plan.estimated_time,
        removal_rate_mm3_s: proof.removal_rate(t),
        removal_rate_percent_s: if t > 0.0 { (100.0 - proof.remaining_percent) / t } else { 0.0 },
    };
    let deg = f64::to_degrees;
    Report {
        command: "rough5",
        part: name.to_string(),
        tilt: format!("{:?}", args.tilt).to_lowercase(),
        machine: args.machine.clone(),
        dialect: args.dialect.clone(),
        cl_points: plan.toolpath.moves().len(),
        blocks: post.as_ref().map_or(0, |p| p.blocks),
        replay_tip_deviation_mm: post.as_ref().map_or(f64::NAN, |p| p.replay),
        post_error: post.err(),
        retracts: plan.retracts,
        links: plan.links,
        ramps: plan.ramps,
        metrics,
        levels: plan
            .levels
            .iter()
            .map(|l| LevelJson { distance_mm: l.distance, passes: l.passes, untilted: l.untilted.clone() })
            .collect(),
        passes: plan
            .passes
            .iter()
            .map(|p| PassJson {
                level: p.level,
                pass: p.pass,
                points: p.points,
                dropped: p.dropped,
                runs: p.runs,
                pitch_deg: p.pitch.map(deg),
                max_tilt_deg: deg(p.max_tilt),
            })
            .collect(),
        plan_seconds: seconds[0],
        proof_seconds: seconds[1],
    }
}

fn summary_text(r: &Report, output: &Path) -> String {
    let m = &r.metrics;
    let mut s = format!(
        "{} ({} tilt): {} levels, {} passes, {} CL points, {} blocks on {} ({})\n",
        r.part,
        r.tilt,
        r.levels.len(),
        r.passes.len(),
        r.cl_points,
        r.blocks,
        r.machine,
        r.dialect
    );
    let _ = writeln!(
        s,
        "  V_r {:.2} % ({:.0} of {:.0} mm3), gouge {:.3} mm3 (deepest {:.3} mm), L_HM {:.1} %",
        m.remaining_percent,
        m.remaining_volume_mm3,
        m.volume_to_remove_mm3,
        m.gouge_volume_mm3,
        m.gouge_depth_mm,
        m.out_of_material_percent
    );
    let _ = writeln!(
        s,
        "  time {} (feed {}, rapid {}), removal rate {:.1} mm3/s ({:.3} %/s), path {:.1} dm",
        crate::output::hms(m.machining_time_s),
        crate::output::hms(m.feed_time_s),
        crate::output::hms(m.rapid_time_s),
        m.removal_rate_mm3_s,
        m.removal_rate_percent_s,
        m.path_length_dm
    );
    let _ = writeln!(
        s,
        "  planned in {:.1} s, proven in {:.1} s; written to {}",
        r.plan_seconds,
        r.proof_seconds,
        output.display()
    );
    s
}
