//! `scallop rough5`: 5-axis roughing of a test part by guide curves (or the
//! zero-tilt baseline, or the 3-axis z-level and 3+2 baselines of
//! `--baseline`), proven on a tri-dexel stock and posted for a 5-axis
//! machine (docs/rough5.md): `program.nc`, `toolpath.cl` and `report.json`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::{Args, ValueEnum};
use scallop_cutter::Cutter;
use scallop_engine::{
    OnMachine, Posted, Rough5Metrics, TcpWords, TimeShare, post_tcp, rough5_metrics, rough5_settings, time_breakdown,
};
use scallop_guides::GuideSettings;
use scallop_machine::Kinematics;
use scallop_parts::FaceTag;
use scallop_parts::TestPart;
use scallop_rough5::{
    AirSettings, BaselinePlan, BaselineSettings, CuttingData, EntryCount, EntryMode, LevelOptions, OrientSettings,
    Pocket, Proof, ProofSettings, Rough5Plan, Rough5Settings, TiltMode, TorusTool, Weights, plan_rough5_in,
    plan_three_plus_two, plan_zlevel, prove_from_blank,
};
use scallop_toolpath::Toolpath;
use serde::Serialize;

use crate::guides::{LevelArgs, PartArg, test_part};
use crate::output::{print_json, print_text, progress_bar, with_written};
use crate::outset::OutputSet;
use crate::post::{load_dialect, load_machine};
use crate::{CliResult, Failure};

/// The tool-axis variant.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum TiltArg {
    /// Tool axis +Z on every offset level (the zero-tilt baseline).
    Zero,
    /// Tool axis from the path curve to the tilt curve on the level above (SPU).
    Guides,
    /// Guide curves with the optimised reparameterisation of each pass (`--weights`, `--interval`, `--target`).
    Optimised,
}

/// A refinement of the 5-axis programs that `--without` leaves out (docs/rough5.md, "Where the remaining
/// volume was").
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum RefineArg {
    /// The bottom's inner offsets that the sliver rule drops on its coarse facets.
    CentreOffsets,
    /// Where the guide curves of two levels do not pair, pair their own curves by rank from the limit.
    PairByRank,
    /// Inner passes with the axis +Z wherever the vertical tool clears the flanks.
    VerticalInside,
    /// Limit passes with the axis +Z where the vertical tool clears the flanks and leaves a step within the allowance.
    ThinSteps,
    /// Colliding CL points translated away from the flank (thesis Ch. 3 §3, step 3) before they are dropped.
    Translation,
    /// An open pocket's bottom extended across its open edge and cut as a level (its limit closed there).
    OpenBottom,
    /// CL points whose tool lies above the part's blank (the impeller's turned blank) left out as air.
    AirTrim,
    /// Each run entered from the level above where its tool stands, not from that level's highest point.
    LocalEntry,
    /// Vertical stretches in long blocks and their corners rounded (inner passes' convex corners by 0.8 R).
    Corners,
    /// A rest pass along the bottom's limit passes, moved towards the flanks' roots and tilted across where the tool clears them.
    RootRest,
    /// The bottom level's inner passes with the axis along the bottom's normal where it leans (an impeller's hub).
    BottomNormal,
    /// Feeds, links and plunges outside the in-process stock (by `--air-clearance`) written at `--air-feed`.
    AirMoves,
    /// The tilted tool axes of each run smoothed where the smoothed tool is placed clear of the flanks.
    AxisSmoothing,
    /// Closed runs entered by the helix radius, or the ramp along the run, that takes the least time on the
    /// machine's linear axes' acceleration and jerk (else the largest helix that fits).
    EntryDynamics,
    /// All of them: the program of 28 Nov 2026.
    All,
}

/// A collision correction of `--correction` (thesis Ch. 3 §3).
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum CorrectionArg {
    /// Step 1: the axis turned in its correction plane, the pitch angle kept (Eq. 3.31).
    Planar,
    /// Step 2: on the offset levels, the axis turned through the nearest point of an upper level's limit curve (Eq. 3.32).
    Spatial,
}

/// How the runs are entered (`--entry`, docs/rough5.md, "Entries").
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum EntryArg {
    /// A helix where it fits inside a closed pass, else a side entry from outside the stock where a run starts within
    /// reach of its side, else a ramp along a closed run, else a plunge.
    Auto,
    /// A helix where it fits, else a ramp, else a plunge.
    Helix,
    /// A ramp along a closed run, else a plunge (the program before 7 Dec 2026).
    Ramp,
    /// A side entry where one is found, else a ramp, else a plunge.
    Side,
}

