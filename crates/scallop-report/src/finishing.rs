//! The report of a finishing job (`scallop run`, `scallop demo`).

use scallop_engine::{FinishJob, FinishOutput};
use scallop_sim::{ZMap, part_heights};
use scallop_strategy::lookahead_profile;

use crate::{DeviationMap, Figure, Histogram, PathTiming, ReportData, commanded_feed};

impl ReportData {
    /// The report of a finishing job: part (its tessellation), stock,
    /// toolpath with the look-ahead feed profile, simulated deviation, key
    /// figures (from `out.report`, with `planning_seconds` measured by the
    /// caller), settings and the scallop histogram.
    #[must_use]
    pub fn from_finishing(job: &FinishJob, out: &FinishOutput, planning_seconds: f64, command: &str) -> ReportData {
        let (r, p, d) = (&out.report, &out.report.plan, &out.details);
        let path = &out.toolpath;
        let rapid_rate = d.params.rapid_rate * 60.0;
        let profile = lookahead_profile(path, &d.params);
        let timing = PathTiming {
            model: "look-ahead model (b)".into(),
            durations: profile.iter().map(|m| m.duration).collect(),
            commanded: path.moves().iter().map(|m| commanded_feed(path, m.kind, rapid_rate)).collect(),
            achieved: profile.iter().map(|m| m.peak * 60.0).collect(),
        };
        let deviation = DeviationMap::of_stock(&d.simulation.zmap, &d.prepared.index, r.sim_gouge_tolerance_mm);
        let sc = d.scallop.as_ref();
        let mut figures = vec![
            Figure::number("machining time, stop-to-stop model (a)", p.machining_time_s, 1, "s"),
            Figure::number("machining time, look-ahead model (b)", p.machining_time_lookahead_s, 1, "s"),
            Figure::number("rapid time", p.rapid_time_s, 1, "s"),
            Figure::number("plunge time", p.plunge_time_s, 1, "s"),
            Figure::number("total time (a)", p.total_time_s, 1, "s"),
            Figure::number("path length (passes + links)", p.path_length_mm, 1, "mm"),
            Figure::number("feed length", p.feed_length_mm, 1, "mm"),
            Figure::number("link length", p.link_length_mm, 1, "mm"),
            Figure::number("rapid length", p.rapid_length_mm, 1, "mm"),
            Figure::number("plunge length", p.plunge_length_mm, 1, "mm"),
            Figure::count("passes", p.passes),
            Figure::count("planes", p.planes),
            Figure::count("links on the surface", p.links),
            Figure::count("retracts", p.retracts),
            Figure::count("moves", p.points),
            Figure::number("max scallop (measured)", p.max_scallop_mm, 5, "mm"),
            Figure::number("mean scallop (measured)", p.mean_scallop_mm, 5, "mm"),
            Figure::number("simulated: most material left", r.sim_max_material_mm, 4, "mm"),
            Figure::number("simulated: deepest deviation", r.sim_min_deviation_mm, 4, "mm"),
            Figure::text("gouges", format!("none (deepest within -{:.4} mm)", r.sim_gouge_tolerance_mm)),
            Figure::text("rapids into stock, collisions", "none"),
            Figure::number("planning time", planning_seconds, 2, "s"),
        ];
        if let Some(sc) = sc {
            figures.insert(17, Figure::number("rest material", sc.rest_material_mm, 5, "mm"));
        }
        let [v, a, j] = job.machine;
        let settings = vec![
            Figure::text("part", r.part.clone()),
            Figure::text("cutter", r.cutter.clone()),
            Figure::number("scallop height", r.scallop_height_mm, 4, "mm"),
            Figure::number("feed direction from X", r.direction_deg, 2, "deg"),
            Figure::text("direction", if job.direction_deg.is_some() { "given" } else { "from the PCA of the part" }),
            Figure::text("pattern", format!("{:?}", job.pattern).to_lowercase()),
            Figure::number("feed V", v, 2, "m/min"),
            Figure::number("acceleration A", a, 2, "m/s²"),
            Figure::number("jerk J", j, 2, "m/s³"),
            Figure::number("rapid rate", rapid_rate, 0, "mm/min"),
            Figure::number("clearance", job.clearance, 2, "mm"),
            Figure::number("path tolerance", job.tolerances.path, 4, "mm"),
            Figure::number("gouge tolerance", job.tolerances.gouge, 4, "mm"),
            Figure::number("max forward step", job.max_step, 3, "mm"),
            if r.chordal_error_mm > 0.0 {
                Figure::number("chordal error of the tessellation", r.chordal_error_mm, 5, "mm")
            } else {
                Figure::text("part", "a mesh, machined as given (no tessellation)")
            },
            Figure::number("simulation cell", r.sim_resolution_mm, 3, "mm"),
            Figure::number("PCA slope", r.slope_deg, 2, "deg"),
            Figure::number("critical slope", r.critical_slope_deg, 2, "deg"),
        ];
        ReportData {
            title: format!("Finishing the {}", r.part),
            command: command.into(),
            part: Some(d.prepared.mesh.clone()),
            stock: Some(d.stock),
            toolpath: Some(path.clone()),
            rapid_rate,
            timing: Some(timing),
            zones: None,
            deviation: Some(deviation),
            figures,
            settings,
            histogram: sc.map(|sc| Histogram {
                title: format!("Measured scallop heights ({} samples)", sc.samples),
                bin_width: sc.bin_width_mm,
                counts: sc.histogram.clone(),
                last_is_overflow: true,
                unit: "mm".into(),
            }),
            convergence: Vec::new(),
            engagement: None,
        }
    }
}

impl DeviationMap {
    /// The simulated stock's height minus the part's (`index`) at every cell
    /// of `zmap` (NaN off the part).
    #[must_use]
    pub fn of_stock(zmap: &ZMap, index: &scallop_mesh::MeshIndex, gouge_tolerance: f64) -> DeviationMap {
        let top = part_heights(zmap, index);
        let values: Vec<f64> =
            zmap.heights().iter().zip(&top).map(|(s, t)| if t.is_finite() { s - t } else { f64::NAN }).collect();
        let c0 = zmap.cell_center(0, 0);
        DeviationMap {
            origin: [c0.x, c0.y],
            cell: [zmap.cell_size().0, zmap.cell_size().1],
            nx: zmap.nx(),
            ny: zmap.ny(),
            values,
            gouge_tolerance,
        }
    }
}
