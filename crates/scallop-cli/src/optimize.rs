//! `scallop optimize JOB.toml -o OUTDIR`: the zone-optimisation study of
//! finishing.md chapter 4 (`docs/job.md`, table `[optimize]`).

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget};
use scallop_analysis::{Cutter, MachineLimits};
use scallop_io::job::{
    BarrierWord, FormulationWord, JobFile, OptimizeSpec, ShapeWord, SurrogateCostSpec, SurrogateWord, TransitionWord,
};
use scallop_network::{TransitionModel, Transitions};
use scallop_optim::study::{
    Formulation, KResult, Stopwatch, Study, StudyObserver, StudySettings, Surrogate, run_study,
};
use scallop_optim::surface::{SurfaceModel, SurfaceSettings};
use scallop_optim::{Barrier, CostModel, OptimError, convergence_svg, zones_svg};
use serde::Serialize;

use crate::choice::{Candidate, Choice, choose};
use crate::output::{print_json, print_text, progress_bar, with_written};
use crate::outset::OutputSet;
use crate::{CliResult, Failure};

/// Arguments of `scallop optimize`.
#[derive(Args, Debug)]
pub struct OptimizeArgs {
    /// The job file (TOML with an `[optimize]` table, see docs/job.md).
    job: PathBuf,
    /// Output folder for `study.json`, `report.json`, `convergence.svg` and `zones.svg`.
    #[arg(short, long, default_value = "out/optimize")]
    output: PathBuf,
    /// Print the study as JSON.
    #[arg(long)]
    json: bool,
}

struct Clock(Instant);

impl Stopwatch for Clock {
    fn seconds(&self) -> f64 {
        self.0.elapsed().as_secs_f64()
    }
}

/// One progress bar per K.
struct Bars {
    k_min: usize,
    bars: Vec<ProgressBar>,
}

impl StudyObserver for Bars {
    fn progress(&self, k: usize, spent: f64) {
        if let Some(bar) = self.bars.get(k - self.k_min) {
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)] // 0 <= spent <= budget
            bar.set_position(spent as u64);
        }
    }
    fn finished(&self, k: usize) {
        if let Some(bar) = self.bars.get(k - self.k_min) {
            bar.finish();
        }
    }
}

/// What `study.json` holds.
#[derive(Serialize)]
struct StudyFile<'a> {
    job: String,
    part: String,
    cutter: String,
    scallop_height_mm: f64,
    threads: usize,
    wall_time_s: f64,
    /// What was written, in words.
    gcode: String,
    /// The programs the final choice planned by drop-cutter and proved, with
    /// the model's time next to the program's; `written` marks the one written.
    programs: &'a [Candidate],
    study: &'a Study,
}

/// What `report.json` holds: the written program and the plan it came from.
#[derive(Serialize)]
struct BestReport<'a> {
    part: String,
    formulation: Formulation,
    /// `K` of the written program (1: a single zone).
    k: usize,
    /// Zones planned and written.
    zones: usize,
    /// The network model's time of the written plan (s).
    model_time_s: f64,
    /// The written program's stop-to-stop time (s).
    program_time_s: f64,
    /// The fastest proven single-zone program (s).
    single_zone_time_s: Option<f64>,
    /// The study's best model time over all K (s) and its K.
    model_best_time_s: f64,
    model_best_k: usize,
    /// What was written.
    gcode: String,
    /// The written candidate.
    written: &'a Candidate,
    /// The drop-cutter program: per-zone figures, times next to the network
    /// model's prediction, the stock simulation's scallop.
    program: &'a scallop_engine::ZoneFinishReport,
    /// The study's result for the written `K` (`None`: a single zone).
    result: Option<&'a KResult>,
}

