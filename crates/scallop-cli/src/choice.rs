//! The final choice of `scallop optimize` (issue 20, item 2): the best plans of
//! the study are planned again by drop-cutter and proven on the simulated stock,
//! next to the best single-zone programs (same cutter and scallop height), and
//! the fastest proven program is the one written. A zone plan is written only
//! when it beats every single-zone program, so the written program is never
//! slower than the single zone it was measured against.

use std::path::Path;

use scallop_engine::{EngineError, ProgramCandidate, ZoneFinishOutput, ZonePlanSpec, ZoneSpec, finish_candidates};
use scallop_network::{CellLabels, Transitions};
use scallop_optim::study::{KResult, PlanReport, Study, single_zone_plan, single_zone_times};
use scallop_optim::surface::SurfaceModel;
use serde::Serialize;

use crate::{CliResult, Failure};

/// Zone plans planned again by drop-cutter: the best plan of this many `K`, by
/// model time (each costs one drop-cutter plan and one stock simulation).
pub const ZONE_CANDIDATES: usize = 3;

/// The model scans single-zone directions every this many degrees over `[0, 180)`.
const SCAN_STEP_DEG: f64 = 5.0;

/// Single-zone directions closer than this (degrees, modulo 180) are one candidate.
const SAME_DIRECTION_DEG: f64 = 1.0;

/// The machine of 3+2 zone programs when the job has no `[setup]`.
const DEFAULT_MACHINE: &str = "linuxcnc-xyzac-trt";

/// One program the final choice planned and proved (part of `study.json`).
#[derive(Clone, Debug, Serialize)]
pub struct Candidate {
    /// What it is: `"K = 2"`, or `"single zone, automatic direction"` /
    /// `"single zone, best model direction"`.
    pub source: String,
    /// The `K` of a zone plan (`None`: a single zone).
    pub k: Option<usize>,
    /// Zones of the plan.
    pub zones_planned: usize,
    /// Zones with passes in the program (a zone without any is skipped; see
    /// `report.json`).
    pub zones_written: usize,
    /// Feed direction per zone (degrees, in the zone's frame).
    pub directions_deg: Vec<f64>,
    /// The network model's time of the plan (s).
    pub model_time_s: f64,
    /// The drop-cutter program's stop-to-stop time (s), when it was proven.
    pub program_time_s: Option<f64>,
    /// `program / model - 1`, when proven.
    pub model_gap: Option<f64>,
    /// The simulated scallop of the program (mm), when proven.
    pub sim_max_scallop_mm: Option<f64>,
    /// Why it was not proven (planner refusal, gouge, scallop over the limit).
    pub rejected: Option<String>,
    /// Whether this is the program written.
    pub written: bool,
}

/// What the final choice came to.
pub struct Choice {
    /// Every candidate, zone plans first (increasing model time), then single zones.
    pub candidates: Vec<Candidate>,
    /// Index of the written one in `candidates`.
    pub chosen: usize,
    /// Its program.
    pub output: ZoneFinishOutput,
    /// Its plan (zones, for `zones.svg` and the report).
    pub plan: PlanReport,
}

impl Choice {
    /// The written candidate.
    #[must_use]
    pub fn written(&self) -> &Candidate {
        &self.candidates[self.chosen]
    }

