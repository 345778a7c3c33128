//! `scallop run JOB.toml` of a job whose part is a test part (`[part]
//! test_part`): its one `kind = "rough5"` operation planned, proven on a
//! tri-dexel stock, put through the 5-axis machine the job names and posted in
//! TCP form by `scallop_engine::run_rough5` (docs/job.md, docs/rough5.md);
//! writes `program.nc`, `toolpath.csv` and `report.json`.

use std::fmt::Write as _;
use std::path::Path;
use std::sync::Mutex;
use std::time::Instant;

use scallop_engine::{Rough5Job, Rough5Metrics, Rough5Output, Rough5Step, TcpWords, rough5_settings, run_rough5};
use scallop_guides::GuideSettings;
use scallop_io::job::{EntryWord, JobFile, OperationSpec, Rough5Spec, TestPartWord, TiltWord};
use scallop_rough5::{
    AirSettings, CuttingData, EntryMode, OrientSettings, ProofSettings, Rough5Settings, TiltMode, Weights,
};
use serde::Serialize;

use crate::guides::{PartArg, test_part};
use crate::output::{print_json, print_text, progress_bar, with_written};
use crate::outset::OutputSet;
use crate::{CliResult, Failure};

/// The operation's entry in `report.json`.
#[derive(Serialize)]
struct OperationReport<'a> {
    name: &'a str,
    kind: &'static str,
    tilt: &'static str,
    tool: u32,
    spindle: f64,
    feed_mm_min: f64,
    tool_length_mm: f64,
    ap_mm: f64,
    ae_mm: f64,
    levels: usize,
    passes: usize,
    dropped_pairs: usize,
    cl_points: usize,
    blocks: usize,
    replay_tip_deviation_mm: f64,
    retracts: usize,
    links: usize,
    ramps: usize,
    /// Entries by kind: helix, ramp, side, plunge.
    entries: crate::rough5::EntriesJson,
    metrics: &'a Rough5Metrics,
    planning_time_s: f64,
    proof_time_s: f64,
}

/// `report.json` of a rough5 job.
#[derive(Serialize)]
struct JobReport<'a> {
    command: String,
    part: &'a str,
    machine: String,
    dialect: String,
    operations: Vec<OperationReport<'a>>,
    total_time_s: f64,
    run_time_s: f64,
}

/// Runs the rough5 operation of a job of a test part.
pub(crate) fn run(spec: &JobFile, job: &Path, name: &str, output: &Path, json: bool) -> CliResult<()> {
    let start = Instant::now();
    let op = &spec.operations[0];
    let place = format!("{name}: operation 1 (`{}`)", op.name);
    let reject = |e: &dyn std::fmt::Display| Failure::rejected(format!("{place}: {e}"));
    let in_job = |e: Failure| match e {
        Failure::Rejected(e) => Failure::Rejected(anyhow::anyhow!("{place}: {e:#}")),
        other => other,
    };
    let Some(r) = op.rough5.as_ref() else {
        return Err(reject(&"give [operation.rough5]"));
    };
    let Some(word) = spec.part.test_part else {
        return Err(reject(&"kind = \"rough5\" needs `part.test_part`"));
    };
    let folder = job.parent().unwrap_or(Path::new("."));
    let Some(machine_name) = spec.machine.description.as_deref() else {
        return Err(reject(
            &"a rough5 operation runs on a 5-axis machine: name it at the top of the job, e.g. machine = \"ucp710\"",
        ));
    };
    let machine = crate::post::load_machine(machine_name, folder, "machine").map_err(in_job)?;
    let (part_name, part) = test_part(match word {
        TestPartWord::Pocket => PartArg::Pocket,
        TestPartWord::Impeller => PartArg::Impeller,
        TestPartWord::Fitting => PartArg::Fitting,
    })?;
    let tool = crate::run::cutter_of(&op.cutter).map_err(in_job)?;
    let spindle = op.spindle.unwrap_or(spec.output.spindle);
    let feed = feed_of(op, r, spindle, spec.machine.feed).map_err(|e| reject(&e))?;
    let tool_length = r
        .tool_length
        .unwrap_or(tool.flute_length() + tool.shank_length() + tool.holder().iter().map(|h| h.length).sum::<f64>());
    let settings = settings_of(r, &part, op.cutter.diameter / 2.0, feed).map_err(|e| reject(&e))?;
    let dialect_name = spec.output.dialect_or(None);
    let dialect = scallop_post::Dialect::builtin(dialect_name).map_err(|_| {
        reject(&format!(
            "`output.dialect` = \"{dialect_name}\": no such dialect; use one of {:?}",
            scallop_post::Dialect::builtin_names()
        ))
    })?;
    let words = TcpWords {
        program: spec.output.program.clone(),
        tool: op.tool.unwrap_or(spec.output.tool),
        tool_length,
        spindle,
    };
    let engine_job = Rough5Job {
        part_name: part_name.to_string(),
        part,
        tool,
        settings,
        proof: ProofSettings { resolution: r.resolution, axis_tolerance: r.sim_tolerance },
        machine,
        dialect,
        words,
    };
    let (out, plan_seconds, proof_seconds) = run_with_progress(&engine_job).map_err(|e| {
        let keys = match e {
            scallop_engine::EngineError::Output { .. } => " (job keys: machine, output.dialect, [operation.rough5])",
            _ => " (job keys: [operation.rough5], [operation.cutter])",
        };
        Failure::rejected(format!("{place}: {e}{keys}; nothing was written"))
    })?;
    let report = JobReport {
        command: format!("scallop run {name}"),
        part: part_name,
        machine: engine_job.machine.name().to_string(),
        dialect: dialect_name.to_string(),
        operations: vec![OperationReport {
            name: &op.name,
            kind: "rough5",
            tilt: r.tilt.word(),
            tool: engine_job.words.tool,
            spindle,
            feed_mm_min: feed,
            tool_length_mm: tool_length,
            ap_mm: r.ap,
            ae_mm: r.ae,
            levels: out.plan.levels.len(),
            passes: out.plan.passes.len(),
            dropped_pairs: out.plan.passes.iter().map(|p| p.dropped).sum(),
            cl_points: out.plan.toolpath.moves().len(),
            blocks: out.posted.blocks,
            replay_tip_deviation_mm: out.posted.replay_tip_deviation,
            retracts: out.plan.retracts,
            links: out.plan.links,
            ramps: out.plan.ramps,
            entries: crate::rough5::EntriesJson::of(&out.plan.entries),
            metrics: &out.metrics,
            planning_time_s: plan_seconds,
            proof_time_s: proof_seconds,
        }],
        total_time_s: out.metrics.machining_time_s,
        run_time_s: start.elapsed().as_secs_f64(),
    };
    let mut set = OutputSet::begin(output, "run")?;
    set.write("program.nc", out.posted.text.as_bytes())?;
    set.write("toolpath.csv", scallop_io::cl::write_cl(&out.plan.toolpath).as_bytes())?;
    let text = serde_json::to_string_pretty(&report).map_err(|e| Failure::Io(e.into()))?;
    set.write("report.json", format!("{text}\n").as_bytes())?;
    let written = set.commit()?;
    if json {
        return print_json(&with_written(&report, &written)?);
    }
    print_text(&summary(&report, &out, output))
}