impl EntryArg {
    /// The planner's entry mode.
    pub(crate) fn mode(self) -> EntryMode {
        match self {
            EntryArg::Auto => EntryMode::Auto,
            EntryArg::Helix => EntryMode::Helix,
            EntryArg::Ramp => EntryMode::Ramp,
            EntryArg::Side => EntryMode::Side,
        }
    }
}

/// A 3-axis baseline on the same part, tool and cutting data.
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum BaselineArg {
    /// Z-level roughing in one setup, the tool axis +Z.
    Zlevel,
    /// The z-level program, then rest roughing in fixed orientations chosen from the undercuts.
    #[value(name = "3+2")]
    ThreePlusTwo,
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
    /// Plan a 3-axis baseline instead of the 5-axis program (same part, tool, a_p, a_e, allowances,
    /// feed, proof and machine): `zlevel` in one setup, or `3+2` (zlevel, then rest roughing in
    /// setups chosen from the undercut flanks). `--tilt` is then ignored.
    #[arg(long, value_enum)]
    baseline: Option<BaselineArg>,
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
    /// Teeth z, feed per tooth f_z (mm) and spindle speed N (1/min): the feed is z f_z N (2400 mm/min).
    #[arg(long, num_args = 3, default_values_t = [2.0, 0.08, 15000.0])]
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
    /// Weights (beta, phi, tau) of the bounds, fluidity and pitch-target objectives of `--tilt optimised`.
    #[arg(long, num_args = 3, default_values_t = [15.0, 1.2, 1.0])]
    weights: Vec<f64>,
    /// Per-pass weights: (beta, phi, tau) of the passes that leave the finished faces' stock (the bottom
    /// level's passes and each level's limit passes), optimised with `--interval` and `--target`; the other
    /// passes keep `--weights` with `--tilt optimised`, SPU otherwise. Not with `--tilt zero`.
    #[arg(long, num_args = 3)]
    limit_weights: Option<Vec<f64>>,
    /// Interval [theta_tmin, theta_tmax] of the pitch angle for `--tilt optimised` (degrees).
    #[arg(long, num_args = 2, default_values_t = [0.0, 30.0], allow_negative_numbers = true)]
    interval: Vec<f64>,
    /// Target pitch angle theta_tobj for `--tilt optimised` (degrees).
    #[arg(long, default_value_t = 10.0, allow_negative_numbers = true)]
    target: f64,
    /// Collision corrections of Jousselin 2020, Ch. 3 §3 applied before the axis translation (step 3,
    /// on unless `--without translation`), comma-separated; `--correction` alone is `planar`
    /// (docs/rough5.md, "Collision correction"). Off by default: on the closed pocket step 1 keeps V_r
    /// and costs time (and with `--tilt optimised` the post's replay check refuses one block); step 2
    /// changes V_r by less than 0.05 points on the three parts for about 1 % more machine time.
    /// Never applied with `--tilt zero`.
    #[arg(long, value_enum, value_delimiter = ',', num_args = 0..=1, default_missing_value = "planar")]
    correction: Vec<CorrectionArg>,
    /// How the runs are entered: `auto` (a helix where it fits inside a closed pass, else from the stock's side
    /// where a run starts within reach of it, else a ramp along a closed run, else a plunge), `helix`, `ramp`
    /// or `side` (docs/rough5.md, "Entries").
    #[arg(long, value_enum, default_value = "auto")]
    entry: EntryArg,
    /// Feed of the air moves (mm/min): the feeds, links and plunges that lie outside the in-process stock by
    /// `--air-clearance` are written as G1 at this feed (docs/rough5.md, "Air moves"; `--without air-moves`
    /// keeps them at the cutting feed). Default: the UCP 710's linear rapid rate, 30 m/min.
    #[arg(long, default_value_t = 30_000.0)]
    air_feed: f64,
    /// Clearance between the tool and the in-process stock for a move to be written at the air feed (mm).
    #[arg(long, default_value_t = 1.0)]
    air_clearance: f64,
    /// Leave out refinements of the 5-axis programs, comma-separated (default: all of them are on).
    #[arg(long, value_enum, value_delimiter = ',')]
    without: Vec<RefineArg>,
    /// Run the six orientation weightings of the thesis (Ch. 3 §2.3) on the last pass of one level
    /// instead of planning the pocket: writes `orientation.csv` (pitch traces) and `orientation.json`.
    #[arg(long)]
    orientation_cases: bool,
    /// Level of the orientation cases (0 = bottom; default: the lowest level with tilt curves).
    #[arg(long)]
    case_level: Option<usize>,
    /// Output folder.
    #[arg(short, long)]
    output: PathBuf,
    /// Print the report as JSON on stdout.
    #[arg(long)]
    json: bool,
    /// Also write `block_times.csv`: every block of the machine program with its time and what sets it
    /// (the feed, the orientation feed or an axis's velocity; docs/rough5.md, "Where the machine time goes").
    #[arg(long)]
    block_times: bool,
}

