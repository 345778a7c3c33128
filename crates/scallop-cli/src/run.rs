//! `scallop run JOB.toml`: a finishing job from a job file (`docs/job.md`).

use std::path::{Path, PathBuf};

use clap::Args;
use scallop_cutter::{Cutter, CutterShape};
use scallop_engine::{FinishJob, Job, Operation, OutputOptions, Setup, StockShape, Strategy};
use scallop_geom::Aabb3;
use scallop_geom::Tolerances;
use scallop_geom::nalgebra::Rotation3;
use scallop_io::job::{
    DirectionSpec, IsoWord, JobFile, LeadWord, PatternWord, ShapeWord, StrategyWord, parse_job_with_tools,
    tool_library_of,
};
use scallop_strategy::{IsoDirection, LeadKind, Pattern};

use crate::output::{progress_bar, write_finishing, write_job};
use crate::part::{UnitsArg, load};
use crate::{CliResult, Failure};

/// Arguments of `scallop run`.
#[derive(Args, Debug)]
pub struct RunArgs {
    /// The job file (TOML, see docs/job.md).
    job: PathBuf,
    /// Output folder for `program.nc`, `report.json`, `toolpath.csv`, `report.html` and `scene.glb`.
    #[arg(short, long, default_value = "out/run")]
    output: PathBuf,
    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
    /// Print what each operation will do (strategy, direction, expected planes, length and
    /// time) from the analysis and the spacing rule, without planning; writes nothing.
    #[arg(long)]
    plan_only: bool,
}

/// `scallop run`.
pub fn run(args: &RunArgs) -> CliResult<()> {
    let (name, spec) = read_job(&args.job)?;
    if spec.part.test_part.is_some() {
        if args.plan_only {
            return Err(Failure::rejected(format!(
                "{name}: --plan-only has no estimate for kind = \"rough5\" operations yet; run the job without it"
            )));
        }
        return crate::rough5_job::run(&spec, &args.job, &name, &args.output, args.json);
    }
    let job = finish_job(&spec, args.job.parent().unwrap_or(Path::new("."))).map_err(|e| match e {
        Failure::Rejected(e) => Failure::Rejected(anyhow::anyhow!("{name}: {e:#}")),
        other => other,
    })?;
    if args.plan_only {
        let job = if spec.operation_list {
            operations_job(&spec, job)?
        } else {
            Job { stock: None, operations: vec![Operation { name: "finish".into(), finish: job, rough: None }] }
        };
        return plan_only(&name, &job, args.json);
    }
    if spec.operation_list {
        let engine_job = operations_job(&spec, job).map_err(|e| match e {
            Failure::Rejected(e) => Failure::Rejected(anyhow::anyhow!("{name}: {e:#}")),
            other => other,
        })?;
        let start = std::time::Instant::now();
        let out = run_operations(&engine_job).map_err(|e| Failure::rejected(format!("{name}: {e}{}", job_keys(&e))))?;
        check_travel(&spec, &args.job, &name, &out.toolpath)?;
        let command = format!("scallop run {name}");
        return write_job(&engine_job, &out, start.elapsed().as_secs_f64(), &args.output, args.json, &command);
    }
    let start = std::time::Instant::now();
    let out = run_one(&job).map_err(|e| Failure::rejected(format!("{name}: {e}{}", job_keys(&e))))?;
    check_travel(&spec, &args.job, &name, &out.toolpath)?;
    let command = format!("scallop run {name}");
    write_finishing(&job, &out, start.elapsed().as_secs_f64(), &args.output, args.json, &command)
}

/// The job of `scallop demo --rough`: `examples/jobs/pocket-rest.toml` with its
/// part, `examples/parts/pocket.stl`, both embedded in the binary (a block
/// with a pocket roughed by a 10 mm end mill, rest-roughed in its corners by a
/// 4 mm one, finished by a 4 mm ball; docs/roughing.md).
const ROUGH_DEMO_JOB: &str = include_str!("../../../examples/jobs/pocket-rest.toml");
const ROUGH_DEMO_PART: &[u8] = include_bytes!("../../../examples/parts/pocket.stl");

