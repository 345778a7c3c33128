//! The report of a job of several operations on one stock (`scallop run` on
//! a job with `[[operation]]`s): the part, the stock box, every operation's
//! moves coloured by operation, the deviation of the stock they all left,
//! and the figures of each operation.

use scallop_engine::{Job, JobOutput};
use scallop_toolpath::MoveKind;

use scallop_strategy::lookahead_profile;

use crate::{DeviationMap, Figure, PathTiming, ReportData, Zones, commanded_feed};

impl ReportData {
    /// The report of a job: each operation is a "zone" of the viewer (its
    /// moves take its colour, its time is plotted), the deviation is that of
    /// the final simulated stock, and the figures are the job's then each
    /// operation's (planning times as the caller measured them, in
    /// `out.report`).
    #[must_use]
    pub fn from_job(job: &Job, out: &JobOutput, seconds: f64, command: &str) -> ReportData {
        let r = &out.report;
        let rapid_rate = job.operations.first().map_or(crate::tol::NOMINAL_RAPID_RATE, |o| o.finish.rapid_rate * 60.0);
        let mut of_move = Vec::with_capacity(out.toolpath.moves().len());
        for (k, path) in out.toolpaths.iter().enumerate() {
            of_move.extend(std::iter::repeat_n(u16::try_from(k).unwrap_or(u16::MAX), path.moves().len()));
        }
        let zones = Zones {
            label: "operation".into(),
            of_move,
            names: r
                .operations
                .iter()
                .enumerate()
                .map(|(k, o)| format!("{}. {} ({})", k + 1, o.name, o.cutter))
                .collect(),
            times_s: r.operations.iter().map(|o| o.plan.total_time_s).collect(),
        };
        let mut figures = vec![
            Figure::number("total time, stop-to-stop, rapids included", r.total_time_s, 1, "s"),
            Figure::number("simulated: deepest deviation", r.sim_min_deviation_mm, 4, "mm"),
            Figure::text("gouges", format!("none (deepest within -{:.4} mm)", r.sim_gouge_tolerance_mm)),
            Figure::text("rapids into stock, collisions", "none"),
            Figure::number(
                if job.operations.last().is_some_and(|o| o.rough.is_some()) {
                    "simulated: most material left (the last operation roughs)"
                } else {
                    "simulated scallop on the machined surface"
                },
                r.sim_max_scallop_mm,
                4,
                "mm",
            ),
            Figure::number("unreachable material (last cutter)", r.rest.area_mm2, 1, "mm²"),
            Figure::number("planning, cutting and proof", seconds, 2, "s"),
        ];
        for (k, o) in r.operations.iter().enumerate() {
            let p = &o.plan;
            let label = |what: &str| format!("{}. {}: {what}", k + 1, o.name);
            figures.push(Figure::text(&label("tool"), format!("T{} {}", o.tool, o.cutter)));
            figures.push(Figure::number(&label("time"), p.total_time_s, 1, "s"));
            figures.push(Figure::count(&label("passes"), p.passes));
            figures.push(Figure::number(&label("feed length"), p.feed_length_mm, 0, "mm"));
            figures.push(Figure::number(&label("removed"), o.stock.removed_mm3, 0, "mm³"));
            figures.push(Figure::number(&label("feed length in air"), 100.0 * o.stock.air_length_share, 0, "%"));
            figures.push(Figure::number(&label("planning time"), p.planning_time_s, 2, "s"));
            if let Some(e) = &o.engagement {
                figures.push(Figure::text(
                    &label("engagement, simulated (median / p95 / max, target)"),
                    format!(
                        "{:.0}° / {:.0}° / {:.0}°, target {:.0}° (entries apart: up to {:.0}°)",
                        e.p50_deg, e.p95_deg, e.max_deg, e.target_deg, e.entry_max_deg
                    ),
                ));
                figures.push(Figure::number(&label("length above 1.2 x target"), e.over_length_mm, 0, "mm"));
                figures.push(Figure::number(&label("full-slot length"), e.slot_length_mm, 0, "mm"));
                figures.push(Figure::number(&label("tool-down links"), 100.0 * e.link_share, 0, "%"));
            }
        }
        let settings = job
            .operations
            .iter()
            .enumerate()
            .map(|(k, o)| {
                let what = match &o.rough {
                    Some(s) => format!("rough, stepdown {} mm, stepover {}", s.stepdown, s.stepover),
                    None => format!("finish, {:?}, sh {} mm", o.finish.strategy, o.finish.scallop_height),
                };
                Figure::text(&format!("operation {}", k + 1), format!("{}: {what}", o.name))
            })
            .collect();
        let path = &out.toolpath;
        let (mut durations, mut commanded, mut achieved) = (Vec::new(), Vec::new(), Vec::new());
        for (op, p) in job.operations.iter().zip(&out.toolpaths) {
            let params = op.finish.timing_params();
            let profile = lookahead_profile(p, &params);
            durations.extend(profile.iter().map(|m| m.duration));
            achieved.extend(profile.iter().map(|m| m.peak * 60.0));
            commanded.extend(p.moves().iter().map(|m| commanded_feed(p, m.kind, params.rapid_rate * 60.0)));
        }
        let timing = (durations.len() == path.moves().len()).then(|| PathTiming {
            model: "look-ahead model (b), each operation with its feeds".into(),
            durations,
            commanded,
            achieved,
        });
        ReportData {
            title: format!("{} operations on one stock: {}", r.operations.len(), r.part),
            command: command.into(),
            part: Some(out.prepared.mesh.clone()),
            stock: Some(out.simulation.zmap.stock()),
            toolpath: Some(path.clone()),
            rapid_rate,
            timing,
            zones: Some(zones),
            deviation: Some(DeviationMap::of_stock(
                &out.simulation.zmap,
                &out.prepared.index,
                r.sim_gouge_tolerance_mm,
            )),
            figures,
            settings,
            histogram: None,
            convergence: Vec::new(),
            engagement: engagement_ratios(r, &out.toolpaths),
        }
    }
}

/// Each move's simulated engagement over its operation's target, for the
/// operations that report one (`None` elsewhere); `None` when no operation does.
fn engagement_ratios(
    r: &scallop_engine::JobReport,
    toolpaths: &[scallop_toolpath::Toolpath],
) -> Option<Vec<Option<f64>>> {
    if r.operations.iter().all(|o| o.engagement.is_none()) {
        return None;
    }
    let mut ratios = Vec::new();
    for (o, path) in r.operations.iter().zip(toolpaths) {
        let n = path.moves().len();
        match &o.engagement {
            Some(e) if e.move_deg.len() == n && e.target_deg > 0.0 => {
                let moves = path.moves().iter();
                ratios.extend(e.move_deg.iter().zip(moves).map(|(&d, m)| {
                    (!matches!(m.kind, MoveKind::Rapid | MoveKind::Retract)).then_some(d / e.target_deg)
                }));
            }
            _ => ratios.extend(std::iter::repeat_n(None, n)),
        }
    }
    Some(ratios)
}