/// The feed (mm/min): the operation's, else z f_z N of `[operation.rough5]`,
/// else `machine.feed`.
fn feed_of(op: &OperationSpec, r: &Rough5Spec, spindle: f64, machine_feed: f64) -> Result<f64, String> {
    match (op.feed, r.teeth, r.feed_per_tooth) {
        (Some(f), _, _) => Ok(f),
        (None, Some(teeth), Some(feed_per_tooth)) => CuttingData { teeth, feed_per_tooth, spindle }
            .feed()
            .map_err(|e| format!("rough5.teeth, rough5.feed_per_tooth and the spindle speed (`spindle`): {e}")),
        _ => Ok(machine_feed * 1000.0), // m/min -> mm/min
    }
}

/// The planning settings of `[operation.rough5]`: those of `scallop rough5`
/// (`scallop_engine::rough5_settings`) with the operation's.
fn settings_of(
    r: &Rough5Spec,
    part: &scallop_parts::TestPart,
    tool_radius: f64,
    feed: f64,
) -> Result<Rough5Settings, scallop_engine::EngineError> {
    let base = rough5_settings(part, tool_radius, (r.ap, r.ae), feed)?;
    // The thesis's mixed weighting, interval and target (docs/rough5.md), as `scallop rough5 --tilt optimised`.
    let orientation = OrientSettings {
        interval: [0.0, 30f64.to_radians()],
        target: 10f64.to_radians(),
        ..OrientSettings::new(Weights { bounds: 15.0, fluidity: 1.2, pitch: 1.0 })
    };
    Ok(Rough5Settings {
        tilt: if r.tilt == TiltWord::Zero { TiltMode::Zero } else { TiltMode::Guides },
        guides: GuideSettings { flank_allowance: r.stock_to_leave, voxel: r.voxel, ..base.guides },
        bottom_allowance: r.stock_to_leave_axial.unwrap_or(r.stock_to_leave),
        step: r.step,
        max_angle_step: r.max_angle_step_deg.to_radians(),
        max_azimuth_step: r.max_azimuth_step_deg.to_radians(),
        orientation: (r.tilt == TiltWord::Optimised).then_some(orientation),
        // The per-pass weights of the limit and bottom passes, as `--limit-weights`.
        limit_orientation: r
            .limit_weights
            .as_ref()
            .filter(|_| r.tilt != TiltWord::Zero)
            .map(|w| OrientSettings { weights: Weights { bounds: w[0], fluidity: w[1], pitch: w[2] }, ..orientation }),
        correct: r.correction.planar() && r.tilt != TiltWord::Zero,
        spatial: r.correction.spatial() && r.tilt != TiltWord::Zero,
        entry: match r.entry {
            EntryWord::Auto => EntryMode::Auto,
            EntryWord::Helix => EntryMode::Helix,
            EntryWord::Ramp => EntryMode::Ramp,
            EntryWord::Side => EntryMode::Side,
        },
        air: r.air_moves.then_some(AirSettings {
            feed: r.air_feed,
            clearance: r.air_clearance,
            resolution: r.resolution,
            axis_tolerance: r.sim_tolerance,
        }),
        ..base
    })
}