/// `scallop optimize`.
pub fn run(args: &OptimizeArgs) -> CliResult<()> {
    let (name, spec) = crate::run::read_job(&args.job)?;
    let Some(opt) = &spec.optimize else {
        return Err(Failure::rejected(format!(
            "{name}: the job has no [optimize] table; add one with at least `formulation` (docs/job.md)"
        )));
    };
    let folder = args.job.parent().unwrap_or(Path::new("."));
    let (patch, part_name) = load_patch(&spec, folder).map_err(|e| prefix(&name, e))?;
    let (settings, model_settings) = settings(&spec, opt).map_err(|e| prefix(&name, e))?;
    let model = SurfaceModel::new(&patch, model_settings).map_err(|e| rejected(&name, &e))?;

    let clock = Clock(Instant::now());
    let study = run_with_bars(&model, &settings, &clock).map_err(|e| rejected(&name, &e))?;

    let spinner = progress_bar(0, "G-code: the best plans and the single zone, planned and verified");
    spinner.enable_steady_tick(std::time::Duration::from_millis(120));
    let gcode_start = Instant::now();
    let choice = choose(&spec, folder, &study, &model, model_settings.transitions).map_err(|e| prefix(&name, e))?;
    let gcode_seconds = gcode_start.elapsed().as_secs_f64();
    let wall = clock.seconds();
    spinner.finish_and_clear();
    let gcode = written_text(&choice, gcode_seconds);
    let cutter = match model_settings.tool {
        Cutter::Ball { radius } => format!("ball R{radius} mm"),
        Cutter::Toroidal { radius, corner } => format!("bull-nose R{radius} r{corner} mm"),
        Cutter::Flat { radius, .. } => format!("flat R{radius} mm"),
    };
    let file = StudyFile {
        job: name.clone(),
        part: part_name.clone(),
        cutter,
        scallop_height_mm: model_settings.scallop_height,
        threads: rayon::current_num_threads(),
        wall_time_s: wall,
        gcode: gcode.clone(),
        programs: &choice.candidates,
        study: &study,
    };
    let written = choice.written();
    let model_best = &study.results[study.best];
    let report = BestReport {
        part: part_name.clone(),
        formulation: settings.formulation,
        k: written.k.unwrap_or(1),
        zones: written.zones_written,
        model_time_s: written.model_time_s,
        program_time_s: choice.output.report.plan.total_time_s,
        single_zone_time_s: choice.best_single_zone().and_then(|c| c.program_time_s),
        model_best_time_s: model_best.f_best,
        model_best_k: model_best.k,
        gcode: gcode.clone(),
        written,
        program: &choice.output.report,
        result: written.k.and_then(|k| study.results.iter().find(|r| r.k == k)),
    };
    // The seven files replace the previous set in one step (`outset.rs`).
    let mut set = OutputSet::begin(&args.output, "optimize")?;
    set.write("study.json", to_json(&file).map_err(|e| Failure::Io(e.into()))?.as_bytes())?;
    set.write("report.json", to_json(&report).map_err(|e| Failure::Io(e.into()))?.as_bytes())?;
    set.write("program.nc", choice.output.gcode.as_bytes())?;
    set.write("toolpath.csv", scallop_io::cl::write_cl(&choice.output.toolpath).as_bytes())?;
    set.write("convergence.svg", convergence_svg(&study).as_bytes())?;
    let title = format!("{part_name}, {}, {}", formulation_name(settings.formulation), written.source);
    set.write("zones.svg", zones_svg(&choice.plan, &title).as_bytes())?;
    let page =
        scallop_report::html::report_html(&optimisation_report(&patch, &study, &title, &name, &file.cutter, &choice));
    set.write("report.html", page.as_bytes())?;
    let written_files = set.commit()?;
    if args.json {
        return print_json(&with_written(&file, &written_files)?);
    }
    print_text(&summary_text(&part_name, &settings, &study, &choice, wall, &gcode, &args.output))
}

/// Runs the study with one progress bar per K (on a terminal, not under CI).
fn run_with_bars(model: &SurfaceModel, settings: &StudySettings, clock: &Clock) -> Result<Study, OptimError> {
    let visible = {
        use std::io::IsTerminal;
        std::io::stderr().is_terminal() && std::env::var_os("CI").is_none()
    };
    let multi = MultiProgress::with_draw_target(if visible {
        ProgressDrawTarget::stderr()
    } else {
        ProgressDrawTarget::hidden()
    });
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)] // budget >= 1, finite (validated)
    let total = settings.budget.ceil() as u64;
    let bars = Bars {
        k_min: settings.k_min,
        bars: (settings.k_min..=settings.k_max)
            .map(|k| multi.add(progress_bar(total, &format!("K = {k:2}"))))
            .collect(),
    };
    let study = run_study(model, settings, &bars, Some(clock));
    let _ = multi.clear();
    study
}