/// `scallop demo --rough`: roughing, rest roughing and finishing of the
/// embedded pocket on one stock, written like `scallop run` writes a job.
pub(crate) fn rough_demo(output: &Path, json: bool) -> CliResult<()> {
    let name = "the built-in roughing demo";
    let spec = scallop_io::job::parse_job(ROUGH_DEMO_JOB).map_err(|e| Failure::Io(anyhow::anyhow!("{name}: {e}")))?;
    let loaded = scallop_io::read_mesh(ROUGH_DEMO_PART, scallop_io::MeshFormat::Stl, scallop_io::Units::Millimetres)
        .map_err(|e| Failure::Io(anyhow::anyhow!("{name}: {e}")))?;
    let n = loaded.mesh.triangles().len();
    let part = scallop_engine::Part::Mesh(loaded.mesh);
    let description = format!("built-in pocket block (examples/parts/pocket.stl, {n} triangles)");
    let first = finish_job_with_part(&spec, Path::new("."), part, description)?;
    let job = operations_job(&spec, first)?;
    let start = std::time::Instant::now();
    let out = run_operations(&job).map_err(|e| Failure::Io(anyhow::anyhow!("{name} failed: {e}")))?;
    write_job(&job, &out, start.elapsed().as_secs_f64(), output, json, "scallop demo --rough")
}

/// Checks a 3-axis program against the travel of the machine the job names (a
/// 3+2 program is checked by the kinematics of its setup's machine); nothing is
/// written when it leaves the travel.
fn check_travel(spec: &JobFile, job: &Path, name: &str, path: &scallop_toolpath::Toolpath) -> CliResult<()> {
    if spec.setup.is_some() {
        return Ok(());
    }
    let Some(machine) = crate::machine::job_machine(spec, job.parent().unwrap_or(Path::new(".")))? else {
        return Ok(());
    };
    crate::machine::check_travel(&machine, path.moves().iter().map(|m| m.to)).map_err(|e| match e {
        Failure::Rejected(e) => Failure::Rejected(anyhow::anyhow!("{name}: {e:#}")),
        other => other,
    })
}

/// `scallop run --plan-only`: the estimate of every operation (docs/job.md).
fn plan_only(name: &str, job: &Job, json: bool) -> CliResult<()> {
    let mut estimates = Vec::with_capacity(job.operations.len());
    for (op, e) in job.operations.iter().zip(scallop_engine::estimate_job(job)) {
        let e = e.map_err(|e| Failure::rejected(format!("{name}: operation `{}`: {e}", op.name)))?;
        estimates.push((op.name.clone(), e));
    }
    if json {
        let list: Vec<serde_json::Value> =
            estimates.iter().map(|(n, e)| serde_json::json!({ "name": n, "estimate": e })).collect();
        return crate::output::print_json(&list);
    }
    let mut text = format!("{name}: estimate before planning (no drop-cutter, no simulation)\n");
    for (k, (n, e)) in estimates.iter().enumerate() {
        if e.strategy == "rough" {
            text.push_str(&format!(
                "  {}. {n}: rough, ~{} passes on {} levels, {:.3} mm stepover; ~{:.0} mm of feed, >= {} at the \
                 programmed feed\n",
                k + 1,
                e.passes,
                e.levels,
                e.spacing_mm[0],
                e.feed_length_mm,
                crate::output::hms(e.time_at_feed_s)
            ));
            continue;
        }
        let levels = if e.levels > 0 { format!(" and {} waterline levels", e.levels) } else { String::new() };
        text.push_str(&format!(
            "  {}. {n}: {}, feed at {:.2}° from X ({}); ~{} passes on ~{} planes{levels}, planes {:.3} to {:.3} mm \
             apart; ~{:.0} mm of feed, >= {} at the programmed feed\n",
            k + 1,
            e.strategy,
            e.direction_deg,
            if e.direction_given { "given" } else { "from the analysis" },
            e.passes,
            e.planes,
            e.spacing_mm[0],
            e.spacing_mm[1],
            e.feed_length_mm,
            crate::output::hms(e.time_at_feed_s)
        ));
    }
    crate::output::print_text(&text)
}

