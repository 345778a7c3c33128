//! The zone margin experiment of `docs/validation.md`: the Choi or Rubio surface
//! split into two zones along an oblique line in (u, v), finished by
//! `finish_zones` with the adaptive margin and with fixed margins, and the
//! simulated scallop of each program.
//!
//! `cargo run --release -p scallop-engine --example zone_margin -- choi 0 45`

use scallop_engine::{EngineError, FinishJob, Part, ZonePlanSpec, ZoneSpec, finish_zones};
use scallop_network::{CellLabels, Transitions};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let name = args.get(1).map_or("choi", String::as_str);
    let a: f64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(0.0);
    let b: f64 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(60.0);
    let Some(part) = Part::builtin(name) else {
        eprintln!("no built-in surface {name}");
        std::process::exit(2);
    };
    let n = 80;
    let labels: Vec<u32> = (0..n * n)
        .map(|k| {
            let (i, j) = (k / n, k % n);
            let (u, v) = ((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
            u32::from(u + 0.6 * v >= 0.8)
        })
        .collect();
    // Rubio is 41 mm tall and the verifying stock is a full block: 50 mm flutes.
    let cutter = scallop_cutter::Cutter::new(scallop_cutter::CutterShape::Bull { radius: 5.0, corner: 2.0 }, 50.0)
        .expect("a valid cutter");
    let job = FinishJob { part, part_name: name.into(), cutter, ..FinishJob::choi_demo() };
    for margin in [None, Some(0.0), Some(1.0), Some(2.0), Some(3.0), Some(5.0)] {
        let spec = ZonePlanSpec {
            labels: CellLabels { cells_u: n, cells_v: n, labels: labels.clone() },
            zones: vec![
                ZoneSpec { label: 0, direction_deg: a, tilt_deg: 0.0, azimuth_deg: 0.0, predicted_time_s: None },
                ZoneSpec { label: 1, direction_deg: b, tilt_deg: 0.0, azimuth_deg: 0.0, predicted_time_s: None },
            ],
            transitions: Transitions::default(),
            predicted_time_s: None,
            fixed_margin_mm: margin,
            machine: None,
        };
        let what = margin.map_or("adaptive".to_owned(), |m| format!("{m} mm"));
        match finish_zones(&job, &spec) {
            Ok(out) => {
                let r = &out.report;
                let margins: Vec<String> = r.zones.iter().map(|z| format!("{:.2}", z.margin_mm)).collect();
                println!(
                    "{name} margin {what:>9}: margins [{}] mm, time {:.2} s, simulated scallop {:.5} mm (limit {:.5})",
                    margins.join(", "),
                    r.plan.total_time_s,
                    r.sim_max_scallop_mm,
                    r.sim_scallop_limit_mm
                );
            }
            Err(EngineError::ScallopExceeded { height, limit, x, y }) => {
                println!(
                    "{name} margin {what:>9}: simulated scallop {height:.5} mm > {limit:.5} mm at ({x:.2}, {y:.2})"
                );
            }
            Err(e) => println!("{name} margin {what:>9}: {e}"),
        }
    }
}