/// What was written, in words (`study.json`, `report.json`, the summary).
fn written_text(choice: &Choice, seconds: f64) -> String {
    let w = choice.written();
    let r = &choice.output.report;
    let single = choice.best_single_zone();
    let versus = match (w.k, single.and_then(|c| c.program_time_s)) {
        (None, _) => "no zone plan beats the single zone".to_string(),
        (Some(_), Some(t)) => format!("single zone {t:.1} s"),
        (Some(_), None) => "no single-zone program proven".to_string(),
    };
    format!(
        "program.nc: {} ({} zone{} by drop-cutter{}), {:.1} s stop-to-stop ({:.1} s by the network model; {versus}); \
         simulated scallop {:.5} mm <= {:.5} mm; {} programs planned and verified in {seconds:.1} s",
        w.source,
        w.zones_written,
        if w.zones_written == 1 { "" } else { "s" },
        if r.indexed { " as indexed 3+2 setups" } else { "" },
        r.plan.total_time_s,
        w.model_time_s,
        r.sim_max_scallop_mm,
        r.sim_scallop_limit_mm,
        choice.candidates.len(),
    )
}

/// The text summary: per K the model's times and, where it was planned by
/// drop-cutter, the program's; then every candidate of the final choice.
fn summary_text(
    part_name: &str,
    settings: &StudySettings,
    study: &Study,
    choice: &Choice,
    wall: f64,
    gcode: &str,
    output: &Path,
) -> String {
    let mut text = format!(
        "zone optimisation of the {part_name}: {}, K = {}..{}, budget {} per K, surrogate {:?}\n\
         \x20  K  zones   start (s)  model (s)  program (s)   gain   evals  surr.  wall (s)  eval mean/p95/max (ms)\n",
        formulation_name(settings.formulation),
        settings.k_min,
        settings.k_max,
        settings.budget,
        settings.surrogate
    );
    for r in &study.results {
        let program = choice.candidates.iter().find(|c| c.k == Some(r.k));
        text.push_str(&format!(
            "  {:2}  {:5}  {:10.2}  {:9.2}  {:>11}  {:5.1}%  {:6}  {:5}  {:8.2}  {}\n",
            r.k,
            r.plan.zones.len(),
            r.f0,
            r.f_best,
            program_cell(program),
            100.0 * r.eta,
            r.evaluations,
            r.surrogate_evaluations,
            r.wall_time_s.unwrap_or(f64::NAN),
            r.black_box_times
                .map_or_else(|| "-".to_string(), |t| format!("{:.2}/{:.2}/{:.2}", t.mean_ms, t.p95_ms, t.max_ms))
        ));
    }
    for c in choice.candidates.iter().filter(|c| c.k.is_none()) {
        text.push_str(&format!(
            "  {} ({:.1} deg): model {:.2} s, program {}\n",
            c.source,
            c.directions_deg[0],
            c.model_time_s,
            program_cell(Some(c)).trim()
        ));
    }
    let best = &study.results[study.best];
    text.push_str(&format!(
        "  model best: K = {} ({} zone(s)) in {:.2} s; mean gain {:.1}%; study and programs {:.1} s on {} threads\n\
         \x20 {gcode}\n\
         \x20 wrote {}: study.json, report.json, convergence.svg, zones.svg, report.html, program.nc, toolpath.csv\n",
        best.k,
        best.plan.zones.len(),
        best.f_best,
        100.0 * study.mean_eta,
        wall,
        rayon::current_num_threads(),
        output.display(),
    ));
    text
}

/// A candidate's program time for the tables: seconds, "rejected", or "-" when not planned.
fn program_cell(c: Option<&Candidate>) -> String {
    match c {
        None => "-".into(),
        Some(c) => match (c.program_time_s, c.written) {
            (Some(t), true) => format!("{t:.2} *"),
            (Some(t), false) => format!("{t:.2}"),
            (None, _) => "rejected".into(),
        },
    }
}

