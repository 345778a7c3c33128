//! Writes the generated 5-axis corpus of issue 19 (the minimal cases, a swarf-cut
//! impeller channel, a hull through the pole, long C windings, branch changes on links)
//! for the LinuxCNC `xyzac-trt` trunnion in the LinuxCNC dialect, one file per path and
//! mode (`NAME-joint.ngc`, `NAME-tcp.ngc`), each replayed before it is written:
//! `cargo run -p scallop-post --example post_corpus -- DIR`. Used by
//! `bench/linuxcnc/rs274.sh`.

#[path = "../tests/corpus/paths.rs"]
mod paths;

use scallop_machine::program::{ProgramOptions, to_program};
use scallop_machine::{Kinematics, Machine};
use scallop_post::{Dialect, OutputMode, PostParams, check_replay, program_text, replay};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::path::PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| ".".into()));
    let trunnion = Kinematics::new(&Machine::builtin("linuxcnc-xyzac-trt")?, 0.0);
    let short_c = Kinematics::new(&paths::short_c_trunnion(), 0.0);
    let mut corpus: Vec<(&str, &Kinematics, Vec<scallop_machine::program::ClRecord>)> =
        paths::CASES.iter().map(|(name, make)| (*name, &trunnion, make())).collect();
    corpus.push(("impeller", &trunnion, paths::impeller()));
    corpus.push(("hull", &trunnion, paths::hull()));
    corpus.push(("windings", &short_c, paths::windings(&short_c, 3)));
    corpus.push(("alternating", &trunnion, paths::alternating(4)));
    let dialect = Dialect::builtin("linuxcnc")?;
    let opts = ProgramOptions::default();
    for (name, kin, records) in &corpus {
        let program = to_program(kin, records, None, &opts)?;
        for mode in [OutputMode::Joint, OutputMode::Tcp] {
            let params = PostParams::new("1019", mode, 1, 0.0, 12000.0, &opts);
            let text = program_text(&program, kin, &dialect, &params)?;
            check_replay(&replay(&text, &dialect, kin)?, records, kin, &dialect, opts.tol_pos, opts.tol_ang)?;
            std::fs::write(dir.join(format!("{name}-{}.ngc", mode.name())), text)?;
        }
    }
    Ok(())
}
