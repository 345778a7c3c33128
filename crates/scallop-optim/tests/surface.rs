//! The real model (clustering + network planner) on the spec's surfaces, on
//! coarse grids so the tests stay fast: every formulation improves on its
//! start within the budget, runs are identical on 1 and 2 threads, S3 and S4
//! follow the black box, and a zone no orientation can reach is an error.

#![allow(clippy::unwrap_used, clippy::float_cmp, reason = "tests: a panic is the failure report; exact zeros")]

use scallop_geom::Point3;
use scallop_optim::study::{Design, Fidelity, Formulation, MachiningModel, Silent, StudySettings, run_study};
use scallop_optim::surface::{SurfaceModel, SurfaceSettings};

fn coarse() -> SurfaceSettings {
    SurfaceSettings {
        grid: [32, 32],
        surrogate_grid: [16, 16],
        step: 1.0,
        surrogate_step: 5.0,
        ..SurfaceSettings::default()
    }
}

fn model(name: &str) -> SurfaceModel {
    let set = scallop_surface::builtin(name).unwrap();
    SurfaceModel::new(&set.patches()[0], coarse()).unwrap()
}

#[test]
fn every_formulation_improves_on_its_start_and_reaches_every_zone() {
    for name in ["choi", "rubio"] {
        let m = model(name);
        for formulation in [Formulation::ThreeAxis, Formulation::ThreePlusTwo, Formulation::Heuristic] {
            let s = StudySettings { k_min: 2, k_max: 3, budget: 25.0, ..StudySettings::thesis(formulation) };
            let study = run_study(&m, &s, &Silent, None).unwrap();
            for r in &study.results {
                assert!(
                    r.f_best <= r.f0 && r.f_best > 0.0,
                    "{name} {formulation:?} K = {}: {} > {}",
                    r.k,
                    r.f_best,
                    r.f0
                );
                assert!(r.spent <= s.budget);
                assert_eq!(r.plan.violation, 0.0, "{name} {formulation:?} K = {}", r.k);
                assert!(r.plan.zones.len() >= r.k, "{name}: {} zones for K = {}", r.plan.zones.len(), r.k);
                // The described plan is the optimum found (same model, same design).
                assert!((r.plan.time_s - r.f_best).abs() <= 1e-9 * r.f_best, "{} vs {}", r.plan.time_s, r.f_best);
                assert_eq!(r.plan.labels.len(), 32 * 32);
                assert!(r.plan.zones.iter().all(|z| z.passes > 0 || z.cells < 4));
            }
        }
    }
}

#[test]
fn one_and_two_threads_give_the_same_study() {
    let m = model("rubio");
    let s = StudySettings { k_min: 2, k_max: 3, budget: 15.0, ..StudySettings::thesis(Formulation::ThreePlusTwo) };
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    let two = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    let a = one.install(|| run_study(&m, &s, &Silent, None).unwrap());
    let b = two.install(|| run_study(&m, &s, &Silent, None).unwrap());
    assert_eq!(serde_json::to_string(&a).unwrap(), serde_json::to_string(&b).unwrap());
}

#[test]
fn surrogates_follow_the_black_box_over_feed_directions() {
    // Protocol P7 in small: one cluster, feed direction swept over [0, pi).
    let m = model("choi");
    for fidelity in [Fidelity::S3, Fidelity::S4] {
        let (bb, sur): (Vec<f64>, Vec<f64>) = (0..18)
            .map(|i| {
                let mut d = Design::zeros(1);
                d.theta[0] = f64::from(i) * 10f64.to_radians();
                let p = m.partition(1, &[1.0; 4], Fidelity::BlackBox).unwrap();
                let ps = m.partition(1, &[1.0; 4], fidelity).unwrap();
                let f = m.assess(&p, Formulation::ThreeAxis, &d, Fidelity::BlackBox).unwrap().time_s;
                let g = m.assess(&ps, Formulation::ThreeAxis, &d, fidelity).unwrap().time_s;
                (f, g)
            })
            .unzip();
        let mean = |v: &[f64]| v.iter().sum::<f64>() / 18.0;
        let (mf, mg) = (mean(&bb), mean(&sur));
        let cov: f64 = bb.iter().zip(&sur).map(|(f, g)| (f - mf) * (g - mg)).sum();
        let var = |v: &[f64], m: f64| v.iter().map(|x| (x - m).powi(2)).sum::<f64>();
        let rho = cov / (var(&bb, mf) * var(&sur, mg)).sqrt();
        assert!(rho > 0.5, "{fidelity:?}: Pearson rho {rho}");
    }
}

#[test]
fn a_zone_no_orientation_can_reach_is_an_error() {
    // A curl whose normals turn all the way round: one zone (K = 1) cannot be
    // seen from any single tool axis.
    let row = |x: f64, z: f64| vec![Point3::new(x, 0.0, z), Point3::new(x, 20.0, z)];
    let control = [row(0.0, 0.0), row(40.0, 40.0), row(-40.0, 40.0), row(1.0, 0.0)];
    let patch = scallop_surface::Patch::bezier("curl", [3, 1], &control, None).unwrap();
    let m = SurfaceModel::new(&patch, coarse()).unwrap();
    let s = StudySettings { k_min: 1, k_max: 2, budget: 5.0, ..StudySettings::thesis(Formulation::ThreePlusTwo) };
    let err = run_study(&m, &s, &Silent, None).unwrap_err().to_string();
    assert!(err.contains("no tool orientation reaches"), "{err}");
}