/// The page of a study (`report.html`): the part, the written program with its
/// plan's model time and the single zone's time, the model and program time per
/// K, and one convergence curve per K.
fn optimisation_report(
    patch: &scallop_surface::Patch,
    study: &scallop_optim::study::Study,
    title: &str,
    command: &str,
    cutter: &str,
    choice: &Choice,
) -> scallop_report::ReportData {
    use scallop_report::{Convergence, Curve, Figure, ReportData, Zones};
    let written = choice.written();
    let model_best = &study.results[study.best];
    let r = &choice.output.report;
    let mut data = ReportData::new(&format!("optimisation: {title}"));
    data.command = format!("scallop optimize {command}");
    data.part = patch.tessellate(tol_display(patch)).ok().map(|t| t.mesh);
    data.figures = vec![
        Figure::text("written program", written.source.clone()),
        Figure::count("zones written", written.zones_written),
        Figure::number("program time (drop-cutter, stop-to-stop)", r.plan.total_time_s, 2, "s"),
        Figure::number("model time of the written plan", written.model_time_s, 2, "s"),
        Figure::number("program time (look-ahead, cutting)", r.plan.machining_time_lookahead_s, 2, "s"),
        Figure::number("simulated scallop", r.sim_max_scallop_mm, 4, "mm"),
        Figure::number("scallop limit (sh + resolution bound)", r.sim_scallop_limit_mm, 4, "mm"),
        Figure::number("model best", model_best.f_best, 2, &format!("s (K = {})", model_best.k)),
        Figure::number("mean gain over K (model)", 100.0 * study.mean_eta, 1, "%"),
    ];
    if let Some(single) = choice.best_single_zone().and_then(|c| c.program_time_s) {
        data.figures.push(Figure::number("best single-zone program", single, 2, "s"));
    }
    data.settings = vec![
        Figure::text("formulation", formulation_name(study.settings.formulation)),
        Figure::text("cutter", cutter),
        Figure::text("K range", format!("{} to {}", study.settings.k_min, study.settings.k_max)),
        Figure::number("budget per K", study.settings.budget, 0, "black-box evaluations"),
    ];
    for k in &study.results {
        let program = program_cell(choice.candidates.iter().find(|c| c.k == Some(k.k)));
        data.figures.push(Figure::number(
            &format!("K = {}: model / program", k.k),
            k.f_best,
            2,
            &format!("s / {program} s (start {:.2} s, {} evaluations)", k.f0, k.evaluations),
        ));
    }
    data.toolpath = Some(choice.output.toolpath.clone());
    data.zones = Some(Zones {
        label: "zone".into(),
        of_move: choice.output.zone_of_move.iter().map(|&z| u16::try_from(z).unwrap_or(u16::MAX)).collect(),
        names: choice.plan.zones.iter().map(|z| format!("{} ({:.0} deg)", z.zone, z.theta_deg)).collect(),
        times_s: choice.plan.zones.iter().map(|z| z.time_s).collect(),
    });
    data.convergence = vec![Convergence {
        title: "Best plan time against the budget spent, per K".into(),
        x_label: "budget spent (black-box evaluations)".into(),
        y_label: "best time (s)".into(),
        curves: study
            .results
            .iter()
            .map(|r| Curve {
                name: format!("K = {}", r.k),
                points: r.history.iter().map(|h| [h.spent, h.best]).collect(),
            })
            .collect(),
    }];
    data
}

/// A display tessellation tolerance: a thousandth of the control net's extent.
fn tol_display(patch: &scallop_surface::Patch) -> f64 {
    let b = patch.control_bounds();
    ((b.max - b.min).norm() * 1e-3).max(1e-3)
}

fn formulation_name(f: Formulation) -> &'static str {
    match f {
        Formulation::ThreeAxis => "3-axis",
        Formulation::ThreePlusTwo => "3+2",
        Formulation::Heuristic => "PCA heuristic",
    }
}

/// JSON text of a serialisable value, with the error as an I/O error.
fn to_json(value: &impl Serialize) -> std::io::Result<String> {
    serde_json::to_string_pretty(value).map_err(std::io::Error::other)
}

fn prefix(name: &str, e: Failure) -> Failure {
    match e {
        Failure::Rejected(e) => Failure::Rejected(anyhow::anyhow!("{name}: {e:#}")),
        other => other,
    }
}

fn rejected(name: &str, e: &OptimError) -> Failure {
    Failure::rejected(format!("{name}: {e}"))
}

