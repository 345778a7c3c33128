//! The studies of chapter 4 on a cheap fake machining model: improvement,
//! budget, determinism, parallel = sequential, settings errors, unreachable
//! zones.

#![allow(
    clippy::unwrap_used,
    clippy::float_cmp,
    reason = "tests: a panic is the failure report; exact zeros and counts"
)]

use std::f64::consts::PI;

use scallop_optim::study::{
    Assessment, Design, Fidelity, Formulation, MachiningModel, PlanReport, Silent, StudyObserver, StudySettings,
    Surrogate, ZoneReport, run_study,
};
use scallop_optim::{Barrier, CostModel, OptimError};

/// `K` clusters as vertical strips of an 8 x 8 grid; cluster `c` machines
/// fastest along `a_c` (which moves with `omega`), at tilt `|phi| <= 0.8`
/// reachable, best at `zeta = 0.2`; a transition costs 1 s per extra zone.
struct Fake {
    unreachable: bool,
}

struct Strips {
    k: usize,
    best_angle: Vec<f64>,
    omega_penalty: f64,
}

impl Fake {
    fn time(p: &Strips, f: Formulation, d: &Design) -> Assessment {
        let mut time = p.omega_penalty;
        let mut violation = 0.0;
        for c in 0..p.k {
            time += 10.0 + 5.0 * (d.theta[c] - p.best_angle[c]).sin().powi(2);
            match f {
                Formulation::ThreeAxis => {}
                Formulation::ThreePlusTwo => {
                    let a = d.axis(c);
                    time += 2.0 * (1.0 - (a[0] * 0.3 + a[2] * 0.954).abs());
                    violation += (d.phi[c].abs() - 0.8).max(0.0).powi(2);
                }
                Formulation::Heuristic => time += (d.zeta[c] - 0.2).powi(2),
            }
        }
        #[allow(clippy::cast_precision_loss)]
        let transitions = (p.k - 1) as f64;
        Assessment { time_s: time + transitions, violation }
    }
}

impl MachiningModel for Fake {
    type Partition = Strips;

    fn partition(&self, k: usize, omega: &[f64; 4], _fidelity: Fidelity) -> Result<Strips, OptimError> {
        #[allow(clippy::cast_precision_loss)]
        let best_angle = (0..k).map(|c| (c as f64 * 0.7 + 0.3 * omega[2]).rem_euclid(PI)).collect();
        let omega_penalty = 3.0 * ((omega[0] - 0.6).powi(2) + (omega[1] - 0.4).powi(2) + omega[3].powi(2));
        Ok(Strips { k, best_angle, omega_penalty })
    }

    fn assess(&self, p: &Strips, f: Formulation, d: &Design, fidelity: Fidelity) -> Result<Assessment, OptimError> {
        let exact = Fake::time(p, f, d);
        Ok(match fidelity {
            Fidelity::BlackBox => exact,
            // Surrogates: same variations, other scale.
            Fidelity::S3 => Assessment { time_s: 0.8 * exact.time_s + 3.0, ..exact },
            Fidelity::S4 => Assessment { time_s: 0.5 * exact.time_s, ..exact },
        })
    }

    fn initial_design(&self, k: usize, f: Formulation, p: &Strips) -> Result<Design, OptimError> {
        if self.unreachable && f == Formulation::ThreePlusTwo {
            return Err(OptimError::Model(format!(
                "K = {k}: zone 1 (cluster 0): no tool axis reaches all its samples"
            )));
        }
        let mut d = Design::zeros(k);
        d.theta = p.best_angle.iter().map(|a| a + 0.9).collect();
        Ok(d)
    }