/// The engine job of a file with `[[operation]]`s: one finishing job per
/// operation, each a copy of `first` (the job-level settings, the part loaded
/// once) with the operation's cutter, finishing settings, tool and spindle.
fn operations_job(spec: &JobFile, first: FinishJob) -> CliResult<Job> {
    let mut operations = Vec::with_capacity(spec.operations.len());
    for (k, op) in spec.operations.iter().enumerate() {
        let mut finish = first.clone();
        finish.cutter = cutter_of(&op.cutter).map_err(|e| match e {
            Failure::Rejected(e) => Failure::rejected(format!("operation {} (`{}`): {e:#}", k + 1, op.name)),
            other => other,
        })?;
        let rough = op.roughing.as_ref().map(rough_settings);
        if rough.is_none() {
            apply_finishing(&mut finish, &op.finishing);
        }
        finish.output.tool = op.tool.unwrap_or(spec.output.tool);
        finish.output.spindle = op.spindle.unwrap_or(spec.output.spindle);
        if let Some(feed) = op.feed {
            finish.machine[0] = feed / 1000.0; // mm/min -> m/min
        }
        operations.push(Operation { name: op.name.clone(), finish, rough });
    }
    let stock = spec.stock.as_ref().map(|s| match (s.min, s.max) {
        (Some(min), Some(max)) => StockShape::Box(Aabb3 { min: min.into(), max: max.into() }),
        _ => StockShape::AroundPart { margin: s.margin, top: s.top.unwrap_or(1.0), bottom: s.bottom.unwrap_or(1.0) },
    });
    Ok(Job { stock, operations })
}

/// The settings of an `[operation.roughing]` table.
fn rough_settings(r: &scallop_io::job::RoughingSpec) -> scallop_rough::RoughSettings {
    scallop_rough::RoughSettings {
        stepdown: r.stepdown,
        stepover: r.stepover,
        radial_allowance: r.stock_to_leave,
        axial_allowance: r.stock_to_leave_axial.unwrap_or(r.stock_to_leave),
        pattern: match r.pattern {
            scallop_io::job::RoughPatternWord::Offset => scallop_rough::Pattern::Offset,
            scallop_io::job::RoughPatternWord::OffsetLoops => scallop_rough::Pattern::OffsetLoops,
            scallop_io::job::RoughPatternWord::Adaptive => scallop_rough::Pattern::Adaptive,
        },
        direction: match r.direction {
            scallop_io::job::MillingWord::Climb => scallop_rough::Direction::Climb,
            scallop_io::job::MillingWord::Conventional => scallop_rough::Direction::Conventional,
            scallop_io::job::MillingWord::Both => scallop_rough::Direction::Both,
        },
    }
}

/// The cutter of a `[cutter]` table (or a library tool): profile, flutes
/// (default 4 D, or the cone's height if longer), shank and holder stack.
pub(crate) fn cutter_of(spec: &scallop_io::job::CutterSpec) -> CliResult<Cutter> {
    let radius = spec.diameter / 2.0;
    let shape = match spec.shape {
        ShapeWord::Ball => CutterShape::Ball { radius },
        ShapeWord::Flat => CutterShape::Flat { radius },
        ShapeWord::Bull => CutterShape::Bull { radius, corner: spec.corner_radius.unwrap_or(radius) },
        ShapeWord::Cone => {
            CutterShape::Cone { radius, half_angle: (0.5 * spec.angle_deg.unwrap_or(90.0)).to_radians() }
        }
    };
    let flute = spec.flute_length.unwrap_or((4.0 * spec.diameter).max(shape.profile_height()));
    let shank = (spec.shank_diameter.unwrap_or(spec.diameter) / 2.0, spec.shank_length.unwrap_or(flute));
    let holder = spec
        .holder
        .iter()
        .map(|h| scallop_cutter::HolderSegment {
            length: h.length,
            bottom_radius: h.diameter / 2.0,
            top_radius: h.top_diameter.unwrap_or(h.diameter) / 2.0,
        })
        .collect();
    Cutter::new(shape, flute).and_then(|c| c.with_shank(shank.0, shank.1)).and_then(|c| c.with_holder(holder)).map_err(
        |e| {
            Failure::rejected(format!(
                "[cutter] (diameter, corner_radius, angle_deg, flute_length, shank_diameter, shank_length, holder): {e}"
            ))
        },
    )
}