/// The one patch of the job's part.
fn load_patch(spec: &JobFile, folder: &Path) -> CliResult<(scallop_surface::Patch, String)> {
    let (set, part_name) = match (&spec.part.file, &spec.part.builtin) {
        (_, Some(name)) => {
            let set = scallop_surface::builtin(name).ok_or_else(|| {
                Failure::rejected(format!("part.builtin = \"{name}\": no such built-in surface (choi, rubio)"))
            })?;
            (set, format!("built-in {name} surface"))
        }
        (Some(file), None) => {
            let path = folder.join(file);
            let loaded = crate::part::load(&path.to_string_lossy(), crate::part::UnitsArg::Mm)?;
            match loaded.part {
                scallop_engine::Part::Surfaces(set) => (set, loaded.description),
                scallop_engine::Part::Mesh(_) => {
                    return Err(Failure::rejected(format!(
                        "part.file = \"{file}\": zone optimisation needs a parametric surface (.toml), not a mesh"
                    )));
                }
            }
        }
        (None, None) => return Err(Failure::rejected("part: give `file` or `builtin`")),
    };
    if set.patches().len() != 1 {
        return Err(Failure::rejected(format!(
            "part: {} patches; zone optimisation works on one parametric patch",
            set.patches().len()
        )));
    }
    Ok((set.patches()[0].clone(), part_name))
}

/// Study and model settings from the job.
fn settings(spec: &JobFile, o: &OptimizeSpec) -> CliResult<(StudySettings, SurfaceSettings)> {
    let formulation = match o.formulation {
        FormulationWord::ThreeAxis => Formulation::ThreeAxis,
        FormulationWord::ThreePlusTwo => Formulation::ThreePlusTwo,
        FormulationWord::Heuristic => Formulation::Heuristic,
    };
    let radius = spec.cutter.diameter / 2.0;
    let tool = match spec.cutter.shape {
        ShapeWord::Ball => Cutter::Ball { radius },
        ShapeWord::Bull => Cutter::Toroidal { radius, corner: spec.cutter.corner_radius.unwrap_or(radius) },
        other => {
            return Err(Failure::rejected(format!(
                "cutter.shape = \"{}\": zone optimisation plans ball or bull-nose cutters",
                other.word()
            )));
        }
    };
    let machine = MachineLimits::from_thesis_units(spec.machine.feed, spec.machine.acceleration, spec.machine.jerk);
    let transitions = Transitions {
        model: match o.transition {
            TransitionWord::Linear => TransitionModel::Linear,
            TransitionWord::Retract => {
                TransitionModel::RetractTraverse { clearance: o.transition_clearance, rapid_feed: None }
            }
        },
        reorientation_s: 0.0,
    };
    #[allow(clippy::cast_sign_loss, clippy::cast_possible_truncation)] // validated: 2..=2000
    let grid = |g: [i64; 2]| [g[0] as usize, g[1] as usize];
    #[allow(clippy::cast_sign_loss, clippy::cast_possible_truncation)] // validated: 1 <= k_min <= k_max <= 64
    let (k_min, k_max) = (o.k_min as usize, o.k_max as usize);
    let study = StudySettings {
        formulation,
        k_min,
        k_max,
        budget: o.budget,
        surrogate: match o.surrogate {
            SurrogateWord::None => Surrogate::None,
            SurrogateWord::S3 => Surrogate::S3,
            SurrogateWord::S4 => Surrogate::S4,
        },
        seed: o.seed,
        cost: match o.surrogate_cost {
            SurrogateCostSpec::Ratio(r) => CostModel::Fixed(r),
            SurrogateCostSpec::Named(_) => CostModel::Measured,
        },
        model_search: o.model_search,
        barrier: match o.barrier {
            BarrierWord::Extreme => Barrier::Extreme,
            BarrierWord::Progressive => Barrier::Progressive,
        },
        start_omega: o.omega,
    };
    let model = SurfaceSettings {
        tool,
        scallop_height: spec.finishing.scallop_height,
        surrogate_scallop_height: o.surrogate_scallop_height,
        machine,
        transitions,
        grid: grid(o.grid),
        surrogate_grid: grid(o.surrogate_grid),
        step: o.step,
        surrogate_step: o.surrogate_step,
        // The written program dilates each zone by at least this (scallop_engine::finish_zones).
        zone_margin_mm: scallop_engine::ZONE_MARGIN_PER_RADIUS[0] * radius,
        ..SurfaceSettings::default()
    };
    Ok((study, model))
}