    fn describe(&self, p: &Strips, f: Formulation, d: &Design) -> Result<PlanReport, OptimError> {
        let a = Fake::time(p, f, d);
        let labels = (0..64).map(|i| u32::try_from((i / 8) * p.k / 8).unwrap()).collect();
        let zones = (0..p.k)
            .map(|c| ZoneReport {
                zone: c,
                cluster: c,
                cells: 64 / p.k,
                theta_deg: d.theta[c].to_degrees(),
                phi_deg: d.phi[c].to_degrees(),
                psi_deg: d.psi[c].to_degrees(),
                zeta_deg: d.zeta[c].to_degrees(),
                time_s: 0.0,
                length_mm: 0.0,
                passes: 1,
            })
            .collect();
        #[allow(clippy::cast_precision_loss)]
        let cell_xy = (0..64).map(|i| [(i / 8) as f64, (i % 8) as f64]).collect();
        Ok(PlanReport {
            time_s: a.time_s,
            transition_time_s: 0.0,
            violation: a.violation,
            grid: [8, 8],
            labels,
            cell_xy,
            zones,
        })
    }
}

fn settings(formulation: Formulation) -> StudySettings {
    StudySettings { k_max: 5, budget: 300.0, ..StudySettings::thesis(formulation) }
}

#[test]
fn every_formulation_improves_within_budget() {
    for formulation in [Formulation::ThreeAxis, Formulation::ThreePlusTwo, Formulation::Heuristic] {
        for surrogate in [Surrogate::None, Surrogate::S3, Surrogate::S4] {
            let s = StudySettings { surrogate, ..settings(formulation) };
            let study = run_study(&Fake { unreachable: false }, &s, &Silent, None).unwrap();
            assert_eq!(study.results.iter().map(|r| r.k).collect::<Vec<_>>(), vec![2, 3, 4, 5]);
            for r in &study.results {
                assert!(r.spent <= s.budget, "{formulation:?} {surrogate:?} K = {}: {}", r.k, r.spent);
                assert!(r.f_best <= r.f0 && r.eta > 0.05, "{formulation:?} {surrogate:?} K = {}: {r:?}", r.k);
                assert_eq!(r.plan.zones.len(), r.k);
                assert_eq!(r.plan.violation, 0.0);
                assert!((r.eta - (r.f0 - r.f_best) / r.f0).abs() < 1e-15);
            }
            let best = &study.results[study.best];
            assert!(study.results.iter().all(|r| r.f_best >= best.f_best));
        }
    }
}

#[test]
fn directions_converge_to_the_fake_optimum() {
    for formulation in [Formulation::ThreeAxis, Formulation::Heuristic] {
        let s = StudySettings { k_max: 4, budget: 3000.0, ..StudySettings::thesis(formulation) };
        let study = run_study(&Fake { unreachable: false }, &s, &Silent, None).unwrap();
        for r in &study.results {
            let p = Fake { unreachable: false }.partition(r.k, &r.best.omega, Fidelity::BlackBox).unwrap();
            for (t, a) in r.best.theta.iter().zip(&p.best_angle) {
                assert!((t - a).sin().abs() < 1e-3, "{formulation:?} K = {}: theta {t} vs {a}", r.k);
            }
        }
    }
}

#[test]
fn parallel_equals_sequential_and_is_deterministic() {
    let s = settings(Formulation::ThreePlusTwo);
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    let two = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    let a = one.install(|| run_study(&Fake { unreachable: false }, &s, &Silent, None).unwrap());
    let b = two.install(|| run_study(&Fake { unreachable: false }, &s, &Silent, None).unwrap());
    assert_eq!(a, b);
    assert_eq!(serde_json::to_string(&a).unwrap(), serde_json::to_string(&b).unwrap());
    let svg = scallop_optim::convergence_svg(&a);
    assert_eq!(svg.matches("K = ").count(), a.results.len());
    let zones = scallop_optim::zones_svg(&a.results[0].plan, "fake");
    assert_eq!(zones.matches("<rect").count(), 65);
    assert_eq!(zones.matches("<line").count(), a.results[0].plan.zones.len());
}