/// The settings of a `[finishing]` table on a finishing job.
fn apply_finishing(job: &mut FinishJob, f: &scallop_io::job::FinishingSpec) {
    job.scallop_height = f.scallop_height;
    job.direction_deg = match f.direction {
        DirectionSpec::Degrees(d) => Some(d),
        DirectionSpec::Named(_) | DirectionSpec::Auto => None,
    };
    job.pattern = match f.pattern {
        PatternWord::OneWay => Pattern::OneWay,
        PatternWord::Zigzag => Pattern::Zigzag,
    };
    job.max_step = f.max_step;
    job.strategy = match (f.strategy, f.iso_direction) {
        (StrategyWord::Isoparametric, IsoWord::V) => Strategy::Isoparametric(IsoDirection::V),
        (StrategyWord::Isoparametric, IsoWord::U) => Strategy::Isoparametric(IsoDirection::U),
        (StrategyWord::Network, _) => Strategy::NetworkPlanes,
        (StrategyWord::Parallel, _) => Strategy::ParallelPlanes,
        (StrategyWord::SteepShallow, _) => Strategy::SteepShallow { threshold_deg: f.steep_threshold_deg },
        (StrategyWord::Auto, _) if matches!(job.part, scallop_engine::Part::Mesh(_)) && job.setup.is_none() => {
            Strategy::SteepShallow { threshold_deg: f.steep_threshold_deg }
        }
        (StrategyWord::Auto, _) => Strategy::ParallelPlanes,
    };
    job.leads = match f.lead {
        LeadWord::Arc => LeadKind::Arc { radius: f.lead_radius },
        LeadWord::Ramp => LeadKind::Ramp { length: f.lead_length, angle: f.lead_angle_deg.to_radians() },
        LeadWord::None => LeadKind::None,
    };
}

/// Reads and checks a job file: its name for messages and its contents; a
/// missing or non-UTF-8 file or a bad job is rejected naming the file.
pub(crate) fn read_job(path: &Path) -> CliResult<(String, JobFile)> {
    let name = path.display().to_string();
    let bytes = crate::input::read_bytes(path, &name, "the job file")?;
    let text = std::str::from_utf8(&bytes)
        .map_err(|e| Failure::rejected(format!("{name}: byte {}: the job file is not UTF-8 text", e.valid_up_to())))?;
    let library_file = tool_library_of(text);
    let library = match &library_file {
        Some(file) => Some(read_tool_library(&path.parent().unwrap_or(Path::new(".")).join(file))?),
        None => None,
    };
    let mut spec = parse_job_with_tools(text, library.as_ref()).map_err(|e| match (&e, &library_file) {
        (scallop_io::job::JobError::UnknownTool { .. }, Some(lib)) => {
            Failure::rejected(format!("{name}: {e} (tool library {lib})"))
        }
        _ => Failure::rejected(format!("{name}: {e}")),
    })?;
    let in_job = |e: Failure| match e {
        Failure::Rejected(e) => Failure::Rejected(anyhow::anyhow!("{name}: {e:#}")),
        other => other,
    };
    if let Some(machine) =
        crate::machine::job_machine(&spec, path.parent().unwrap_or(Path::new("."))).map_err(in_job)?
    {
        for note in crate::machine::apply(&mut spec, &machine).map_err(in_job)? {
            eprintln!("note: {name}: {note}");
        }
    }
    Ok((name, spec))
}

/// Reads a tool library (docs/job.md, "Tool library"); errors name the file,
/// the line and the fix.
pub(crate) fn read_tool_library(path: &Path) -> CliResult<scallop_io::tools::ToolLibrary> {
    let text = crate::input::read_text(path, "the tool library (`tool_library` of the job)")?;
    scallop_io::tools::parse_tool_library(&text).map_err(|e| Failure::rejected(format!("{}: {e}", path.display())))
}