#[derive(Serialize)]
struct PassJson {
    level: usize,
    pass: usize,
    points: usize,
    dropped: usize,
    corrected: usize,
    /// CL points whose axis the spatial correction (step 2) turned.
    spatial: usize,
    /// CL points the axis translation (step 3) moved.
    translated: usize,
    runs: usize,
    pitch_deg: [f64; 3],
    max_tilt_deg: f64,
}

#[derive(Serialize)]
struct LevelJson {
    distance_mm: f64,
    passes: usize,
    untilted: Option<String>,
    /// Why the guide curves did not pair, when the passes were paired by rank instead.
    paired_by_rank: Option<String>,
}

/// One fixed orientation of a baseline.
#[derive(Serialize)]
struct SetupJson {
    axis: [f64; 3],
    tilt_deg: f64,
    undercut_area_mm2: f64,
    levels: usize,
    passes: usize,
    links: usize,
    retracts: usize,
    helices: usize,
}

/// Entries by kind.
#[derive(Serialize)]
pub(crate) struct EntriesJson {
    helix: usize,
    ramp: usize,
    side: usize,
    plunge: usize,
}

impl EntriesJson {
    pub(crate) fn of(e: &EntryCount) -> Self {
        EntriesJson { helix: e.helix, ramp: e.ramp, side: e.side, plunge: e.plunge }
    }
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
    /// Entries by kind: helix, ramp, side, plunge.
    entries: EntriesJson,
    /// The pass starts entered by a plunge into material (tool tips, mm).
    plunged_at: Vec<[f64; 3]>,
    metrics: Rough5Metrics,
    /// The machine time by what the moves are for and how they are written, and what sets it.
    time_breakdown: Vec<TimeShare>,
    levels: Vec<LevelJson>,
    passes: Vec<PassJson>,
    /// The setups of a 3-axis baseline (empty for the 5-axis programs).
    setups: Vec<SetupJson>,
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
    TorusTool {
        radius: a.tool_radius,
        corner: a.corner,
        flutes: a.flutes,
        stick_out: a.stick_out,
        holder_diameter: a.holder[0],
        holder_length: a.holder[1],
    }
    .cutter()
    .map_err(bad)
}

/// The planning settings of the arguments.
fn settings(args: &Rough5Args, part: &TestPart) -> CliResult<Rough5Settings> {
    let weights = Weights { bounds: args.weights[0], fluidity: args.weights[1], pitch: args.weights[2] };
    let on = |r: RefineArg| !args.without.iter().any(|w| *w == r || *w == RefineArg::All);
    let base = rough5_settings(part, args.tool_radius, (args.levels.ap, args.levels.ae), cutting_feed(args)?)
        .map_err(|e| Failure::rejected(e.to_string()))?;
    Ok(Rough5Settings {
        tilt: match args.tilt {
            TiltArg::Zero => TiltMode::Zero,
            TiltArg::Guides | TiltArg::Optimised => TiltMode::Guides,
        },
        guides: GuideSettings { flank_allowance: args.allowance[0], voxel: args.levels.voxel, ..base.guides },
        bottom_allowance: args.allowance[1],
        step: args.step,
        max_angle_step: args.max_angle_step.to_radians(),
        max_azimuth_step: args.max_azimuth_step.to_radians(),
        orientation: matches!(args.tilt, TiltArg::Optimised).then(|| orientation(args, weights)),
        limit_orientation: args
            .limit_weights
            .as_ref()
            .filter(|_| !matches!(args.tilt, TiltArg::Zero))
            .map(|w| orientation(args, Weights { bounds: w[0], fluidity: w[1], pitch: w[2] })),
        correct: args.correction.contains(&CorrectionArg::Planar) && !matches!(args.tilt, TiltArg::Zero),
        levels: LevelOptions {
            centre_offsets: on(RefineArg::CentreOffsets),
            pair_by_rank: on(RefineArg::PairByRank),
            open_bottom: on(RefineArg::OpenBottom),
        },
        vertical_inside: on(RefineArg::VerticalInside),
        vertical_thin_steps: on(RefineArg::ThinSteps),
        spatial: args.correction.contains(&CorrectionArg::Spatial) && !matches!(args.tilt, TiltArg::Zero),
        translate: on(RefineArg::Translation),
        local_entry: on(RefineArg::LocalEntry),
        smooth_axes: on(RefineArg::AxisSmoothing),
        entry_dynamics: if on(RefineArg::EntryDynamics) {
            scallop_engine::path_dynamics(&load_machine(&args.machine, Path::new(""), "--machine")?)
        } else {
            None
        },
        round_corners: on(RefineArg::Corners),
        root_rest: on(RefineArg::RootRest),
        bottom_normal: on(RefineArg::BottomNormal),
        entry: args.entry.mode(),
        air: on(RefineArg::AirMoves).then_some(AirSettings {
            feed: args.air_feed,
            clearance: args.air_clearance,
            resolution: args.resolution,
            axis_tolerance: args.sim_tolerance,
        }),
        ..base
    })
}