#[test]
fn progress_reports_every_black_box_evaluation() {
    use std::sync::Mutex;
    struct Count(Mutex<Vec<(usize, f64)>>, Mutex<Vec<usize>>);
    impl StudyObserver for Count {
        fn progress(&self, k: usize, spent: f64) {
            self.0.lock().unwrap().push((k, spent));
        }
        fn finished(&self, k: usize) {
            self.1.lock().unwrap().push(k);
        }
    }
    let count = Count(Mutex::new(Vec::new()), Mutex::new(Vec::new()));
    let s = StudySettings { cost: CostModel::Fixed(0.0), ..settings(Formulation::ThreeAxis) };
    let study = run_study(&Fake { unreachable: false }, &s, &count, None).unwrap();
    let calls = count.0.lock().unwrap();
    for r in &study.results {
        assert_eq!(calls.iter().filter(|(k, _)| *k == r.k).count(), r.evaluations);
    }
    let mut done = count.1.lock().unwrap().clone();
    done.sort_unstable();
    assert_eq!(done, vec![2, 3, 4, 5]);
}

#[test]
fn bad_settings_name_their_key() {
    let base = settings(Formulation::ThreeAxis);
    let cases = [
        (StudySettings { k_max: 1, k_min: 1, ..base }, "optimize.k_max"),
        (StudySettings { k_min: 6, ..base }, "optimize.k_min"),
        (StudySettings { budget: 0.0, ..base }, "optimize.budget"),
        (StudySettings { start_omega: [1.0, 1.2, 1.0, 1.0], ..base }, "optimize.omega"),
        (StudySettings { start_omega: [1.0, 1.0, -0.1, 1.0], ..base }, "optimize.omega"),
        (StudySettings { cost: CostModel::Fixed(-0.5), ..base }, "optimize.surrogate_cost"),
    ];
    for (s, key) in cases {
        let err = run_study(&Fake { unreachable: false }, &s, &Silent, None).unwrap_err().to_string();
        assert!(err.contains(key), "{key}: {err}");
    }
}

#[test]
fn an_unreachable_zone_is_an_error_and_an_infeasible_start_is_refused_by_the_extreme_barrier() {
    let err = run_study(&Fake { unreachable: true }, &settings(Formulation::ThreePlusTwo), &Silent, None).unwrap_err();
    assert!(err.to_string().contains("no tool axis reaches"), "{err}");

    /// Starts every tilt at 1.2 rad (violation > 0).
    struct Tilted;
    impl MachiningModel for Tilted {
        type Partition = Strips;
        fn partition(&self, k: usize, omega: &[f64; 4], f: Fidelity) -> Result<Strips, OptimError> {
            Fake { unreachable: false }.partition(k, omega, f)
        }
        fn assess(&self, p: &Strips, f: Formulation, d: &Design, fi: Fidelity) -> Result<Assessment, OptimError> {
            Fake { unreachable: false }.assess(p, f, d, fi)
        }
        fn initial_design(&self, k: usize, f: Formulation, p: &Strips) -> Result<Design, OptimError> {
            let mut d = Fake { unreachable: false }.initial_design(k, f, p)?;
            d.phi = vec![1.2; k];
            Ok(d)
        }
        fn describe(&self, p: &Strips, f: Formulation, d: &Design) -> Result<PlanReport, OptimError> {
            Fake { unreachable: false }.describe(p, f, d)
        }
    }
    let s = StudySettings { barrier: Barrier::Extreme, ..settings(Formulation::ThreePlusTwo) };
    let err = run_study(&Tilted, &s, &Silent, None).unwrap_err().to_string();
    assert!(err.contains("cannot be planned"), "{err}");
    // The progressive barrier walks back to the feasible region.
    let s = StudySettings { barrier: Barrier::Progressive, ..settings(Formulation::ThreePlusTwo) };
    let study = run_study(&Tilted, &s, &Silent, None).unwrap();
    assert!(study.results.iter().all(|r| r.plan.violation == 0.0), "{:?}", study.results[0].plan);
}