pub(crate) fn finish_job(spec: &JobFile, folder: &Path) -> CliResult<FinishJob> {
    let units = UnitsArg::from(spec.part.units);
    let (part, part_name) = match (&spec.part.file, &spec.part.builtin) {
        (Some(file), _) => {
            let path = folder.join(file);
            let loaded = load(&path.to_string_lossy(), units)?;
            (loaded.part, loaded.description)
        }
        (None, Some(name)) => {
            let part = scallop_engine::Part::builtin(name).ok_or_else(|| {
                Failure::rejected(format!("part.builtin = \"{name}\": no such built-in part (choi, rubio)"))
            })?;
            (part, format!("built-in {name} surface"))
        }
        (None, None) => return Err(Failure::rejected("part: give `file` or `builtin`")),
    };
    finish_job_with_part(spec, folder, part, part_name)
}

/// The finishing job of `spec` on a part already loaded (`scallop demo --rough`
/// gives its embedded part this way); `folder` resolves the job's other files.
pub(crate) fn finish_job_with_part(
    spec: &JobFile,
    folder: &Path,
    part: scallop_engine::Part,
    part_name: String,
) -> CliResult<FinishJob> {
    let cutter = cutter_of(&spec.cutter)?;
    let first = &spec.operations[0];
    let o = &spec.output;
    let dialect_name = o.dialect_or(None);
    let mut dialect = scallop_post::Dialect::builtin(dialect_name).map_err(|_| {
        Failure::rejected(format!(
            "`output.dialect` = \"{dialect_name}\": no such dialect; use one of {:?}",
            scallop_post::Dialect::builtin_names()
        ))
    })?;
    if let Some(machine) = crate::machine::job_machine(spec, folder)? {
        crate::machine::manual_tool_change(&mut dialect, &machine);
    }
    let dialect = match o.units {
        scallop_io::job::UnitsWord::In => dialect.in_inches().map_err(|e| {
            Failure::rejected(format!("`output.units` = \"in\" with `output.dialect` = \"{dialect_name}\": {e}"))
        })?,
        _ => dialect,
    };
    let output = OutputOptions {
        dialect,
        arc_fitting: o.arc_fitting,
        program: o.program.clone(),
        tool: o.tool,
        spindle: first.spindle.unwrap_or(o.spindle),
    };
    let setup = match &spec.setup {
        None => None,
        Some(s) => {
            let machine = crate::post::load_machine(&s.machine, folder, "setup.machine")?;
            let [rx, ry, rz] = s.rotation_deg.map(f64::to_radians);
            Some(Setup { rotation: Rotation3::from_euler_angles(rx, ry, rz), machine, tool_length: s.tool_length })
        }
    };
    let mut job = FinishJob {
        part,
        part_name,
        cutter,
        scallop_height: 0.0,
        direction_deg: None,
        pattern: Pattern::Zigzag,
        machine: [first.feed.map_or(spec.machine.feed, |f| f / 1000.0), spec.machine.acceleration, spec.machine.jerk],
        rapid_rate: spec.machine.rapid * 1000.0 / 60.0,
        clearance: spec.machine.clearance,
        tolerances: Tolerances { path: spec.tolerances.path, gouge: spec.tolerances.gouge },
        max_step: 0.0,
        sim_resolution: spec.verify.resolution,
        output,
        setup,
        strategy: Strategy::ParallelPlanes,
        leads: LeadKind::None,
    };
    apply_finishing(&mut job, &spec.finishing);
    Ok(job)
}