/// The orientation settings of `--weights`, `--interval` and `--target`.
fn orientation(args: &Rough5Args, weights: Weights) -> OrientSettings {
    OrientSettings {
        interval: [args.interval[0].to_radians(), args.interval[1].to_radians()],
        target: args.target.to_radians(),
        ..OrientSettings::new(weights)
    }
}

/// The feed z f_z N of `--cutting` (mm/min).
fn cutting_feed(a: &Rough5Args) -> CliResult<f64> {
    let teeth = a.cutting[0];
    if !(teeth.fract() == 0.0 && (1.0..=64.0).contains(&teeth)) {
        return Err(Failure::rejected(format!("--cutting: {teeth} teeth: give a whole number of teeth (1 to 64)")));
    }
    let data = CuttingData { teeth: teeth as u32, feed_per_tooth: a.cutting[1], spindle: a.cutting[2] };
    data.feed().map_err(|e| Failure::rejected(format!("--cutting: {e}")))
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
    let settings = settings(args, &part)?;
    if args.orientation_cases {
        return cases::run(args, name, &part, (&bottom, &flanks), &tool, &settings);
    }
    let (plan, setups) = if let Some(which) = args.baseline {
        let max_tilt = machine_tilt(args)?;
        baseline(args, (which, max_tilt), &part, &tool, &settings)
            .map_err(|e| Failure::rejected(format!("{name}: {e}")))?
    } else {
        let bar = progress_bar(0, "levels");
        let blank = part
            .blank
            .as_ref()
            .filter(|_| !args.without.iter().any(|w| matches!(w, RefineArg::AirTrim | RefineArg::All)));
        let plan = plan_rough5_in(&bottom, &flanks, (&part.stock, blank), &tool, &settings, &|d, t| {
            crate::simulate::show(&bar, d, t);
        })
        .map_err(|e| Failure::rejected(format!("{name}: {e}")))?;
        bar.finish_and_clear();
        (plan, Vec::new())
    };
    let plan_seconds = clock.elapsed().as_secs_f64();
    let bar = progress_bar(0, "tri-dexel proof");
    let proof_settings = ProofSettings { resolution: args.resolution, axis_tolerance: args.sim_tolerance };
    let proof = prove_from_blank(
        &plan.toolpath,
        &tool,
        &part.stock,
        part.blank.as_ref(),
        &part.mesh,
        &proof_settings,
        &|d, t| {
            crate::simulate::show(&bar, d, t);
        },
    )
    .map_err(|e| Failure::rejected(format!("{name}: the program is not safe: {e}")))?;
    bar.finish_and_clear();
    if proof.gouge_depth > args.sim_tolerance {
        let [x, y, z] = proof.gouge_at.unwrap_or_default();
        return Err(Failure::rejected(format!(
            "{name}: the program is not safe: it removes {:.1} mm3 outside the volume to remove, {:.3} mm deep along Z \
             near ({x:.3}, {y:.3}, {z:.3}) (tolerance --sim-tolerance {} mm); nothing was written",
            proof.gouge_volume, proof.gouge_depth, args.sim_tolerance
        )));
    }
    let proof_seconds = clock.elapsed().as_secs_f64() - plan_seconds;
    let posted = post_program(args, &plan);
    let post = posted.as_ref().map_err(|e| match e {
        Failure::Rejected(e) | Failure::Io(e) => e.to_string(),
    });
    let mut report = report(args, name, &plan, &proof, post, [plan_seconds, proof_seconds]);
    report.setups = setups;
    let mut out = OutputSet::begin(&args.output, "rough5")?;
    if let Ok(p) = &posted {
        out.write("program.nc", p.text.as_bytes())?;
        if args.block_times {
            out.write("block_times.csv", block_csv(&plan, p).as_bytes())?;
        }
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

/// The toolpath through the machine's kinematics (joint limits checked) and
/// its time model.
fn on_machine(args: &Rough5Args, path: &Toolpath) -> CliResult<OnMachine> {
    let machine = load_machine(&args.machine, Path::new(""), "--machine")?;
    let kin = Kinematics::new(&machine, args.tool_length);
    scallop_engine::on_machine(&kin, path).map_err(|e| Failure::rejected(e.to_string()))
}

/// The program through the machine's kinematics (joint limits checked) and
/// the dialect in TCP form (TRAORI on the 840D), replayed against the CL path.
fn post_program(args: &Rough5Args, plan: &Rough5Plan) -> CliResult<Posted> {
    let machine = load_machine(&args.machine, Path::new(""), "--machine")?;
    let kin = Kinematics::new(&machine, args.tool_length);
    let dialect = load_dialect(&args.dialect)?;
    let words = TcpWords { program: "1000".into(), tool: 1, tool_length: args.tool_length, spindle: args.cutting[2] };
    post_tcp(&kin, &plan.toolpath, &dialect, &words).map_err(|e| Failure::rejected(e.to_string()))
}

fn report(
    args: &Rough5Args,
    name: &str,
    plan: &Rough5Plan,
    proof: &Proof,
    post: Result<&Posted, String>,
    seconds: [f64; 2],
) -> Report {
    let metrics = rough5_metrics(plan, proof, post.as_ref().ok().copied());
    let breakdown =
        post.as_ref().map_or_else(|_| Vec::new(), |p| time_breakdown(&p.block_times, &|i| move_label(plan, i)));
    let deg = f64::to_degrees;
    Report {
        command: "rough5",
        part: name.to_string(),
        tilt: match args.baseline {
            Some(BaselineArg::Zlevel) => "zlevel (3-axis baseline)".into(),
            Some(BaselineArg::ThreePlusTwo) => "3+2 (3-axis baseline)".into(),
            None => format!("{:?}", args.tilt).to_lowercase(),
        },
        machine: args.machine.clone(),
        dialect: args.dialect.clone(),
        cl_points: plan.toolpath.moves().len(),
        blocks: post.as_ref().map_or(0, |p| p.blocks),
        replay_tip_deviation_mm: post.as_ref().map_or(f64::NAN, |p| p.replay_tip_deviation),
        post_error: post.err(),
        retracts: plan.retracts,
        links: plan.links,
        ramps: plan.ramps,
        entries: EntriesJson::of(&plan.entries),
        plunged_at: plan.plunged_at.iter().map(|p| [p.x, p.y, p.z]).collect(),
        metrics,
        time_breakdown: breakdown,
        levels: plan
            .levels
            .iter()
            .map(|l| LevelJson {
                distance_mm: l.distance,
                passes: l.passes,
                untilted: l.untilted.clone(),
                paired_by_rank: l.paired_by_rank.clone(),
            })
            .collect(),
        passes: plan
            .passes
            .iter()
            .map(|p| PassJson {
                level: p.level,
                pass: p.pass,
                points: p.points,
                dropped: p.dropped,
                corrected: p.corrected,
                spatial: p.spatial,
                translated: p.translated,
                runs: p.runs,
                pitch_deg: p.pitch.map(deg),
                max_tilt_deg: deg(p.max_tilt),
            })
            .collect(),
        setups: Vec::new(),
        plan_seconds: seconds[0],
        proof_seconds: seconds[1],
    }
}

/// What move `i` of the plan is for and how it is written: `role kind`, with
/// `(air)` for a move at the air feed (`cut feed`, `retract link`, `entry
/// feed (air)`, ...); the kind alone without roles (the baselines).
fn move_label(plan: &Rough5Plan, i: usize) -> String {
    let Some(m) = plan.toolpath.moves().get(i) else { return "other".into() };
    let kind = format!("{:?}", m.kind).to_lowercase();
    let air = if scallop_rough5::is_air_move(&plan.toolpath, i) { " (air)" } else { "" };
    match plan.roles.get(i) {
        Some(r) => format!("{} {kind}{air}", r.name()),
        None => format!("{kind}{air}"),
    }
}

/// `block_times.csv`: one line per block of the machine program.
fn block_csv(plan: &Rough5Plan, posted: &Posted) -> String {
    let mut s = String::from(
        "block,move,label,length_mm,feed_mm_min,time_s,at_feed_s,at_velocity_s,bound,rotary_only_s,linear_only_s\n",
    );
    for b in &posted.block_times {
        let _ = writeln!(
            s,
            "{},{},{},{:.4},{:.0},{:.6},{:.6},{:.6},{},{:.6},{:.6}",
            b.block,
            b.cl_index,
            move_label(plan, b.cl_index),
            b.length_mm,
            b.feed_mm_min,
            b.time_s,
            b.at_feed_s,
            b.at_velocity_s,
            b.bound,
            b.rotary_only_s,
            b.linear_only_s
        );
    }
    s
}

/// The largest tilt of the tool axis from +Z the machine allows: the largest
/// stop of its rotary axes that are not vertical (a quarter turn without
/// stops).
fn machine_tilt(args: &Rough5Args) -> CliResult<f64> {
    let machine = load_machine(&args.machine, Path::new(""), "--machine")?;
    let tilt = machine
        .axes()
        .iter()
        .filter(|a| matches!(a.kind, scallop_machine::AxisKind::Rotary) && a.direction.z.abs() < 0.5)
        .map(|a| a.limits.map_or(std::f64::consts::FRAC_PI_2, |(lo, hi)| lo.abs().max(hi.abs())))
        .fold(0.0, f64::max);
    Ok(tilt.min(std::f64::consts::FRAC_PI_2))
}

/// Plans a 3-axis baseline (`--baseline`) with the settings of the 5-axis
/// program, as a plan the rest of the command proves, posts and reports.
fn baseline(
    args: &Rough5Args,
    (which, max_tilt): (BaselineArg, f64),
    part: &scallop_parts::TestPart,
    tool: &Cutter,
    settings: &Rough5Settings,
) -> Result<(Rough5Plan, Vec<SetupJson>), String> {
    let faces = |tags: &[FaceTag]| part.faces(tags).map_err(|e| e.to_string());
    let (surface, opening) = (faces(&[FaceTag::Bottom, FaceTag::Flank])?, faces(&[FaceTag::Top])?);
    let flanks = faces(&[FaceTag::Flank])?;
    let pocket = Pocket {
        surface: &surface,
        opening: &opening,
        flanks: &flanks,
        volume: &part.mesh,
        stock: part.stock,
        blank: part.blank.as_ref(),
    };
    let s = BaselineSettings {
        stepdown: settings.guides.axial_step,
        stepover: settings.guides.radial_step,
        flank_allowance: settings.guides.flank_allowance,
        bottom_allowance: settings.bottom_allowance,
        feed: settings.feed,
        rapid_rate: settings.rapid_rate,
        clearance: settings.clearance,
        max_tilt,
        resolution: args.resolution,
        axis_tolerance: args.sim_tolerance,
    };
    let plan: BaselinePlan = match which {
        BaselineArg::Zlevel => plan_zlevel(&pocket, tool, &s),
        BaselineArg::ThreePlusTwo => plan_three_plus_two(&pocket, tool, &s),
    }
    .map_err(|e| e.to_string())?;
    let setups = plan
        .setups
        .iter()
        .map(|u| SetupJson {
            axis: [u.axis.x, u.axis.y, u.axis.z],
            tilt_deg: u.axis.angle(&scallop_geom::Vec3::z()).to_degrees(),
            undercut_area_mm2: u.undercut_area,
            levels: u.levels,
            passes: u.passes,
            links: u.links,
            retracts: u.retracts,
            helices: u.helices,
        })
        .collect();
    let sum = |f: fn(&scallop_rough5::SetupReport) -> usize| plan.setups.iter().map(f).sum();
    let as_plan = Rough5Plan {
        retracts: sum(|u| u.retracts),
        links: sum(|u| u.links),
        ramps: sum(|u| u.helices),
        entries: EntryCount { helix: sum(|u| u.helices), ..EntryCount::default() },
        plunged_at: Vec::new(),
        toolpath: plan.toolpath,
        levels: Vec::new(),
        passes: Vec::new(),
        estimated_time: plan.estimated_time,
        air: None,
        roles: Vec::new(),
    };
    Ok((as_plan, setups))
}

/// The program's spec 10.1 figures as two summary lines, each after
/// `indent`: what is left and cut outside the volume, then the machine time
/// and the removal rate (`scallop rough5` and a job's rough5 operation).
pub(crate) fn metric_lines(s: &mut String, m: &Rough5Metrics, indent: &str) {
    let _ = writeln!(
        s,
        "{indent}V_r {:.2} % ({:.0} of {:.0} mm3), gouge {:.3} mm3 (deepest {:.3} mm), out of material (L_HM) {:.1} % \
         ({:.1} % in {} moves at the air feed)",
        m.remaining_percent,
        m.remaining_volume_mm3,
        m.volume_to_remove_mm3,
        m.gouge_volume_mm3,
        m.gouge_depth_mm,
        m.out_of_material_percent,
        m.air_feed_percent,
        m.air_moves
    );
    let _ = writeln!(
        s,
        "{indent}time {} on the machine (feed {}, rapid {}), removal rate {:.1} mm3/s ({:.3} %/s), path {:.1} dm",
        crate::output::hms(m.machining_time_s),
        crate::output::hms(m.feed_time_s),
        crate::output::hms(m.rapid_time_s),
        m.removal_rate_mm3_s,
        m.removal_rate_percent_s,
        m.path_length_dm
    );
    let _ = match (m.min_stick_out_move, m.min_stick_out_at_mm) {
        (Some(k), Some([x, y, z])) => writeln!(
            s,
            "{indent}minimum collision-free stick-out {:.2} mm (move {k}, stock at ({x:.3}, {y:.3}, {z:.3}))",
            m.min_stick_out_mm
        ),
        _ => writeln!(s, "{indent}minimum collision-free stick-out {:.2} mm (the flutes alone)", m.min_stick_out_mm),
    };
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
    for (k, u) in r.setups.iter().enumerate() {
        let _ = writeln!(
            s,
            "  setup {}: axis ({:.3}, {:.3}, {:.3}) tilted {:.1} deg, {} levels, {} passes",
            k + 1,
            u.axis[0],
            u.axis[1],
            u.axis[2],
            u.tilt_deg,
            u.levels,
            u.passes
        );
    }
    metric_lines(&mut s, m, "  ");
    let corrected: usize = r.passes.iter().map(|p| p.corrected).sum();
    let spatial: usize = r.passes.iter().map(|p| p.spatial).sum();
    let translated: usize = r.passes.iter().map(|p| p.translated).sum();
    let dropped: usize = r.passes.iter().map(|p| p.dropped).sum();
    let _ = writeln!(
        s,
        "  flank collisions: {corrected} CL points turned in their plane (step 1), {spatial} turned through an upper \
         limit curve (step 2), {translated} translated (step 3), {dropped} dropped"
    );
    let e = &r.entries;
    let _ = writeln!(
        s,
        "  entries: {} helices, {} ramps, {} from the side, {} plunges; {} retracts, {} links",
        e.helix, e.ramp, e.side, e.plunge, r.retracts, r.links
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

/// `scallop rough5 --orientation-cases`: the six weightings of the thesis
/// (Jousselin 2020, Ch. 3 §2.3, Tables 3.3-3.4) on the last pass of one
/// level, each with its pitch trace and its machining time (docs/rough5.md).
mod cases {
    use std::fmt::Write as _;

    use scallop_geom::Point3;
    use scallop_mesh::TriMesh;
    use scallop_parts::TestPart;
    use scallop_rough5::{
        OrientSettings, Rough5Settings, SinglePass, TiltMode, Weights, level_passes, plan_single_pass,
    };
    use serde::Serialize;

    use super::{Rough5Args, on_machine};
    use crate::output::{print_json, print_text, with_written};
    use crate::outset::OutputSet;
    use crate::{CliResult, Failure};

    /// (name, (beta, phi, tau), interval, target) in degrees.
    const CASES: [(&str, [f64; 3], [f64; 2], f64); 6] = [
        ("SPU", [0.0, 0.0, 0.0], [0.0, 30.0], 10.0),
        ("mixed", [15.0, 1.2, 1.0], [0.0, 30.0], 10.0),
        ("fluidity", [0.0, 1.0, 0.0], [0.0, 30.0], 10.0),
        ("positive bounds", [1.0, 0.0, 0.0], [0.0, 30.0], 10.0),
        ("negative bounds", [1.0, 0.0, 0.0], [-30.0, 0.0], 10.0),
        ("compromise", [5.0, 10.0, 0.0], [-45.0, 0.0], 10.0),
    ];

    #[derive(Serialize)]
    struct CaseJson {
        case: usize,
        name: &'static str,
        weights: [f64; 3],
        interval_deg: [f64; 2],
        target_deg: f64,
        objective: f64,
        spu_objective: f64,
        iterations: usize,
        constraint_violation: f64,
        coefficients: [f64; 8],
        points: usize,
        dropped: usize,
        runs: usize,
        pitch_deg: [f64; 3],
        max_tilt_deg: f64,
        machining_time_s: f64,
        estimated_time_at_feed_s: f64,
        time_gain_percent: f64,
    }

    #[derive(Serialize)]
    struct Summary {
        command: &'static str,
        part: String,
        level: usize,
        level_distance_mm: f64,
        pass: usize,
        machine: String,
        cases: Vec<CaseJson>,
    }

    /// Runs the six cases.
    pub(super) fn run(
        args: &Rough5Args,
        name: &str,
        part: &TestPart,
        (bottom, flanks): (&TriMesh, &TriMesh),
        tool: &scallop_cutter::Cutter,
        settings: &Rough5Settings,
    ) -> CliResult<()> {
        let fail = |e: scallop_rough5::Rough5Error| Failure::rejected(format!("{name}: {e}"));
        let levels = level_passes(bottom, flanks, &settings.guides, TiltMode::Guides).map_err(fail)?;
        let paired = |j: &usize| levels[*j].untilted.is_none() && !levels[*j].passes.is_empty();
        let j = match args.case_level {
            Some(j) if j < levels.len() && paired(&j) => j,
            Some(j) => return Err(Failure::rejected(format!("--case-level {j}: that level has no tilt curves"))),
            None => (0..levels.len())
                .find(paired)
                .ok_or_else(|| Failure::rejected(format!("{name}: no level has tilt curves")))?,
        };
        let level = &levels[j];
        let pass = level.passes.len() - 1;
        let path = &level.passes[pass].0;
        // The entry point: the middle of the front (-y) side of the stock.
        let entry = Point3::new(part.stock.center().x, part.stock.min.y, path.line.points[0].z);
        let mut csv = String::from("case,name,point,distance_mm,theta_t_deg\n");
        let mut cases = Vec::new();
        for (k, (label, w, interval, target)) in CASES.iter().enumerate() {
            let orient = OrientSettings {
                interval: interval.map(f64::to_radians),
                target: target.to_radians(),
                ..OrientSettings::new(Weights { bounds: w[0], fluidity: w[1], pitch: w[2] })
            };
            let s = Rough5Settings { orientation: Some(orient), ..*settings };
            let single =
                plan_single_pass((level, pass, j == 0), &entry, (&part.stock, flanks), tool, &s).map_err(fail)?;
            for (i, (d, t)) in single.trace.iter().enumerate() {
                let _ = writeln!(csv, "{},{label},{i},{d:.4},{:.5}", k + 1, t.to_degrees());
            }
            let run = on_machine(args, &single.toolpath)?;
            cases.push(case_json(k + 1, label, (w, interval, *target), &single, run.time.total));
        }
        let spu_time = cases[0].machining_time_s;
        for c in &mut cases {
            c.time_gain_percent = 100.0 * (spu_time - c.machining_time_s) / spu_time;
        }
        let summary = Summary {
            command: "rough5 --orientation-cases",
            part: name.to_string(),
            level: j,
            level_distance_mm: level.distance,
            pass,
            machine: args.machine.clone(),
            cases,
        };
        let mut out = OutputSet::begin(&args.output, "rough5")?;
        out.write("orientation.csv", csv.as_bytes())?;
        let json = serde_json::to_string_pretty(&summary).map_err(|e| Failure::Io(e.into()))?;
        out.write("orientation.json", format!("{json}\n").as_bytes())?;
        let written = out.commit()?;
        if args.json {
            return print_json(&with_written(&summary, &written)?);
        }
        print_text(&text(&summary))
    }

    fn case_json(
        case: usize,
        name: &'static str,
        (w, interval, target): (&[f64; 3], &[f64; 2], f64),
        single: &SinglePass,
        machining_time_s: f64,
    ) -> CaseJson {
        let o = single.orientation;
        CaseJson {
            case,
            name,
            weights: *w,
            interval_deg: *interval,
            target_deg: target,
            objective: o.map_or(0.0, |o| o.objective),
            spu_objective: o.map_or(0.0, |o| o.spu_objective),
            iterations: o.map_or(0, |o| o.iterations),
            constraint_violation: o.map_or(0.0, |o| o.violation),
            coefficients: o.map_or(scallop_rough5::Reparam::SPU.x, |o| o.reparam.x),
            points: single.report.points,
            dropped: single.report.dropped,
            runs: single.report.runs,
            pitch_deg: single.report.pitch.map(f64::to_degrees),
            max_tilt_deg: single.report.max_tilt.to_degrees(),
            machining_time_s,
            estimated_time_at_feed_s: single.estimated_time,
            time_gain_percent: 0.0,
        }
    }

    fn text(s: &Summary) -> String {
        let mut t = format!(
            "{}: orientation cases on level {} ({:.2} mm), pass {} (the last), on {}\n",
            s.part, s.level, s.level_distance_mm, s.pass, s.machine
        );
        let _ =
            writeln!(t, "  case  name              theta_t min/max/mean (deg)   time (s)  gain vs SPU  points dropped");
        for c in &s.cases {
            let _ = writeln!(
                t,
                "  {:>4}  {:<16}  {:>7.2} {:>7.2} {:>7.2}       {:>8.1}  {:>10.1} %  {:>6} {:>7}",
                c.case,
                c.name,
                c.pitch_deg[0],
                c.pitch_deg[1],
                c.pitch_deg[2],
                c.machining_time_s,
                c.time_gain_percent,
                c.points,
                c.dropped
            );
        }
        t
    }
}
