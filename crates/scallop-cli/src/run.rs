//! `scallop run JOB.toml`: a finishing job from a job file (`docs/job.md`).

use std::path::{Path, PathBuf};

use clap::Args;
use scallop_cutter::{Cutter, CutterShape};
use scallop_engine::{FinishJob, OutputOptions, Setup, Strategy, run_finishing};
use scallop_geom::Tolerances;
use scallop_geom::nalgebra::Rotation3;
use scallop_io::job::{DirectionSpec, JobFile, parse_job};
use scallop_strategy::{IsoDirection, LeadKind, Pattern};

use crate::output::{progress_bar, write_finishing};
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
}

/// `scallop run`.
pub fn run(args: &RunArgs) -> CliResult<()> {
    let name = args.job.display().to_string();
    let bytes = std::fs::read(&args.job).map_err(|e| {
        let err = anyhow::anyhow!("{name}: cannot read the job file: {e}");
        if e.kind() == std::io::ErrorKind::NotFound { Failure::Rejected(err) } else { Failure::Io(err) }
    })?;
    let text = std::str::from_utf8(&bytes)
        .map_err(|e| Failure::rejected(format!("{name}: byte {}: the job file is not UTF-8 text", e.valid_up_to())))?;
    let spec = parse_job(text).map_err(|e| Failure::rejected(format!("{name}: {e}")))?;
    let job = finish_job(&spec, args.job.parent().unwrap_or(Path::new("."))).map_err(|e| match e {
        Failure::Rejected(e) => Failure::Rejected(anyhow::anyhow!("{name}: {e:#}")),
        other => other,
    })?;
    let spinner = progress_bar(0, "planning and verifying");
    spinner.enable_steady_tick(std::time::Duration::from_millis(120));
    let start = std::time::Instant::now();
    let out = run_finishing(&job).map_err(|e| Failure::rejected(format!("{name}: {e}{}", job_keys(&e))))?;
    spinner.finish_and_clear();
    let command = format!("scallop run {name}");
    write_finishing(&job, &out, start.elapsed().as_secs_f64(), &args.output, args.json, &command)
}

pub(crate) fn finish_job(spec: &JobFile, folder: &Path) -> CliResult<FinishJob> {
    let units = if spec.part.units == "in" { UnitsArg::In } else { UnitsArg::Mm };
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
    let radius = spec.cutter.diameter / 2.0;
    let shape = match spec.cutter.shape.as_str() {
        "ball" => CutterShape::Ball { radius },
        "flat" => CutterShape::Flat { radius },
        _ => CutterShape::Bull { radius, corner: spec.cutter.corner_radius.unwrap_or(radius) },
    };
    let flute = spec.cutter.flute_length.unwrap_or(4.0 * spec.cutter.diameter);
    let cutter = Cutter::new(shape, flute)
        .map_err(|e| Failure::rejected(format!("[cutter] (diameter, corner_radius, flute_length): {e}")))?;
    let o = &spec.output;
    let dialect = scallop_post::Dialect::builtin(&o.dialect).map_err(|_| {
        Failure::rejected(format!(
            "`output.dialect` = \"{}\": no such dialect; use one of {:?}",
            o.dialect,
            scallop_post::Dialect::builtin_names()
        ))
    })?;
    let output = OutputOptions {
        dialect,
        arc_fitting: o.arc_fitting,
        program: o.program.clone(),
        tool: o.tool,
        spindle: o.spindle,
    };
    let setup = match &spec.setup {
        None => None,
        Some(s) => {
            let machine = scallop_machine::Machine::builtin(&s.machine)
                .map_err(|e| Failure::rejected(format!("`setup.machine` = \"{}\": {e}", s.machine)))?;
            let [rx, ry, rz] = s.rotation_deg.map(f64::to_radians);
            Some(Setup { rotation: Rotation3::from_euler_angles(rx, ry, rz), machine, tool_length: s.tool_length })
        }
    };
    Ok(FinishJob {
        part,
        part_name,
        cutter,
        scallop_height: spec.finishing.scallop_height,
        direction_deg: match spec.finishing.direction {
            DirectionSpec::Degrees(d) => Some(d),
            DirectionSpec::Named(_) | DirectionSpec::Auto => None,
        },
        pattern: if spec.finishing.pattern == "one-way" { Pattern::OneWay } else { Pattern::Zigzag },
        machine: [spec.machine.feed, spec.machine.acceleration, spec.machine.jerk],
        rapid_rate: spec.machine.rapid * 1000.0 / 60.0,
        clearance: spec.machine.clearance,
        tolerances: Tolerances { path: spec.tolerances.path, gouge: spec.tolerances.gouge },
        max_step: spec.finishing.max_step,
        sim_resolution: spec.verify.resolution,
        output,
        setup,
        strategy: match (spec.finishing.strategy.as_str(), spec.finishing.iso_direction.as_str()) {
            ("isoparametric", "v") => Strategy::Isoparametric(IsoDirection::V),
            ("isoparametric", _) => Strategy::Isoparametric(IsoDirection::U),
            ("network", _) => Strategy::NetworkPlanes,
            _ => Strategy::ParallelPlanes,
        },
        leads: match spec.finishing.lead.as_str() {
            "arc" => LeadKind::Arc { radius: spec.finishing.lead_radius },
            "ramp" => {
                LeadKind::Ramp { length: spec.finishing.lead_length, angle: spec.finishing.lead_angle_deg.to_radians() }
            }
            _ => LeadKind::None,
        },
    })
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
        _ => "",
    }
}