/// The job keys behind a planning failure, so the message names what to change.
fn job_keys(e: &scallop_engine::EngineError) -> &'static str {
    use scallop_engine::EngineError as E;
    use scallop_strategy::StrategyError as S;
    match e {
        E::Strategy(S::Unreachable { .. }) => {
            " (job keys: cutter.shape, finishing.direction, finishing.scallop_height)"
        }
        E::Strategy(S::EmptyRegion { .. }) => " (job keys: part, finishing.max_step, cutter.diameter)",
        E::Strategy(S::ScallopTooLarge { .. }) => " (job keys: finishing.scallop_height, cutter.corner_radius)",
        E::Strategy(S::TooMuchWork { .. }) => " (job keys: finishing.max_step, finishing.scallop_height)",
        E::Verification(scallop_sim::SimError::TooManyCells { .. } | scallop_sim::SimError::BadResolution { .. }) => {
            " (job key: verify.resolution)"
        }
        E::Verification(_) => " (job keys: cutter.flute_length, machine.clearance, tolerances.gouge)",
        E::Output { .. } => " (job keys: [output], [setup])",
        E::Rough(_) => " (job keys: [operation.roughing], [operation.cutter], [stock])",
        _ => "",
    }
}

/// Runs a job of several operations with a progress line per operation and
/// phase; each operation's `planning_time_s` is the wall time from its
/// planning step to its cutting step.
fn run_operations(job: &Job) -> Result<scallop_engine::JobOutput, scallop_engine::EngineError> {
    use scallop_engine::{JobPhase, JobStep};
    let spinner = progress_bar(0, "planning the first operation");
    spinner.enable_steady_tick(std::time::Duration::from_millis(120));
    let steps: std::cell::RefCell<Vec<(JobStep, std::time::Instant)>> = std::cell::RefCell::new(Vec::new());
    let progress = |step: JobStep| {
        steps.borrow_mut().push((step, std::time::Instant::now()));
        let message = match (step.phase, job.operations.get(step.index)) {
            (JobPhase::Planning, Some(op)) => {
                format!("operation {}/{} `{}`: planning", step.index + 1, step.count, op.name)
            }
            (JobPhase::Cutting, Some(op)) => {
                format!("operation {}/{} `{}`: cutting the simulated stock", step.index + 1, step.count, op.name)
            }
            _ => "proving the stock all operations left, writing the program".to_string(),
        };
        spinner.set_message(message);
    };
    let mut out = scallop_engine::run_job_with_progress(job, &progress)?;
    spinner.finish_and_clear();
    let steps = steps.into_inner();
    for (planning, cutting) in steps.iter().zip(steps.iter().skip(1)) {
        if planning.0.phase == JobPhase::Planning
            && cutting.0.phase == JobPhase::Cutting
            && let Some(op) = out.report.operations.get_mut(planning.0.index)
        {
            op.plan.planning_time_s = cutting.1.duration_since(planning.1).as_secs_f64();
        }
    }
    Ok(out)
}

/// Runs a finishing job with a progress line: the strategy while planning,
/// a bar of the stock's bands cut (with the time left) while simulating, then the
/// proof.
fn run_one(job: &FinishJob) -> Result<scallop_engine::FinishOutput, scallop_engine::EngineError> {
    use scallop_engine::FinishStep;
    let bar = progress_bar(0, "preparing the part");
    bar.enable_steady_tick(std::time::Duration::from_millis(120));
    let progress = |step: FinishStep| match step {
        FinishStep::Planning(strategy) => bar.set_message(format!("planning ({})", strategy_name(strategy))),
        FinishStep::Cutting { done, total } => {
            if bar.length() != Some(total as u64) {
                bar.set_length(total as u64);
                bar.set_message("cutting the simulated stock (bands of rows)");
            }
            bar.set_position(done as u64);
        }
        FinishStep::Verifying => bar.set_message("measuring the scallop and the material left"),
        FinishStep::Refining { round } => {
            bar.set_length(0);
            bar.set_message(format!("planning again with passes where the scallop exceeded sh (round {round})"));
        }
    };
    let out = scallop_engine::run_finishing_with_progress(job, &progress);
    bar.finish_and_clear();
    out
}

/// How the progress line names a strategy.
fn strategy_name(strategy: Strategy) -> &'static str {
    match strategy {
        Strategy::ParallelPlanes => "parallel planes",
        Strategy::Isoparametric(_) => "isoparametric passes",
        Strategy::NetworkPlanes => "network planes",
        Strategy::SteepShallow { .. } => "steep and shallow: planes and waterline levels",
    }
}