    /// The fastest proven single-zone candidate.
    #[must_use]
    pub fn best_single_zone(&self) -> Option<&Candidate> {
        self.candidates
            .iter()
            .filter(|c| c.k.is_none())
            .filter_map(|c| c.program_time_s.map(|t| (c, t)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(c, _)| c)
    }
}

/// Plans and proves the best zone plans of `study` and the best single-zone
/// programs, and keeps the fastest proven one.
///
/// # Errors
/// The job cannot be made into a finishing job, or no candidate was proven
/// (the message lists why each was rejected).
pub fn choose(
    spec: &scallop_io::job::JobFile,
    folder: &Path,
    study: &Study,
    model: &SurfaceModel,
    transitions: Transitions,
) -> CliResult<Choice> {
    let mut job = crate::run::finish_job(spec, folder)?;
    // 3+2 zones are written for the job's [setup] machine (default: the LinuxCNC
    // XYZAC trunnion); the setup's rotation is not used (each zone has its own).
    let machine = match job.setup.take() {
        Some(setup) => setup.machine,
        None => scallop_machine::Machine::builtin(DEFAULT_MACHINE)
            .map_err(|e| Failure::rejected(format!("machine `{DEFAULT_MACHINE}`: {e}")))?,
    };
    let mut ranked: Vec<&KResult> = study.results.iter().collect();
    ranked.sort_by(|a, b| a.f_best.total_cmp(&b.f_best).then(a.k.cmp(&b.k)));
    ranked.truncate(ZONE_CANDIDATES);

    let mut specs: Vec<ProgramCandidate> =
        ranked.iter().map(|r| ProgramCandidate::Zones(zone_spec(r, transitions, &machine))).collect();
    let mut candidates: Vec<Candidate> = ranked.iter().map(|r| zone_candidate(r)).collect();
    let mut plans: Vec<PlanReport> = ranked.iter().map(|r| r.plan.clone()).collect();

    let auto = scallop_engine::auto_direction_deg(&job).map_err(|e| Failure::rejected(e.to_string()))?;
    for (source, direction, time) in single_zone_directions(model, auto)? {
        specs.push(ProgramCandidate::SingleZone { direction_deg: direction, predicted_time_s: Some(time) });
        candidates.push(Candidate {
            source: source.into(),
            k: None,
            zones_planned: 1,
            zones_written: 0,
            directions_deg: vec![direction],
            model_time_s: time,
            program_time_s: None,
            model_gap: None,
            sim_max_scallop_mm: None,
            rejected: None,
            written: false,
        });
        plans.push(single_zone_plan(model, direction.to_radians()).map_err(|e| Failure::rejected(e.to_string()))?);
    }

    let results = finish_candidates(&job, &specs);
    let mut best: Option<(usize, ZoneFinishOutput)> = None;
    for (i, result) in results.into_iter().enumerate() {
        let c = &mut candidates[i];
        match result {
            Ok(out) => {
                let t = out.report.plan.total_time_s;
                c.program_time_s = Some(t);
                c.model_gap = Some(t / c.model_time_s - 1.0);
                c.sim_max_scallop_mm = Some(out.report.sim_max_scallop_mm);
                c.zones_written = out.report.zones.iter().filter(|z| z.passes > 0).count();
                // Strictly faster only: ties keep the earlier candidate (deterministic).
                if best.as_ref().is_none_or(|(_, b)| t < b.report.plan.total_time_s) {
                    best = Some((i, out));
                }
            }
            Err(e) => c.rejected = Some(rejection(&e)),
        }
    }
    let Some((chosen, output)) = best else {
        let why: Vec<String> =
            candidates.iter().map(|c| format!("{}: {}", c.source, c.rejected.as_deref().unwrap_or("-"))).collect();
        return Err(Failure::rejected(format!("no program of the study was proven ({})", why.join("; "))));
    };
    candidates[chosen].written = true;
    let plan = plans.swap_remove(chosen);
    Ok(Choice { candidates, chosen, output, plan })
}

/// The drop-cutter zone plan of a study result: zones in label order with the
/// optimiser's directions (and 3+2 orientations).
fn zone_spec(r: &KResult, transitions: Transitions, machine: &scallop_machine::Machine) -> ZonePlanSpec {
    let plan = &r.plan;
    ZonePlanSpec {
        labels: CellLabels { cells_u: plan.grid[0], cells_v: plan.grid[1], labels: plan.labels.clone() },
        zones: plan
            .zones
            .iter()
            .map(|z| ZoneSpec {
                label: u32::try_from(z.zone).unwrap_or(u32::MAX),
                direction_deg: z.theta_deg,
                tilt_deg: z.phi_deg,
                azimuth_deg: z.psi_deg,
                predicted_time_s: Some(z.time_s),
            })
            .collect(),
        transitions,
        predicted_time_s: Some(plan.time_s),
        fixed_margin_mm: None,
        machine: Some(machine.clone()),
    }
}

fn zone_candidate(r: &KResult) -> Candidate {
    Candidate {
        // The clustering can merge clusters (e.g. omega = 0 makes every cell alike):
        // the plan then has fewer zones than K, and says so.
        source: if r.plan.zones.len() == r.k {
            format!("K = {}", r.k)
        } else {
            format!("K = {} ({} zone{})", r.k, r.plan.zones.len(), if r.plan.zones.len() == 1 { "" } else { "s" })
        },
        k: Some(r.k),
        zones_planned: r.plan.zones.len(),
        zones_written: 0,
        directions_deg: r.plan.zones.iter().map(|z| z.theta_deg).collect(),
        model_time_s: r.f_best,
        program_time_s: None,
        model_gap: None,
        sim_max_scallop_mm: None,
        rejected: None,
        written: false,
    }
}

/// The single-zone candidates: the direction `scallop run` takes (`auto`,
/// degrees) and the model's best direction of a scan every [`SCAN_STEP_DEG`]
/// (when it differs), each with its model time.
fn single_zone_directions(model: &SurfaceModel, auto: f64) -> CliResult<Vec<(&'static str, f64, f64)>> {
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)] // 36 directions
    let n = (180.0 / SCAN_STEP_DEG).round() as usize;
    #[allow(clippy::cast_precision_loss)]
    let mut directions: Vec<f64> = (0..n).map(|i| i as f64 * SCAN_STEP_DEG).collect();
    directions.push(auto);
    let radians: Vec<f64> = directions.iter().map(|d| d.to_radians()).collect();
    let times = single_zone_times(model, &radians).map_err(|e| Failure::rejected(e.to_string()))?;
    let auto_time = times[n];
    let best = (0..n).min_by(|&a, &b| times[a].total_cmp(&times[b]).then(a.cmp(&b))).unwrap_or(0);
    let auto = auto + 0.0; // no "-0.0" in the reports
    let mut out = vec![("single zone, automatic direction", auto, auto_time)];
    let apart = (directions[best] - auto).rem_euclid(180.0);
    if apart.min(180.0 - apart) > SAME_DIRECTION_DEG {
        out.push(("single zone, best model direction", directions[best], times[best]));
    }
    Ok(out)
}

/// A rejection's text, on one line.
fn rejection(e: &EngineError) -> String {
    e.to_string().replace('\n', " ")
}
