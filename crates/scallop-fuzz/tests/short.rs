//! A short fuzzing campaign in the normal test suite: two thousand mutated inputs per

#![allow(clippy::unwrap_used, reason = "tests fail loudly by design")]
//! target (seconds); the long campaign is `scallop-fuzz` (docs/fuzzing.md).

use scallop_fuzz::{Target, campaign, run_one, seeds};

#[test]
fn every_target_survives_a_short_campaign() {
    std::panic::set_hook(Box::new(|_| {}));
    for target in Target::ALL {
        let report = campaign(target, 2026, 0..2000, &|_| {});
        assert_eq!(report.executions, 2000);
        // The mutations keep a share of the inputs valid, so the parsers' inner code runs.
        assert!(report.accepted > 0, "{}: no input was accepted", target.name());
        assert!(
            report.failures.is_empty(),
            "{}: {:?}",
            target.name(),
            &report.failures[..report.failures.len().min(5)]
        );
    }
}

#[test]
fn the_valid_seeds_parse_and_the_bad_cases_are_refused() {
    // The first seed of every target is a valid file: it must be accepted.
    let accepted = |target: Target, bytes: &[u8]| -> bool {
        let text = || scallop_io::utf8_text(bytes).expect("text seed");
        match target {
            Target::Stl => {
                scallop_io::read_mesh(bytes, scallop_io::MeshFormat::Stl, scallop_io::Units::Millimetres).is_ok()
            }
            Target::Obj => {
                scallop_io::read_mesh(bytes, scallop_io::MeshFormat::Obj, scallop_io::Units::Millimetres).is_ok()
            }
            Target::Ply => {
                scallop_io::read_mesh(bytes, scallop_io::MeshFormat::Ply, scallop_io::Units::Millimetres).is_ok()
            }
            Target::ThreeMf => {
                scallop_io::read_mesh(bytes, scallop_io::MeshFormat::ThreeMf, scallop_io::Units::Millimetres).is_ok()
            }
            Target::Gcode => scallop_io::gcode::read_gcode(text(), &Default::default()).is_ok(),
            Target::Cl => scallop_io::cl::read_cl_csv(text()).is_ok(),
            Target::Job => scallop_io::job::parse_job(text()).is_ok(),
            Target::Surface => scallop_surface::toml_format::parse_surfaces(text()).is_ok(),
            Target::Machine => scallop_machine::Machine::from_toml_str(text()).is_ok(),
        }
    };
    for target in Target::ALL {
        let s = seeds(target);
        assert!(accepted(target, &s[0]), "{}: the first seed must be valid", target.name());
        for bytes in &s {
            assert!(run_one(target, bytes).is_ok(), "{}", target.name());
        }
    }
    // The cases among the seeds are refused, not accepted.
    let stl = seeds(Target::Stl);
    assert!(scallop_io::read_mesh(&stl[2], scallop_io::MeshFormat::Stl, scallop_io::Units::Millimetres).is_err());
    let threemf = seeds(Target::ThreeMf);
    assert!(
        scallop_io::read_mesh(&threemf[1], scallop_io::MeshFormat::ThreeMf, scallop_io::Units::Millimetres).is_ok()
    );
    let e = scallop_io::read_mesh(&threemf[2], scallop_io::MeshFormat::ThreeMf, scallop_io::Units::Millimetres)
        .unwrap_err();
    assert!(e.to_string().contains("instancing"), "{e}");
    for (target, index) in [(Target::Gcode, 1), (Target::Gcode, 2), (Target::Surface, 2)] {
        assert!(!accepted(target, &seeds(target)[index]), "{} seed {index}", target.name());
    }
}