/// Runs the operation with a progress line; returns the output, the planning
/// and the proof's wall times (s).
fn run_with_progress(job: &Rough5Job) -> Result<(Rough5Output, f64, f64), scallop_engine::EngineError> {
    let bar = progress_bar(0, "planning the 5-axis roughing (levels)");
    let start = Instant::now();
    let marks: Mutex<[Option<Instant>; 2]> = Mutex::new([None, None]);
    let progress = |step: Rough5Step| {
        let mark = |k: usize, message: &'static str| {
            if let Ok(mut m) = marks.lock()
                && m[k].is_none()
            {
                m[k] = Some(Instant::now());
                bar.set_position(0);
                bar.set_message(message);
            }
        };
        match step {
            Rough5Step::Planning { done, total } => crate::simulate::show(&bar, done, total),
            Rough5Step::Proving { done, total } => {
                mark(0, "proving on the tri-dexel stock");
                crate::simulate::show(&bar, done, total);
            }
            Rough5Step::Posting => mark(1, "through the machine and the post"),
        }
    };
    let out = run_rough5(job, &progress)?;
    bar.finish_and_clear();
    let [proving, posting] = marks.into_inner().unwrap_or_default();
    let proving = proving.unwrap_or(start);
    let plan = proving.duration_since(start).as_secs_f64();
    let proof = posting.map_or(0.0, |p| p.duration_since(proving).as_secs_f64());
    Ok((out, plan, proof))
}

fn summary(r: &JobReport, out: &Rough5Output, folder: &Path) -> String {
    let op = &r.operations[0];
    let m = op.metrics;
    let mut s = format!(
        "{}: 1 operation on the {} ({}, {})\n  1. {}: rough5 ({} tilt), {} levels, {} passes, {} CL points, {} blocks\n",
        r.command, r.part, r.machine, r.dialect, op.name, op.tilt, op.levels, op.passes, op.cl_points, op.blocks
    );
    crate::rough5::metric_lines(&mut s, m, "     ");
    let _ = writeln!(
        s,
        "     replayed within {:.4} mm; {} retracts, {} ramps, {} CL points dropped at flanks",
        out.posted.replay_tip_deviation, op.retracts, op.ramps, op.dropped_pairs
    );
    for f in &m.faces {
        let q = f.deviation_quartiles_outside_corners_mm;
        let _ = writeln!(
            s,
            "     {}: crests max {:.3}, mean {:.3}, sigma {:.3} mm (corners excluded); deviation from the allowance \
             {:.3} / {:.3} / {:.3} / {:.3} / {:.3} mm (min, quartiles, max, outside corners)",
            f.face, f.crest_max_mm, f.crest_mean_mm, f.crest_sigma_mm, q[0], q[1], q[2], q[3], q[4]
        );
    }
    let _ = writeln!(
        s,
        "  planned in {:.1} s, proven in {:.1} s; written to {}",
        op.planning_time_s,
        op.proof_time_s,
        folder.display()
    );
    s
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

    use super::*;

    /// `limit_weights` of a job reaches the planner as the limit passes'
    /// orientation (the bulk keeps SPU with `tilt = "guides"`), with the
    /// interval and target of the mixed weighting; the air-move keys reach
    /// its air settings.
    #[test]
    fn job_keys_reach_the_planner_settings() {
        let job = "[part]\ntest_part = \"pocket\"\n[[operation]]\nkind = \"rough5\"\n\
            [operation.cutter]\nshape = \"bull\"\ndiameter = 10\ncorner_radius = 1.5\nflute_length = 30\n\
            [operation.rough5]\nap = 4\nae = 4.5\nlimit_weights = [1, 0, 2]\nair_feed = 20000\nair_clearance = 1.5\n";
        let spec = scallop_io::job::parse_job(job).unwrap();
        let r = spec.operations[0].rough5.as_ref().unwrap();
        let (_, part) = test_part(PartArg::Pocket).unwrap();
        let s = settings_of(r, &part, 5.0, 2400.0).unwrap();
        assert_eq!(s.orientation, None);
        let limit = s.limit_orientation.unwrap();
        assert_eq!(limit.weights, Weights { bounds: 1.0, fluidity: 0.0, pitch: 2.0 });
        assert!(
            (limit.interval[1] - 30f64.to_radians()).abs() < 1e-12 && (limit.target - 10f64.to_radians()).abs() < 1e-12
        );
        let air = s.air.unwrap();
        assert_eq!((air.feed, air.clearance, air.resolution), (20_000.0, 1.5, 0.5));
        let plain =
            scallop_io::job::parse_job(&job.replace("limit_weights = [1, 0, 2]\n", "air_moves = false\n")).unwrap();
        let s = settings_of(plain.operations[0].rough5.as_ref().unwrap(), &part, 5.0, 2400.0).unwrap();
        assert_eq!((s.limit_orientation, s.air), (None, None));
    }
}
