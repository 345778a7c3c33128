//! Issue 21: `scallop run` killed with SIGKILL at random moments leaves either the
//! previous complete set of outputs or the new complete set, never a mix, and the next
//! run removes every temporary the killed ones left.

#![allow(clippy::unwrap_used, clippy::float_cmp, reason = "tests fail loudly by design; heights are compared exactly")]

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const FILES: [&str; 5] = ["program.nc", "report.json", "toolpath.csv", "report.html", "scene.glb"];

fn job(sh: f64) -> String {
    format!(
        "[part]\nbuiltin = \"choi\"\n\n[cutter]\nshape = \"ball\"\ndiameter = 10\n\n[finishing]\nscallop_height = {sh}\n\n\
         [verify]\nresolution = 0.5\n"
    )
}

fn run(dir: &Path, job: &str, out: &str) -> std::process::Child {
    Command::new(env!("CARGO_BIN_EXE_scallop"))
        .current_dir(dir)
        .env("CI", "true")
        .args(["run", job, "-o", out])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap()
}

/// The deterministic files of a complete set.
fn signature(folder: &Path) -> (Vec<u8>, Vec<u8>) {
    (std::fs::read(folder.join("program.nc")).unwrap(), std::fs::read(folder.join("toolpath.csv")).unwrap())
}

/// Temporaries left next to or inside the output folder.
fn temporaries(dir: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    for folder in [dir.to_path_buf(), dir.join("out")] {
        for entry in std::fs::read_dir(folder).into_iter().flatten().flatten() {
            let name = entry.file_name().to_string_lossy().into_owned();
            if name.contains(".tmp-") || name.contains(".old-") {
                found.push(entry.path());
            }
        }
    }
    found
}

#[test]
fn sigkill_at_random_moments_leaves_one_complete_set() {
    let dir = std::env::temp_dir().join(format!("scallop-kill-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let jobs = [("a.toml", 0.05), ("b.toml", 0.04)];
    for (name, sh) in jobs {
        std::fs::write(dir.join(name), job(sh)).unwrap();
    }
    // The two reference sets, and how long a run takes here.
    let mut sets = Vec::new();
    let mut duration = Duration::ZERO;
    for (name, _) in jobs {
        let start = Instant::now();
        assert!(run(&dir, name, &format!("ref-{name}")).wait().unwrap().success());
        duration = duration.max(start.elapsed());
        sets.push(signature(&dir.join(format!("ref-{name}"))));
    }
    assert_ne!(sets[0], sets[1]);
    assert!(run(&dir, "a.toml", "out").wait().unwrap().success());
    // Kill moments spread over the run, most of them in its second half where the
    // outputs are written; a linear congruential sequence keeps them reproducible.
    let mut state = 0x2026_u64;
    let mut killed = 0;
    // The reference runs' duration is a guess of the next runs' (a loaded
    // machine makes it too long): after ten rounds with no kill, the moments
    // move into the first third of the run, for at most 30 more rounds.
    for round in 0..40 {
        if round >= 10 && killed > 0 {
            break;
        }
        state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        #[allow(clippy::cast_precision_loss)]
        let draw = (state >> 11) as f64 / (1u64 << 53) as f64;
        let fraction = if round < 10 { 0.3 + 0.8 * draw } else { 0.02 + 0.3 * draw };
        let (name, _) = jobs[round % 2];
        let mut child = run(&dir, name, "out");
        std::thread::sleep(duration.mul_f64(fraction));
        if child.try_wait().unwrap().is_none() {
            child.kill().unwrap(); // SIGKILL
            killed += 1;
        }
        let _ = child.wait();
        let out = dir.join("out");
        for file in FILES {
            assert!(out.join(file).is_file(), "round {round}: {file} missing after the kill");
        }
        let got = signature(&out);
        let which = sets.iter().position(|s| *s == got);
        assert!(which.is_some(), "round {round}: program.nc and toolpath.csv are not one set's");
        let report: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
        let sh = report["scallop_height_mm"].as_f64().unwrap();
        assert_eq!(sh, jobs[which.unwrap()].1, "round {round}: report.json is from the other set");
    }
    assert!(killed > 0, "no run was killed: the runs finished before every kill moment");
    // One complete run removes what the killed ones left.
    assert!(run(&dir, "b.toml", "out").wait().unwrap().success());
    assert_eq!(temporaries(&dir), Vec::<PathBuf>::new());
    assert_eq!(signature(&dir.join("out")), sets[1]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn leftovers_of_killed_runs_are_restored_or_removed() {
    // A run killed between the two renames of the fallback commit leaves the previous set in
    // `.out.old-PID` and no `out`; one killed while writing leaves `.out.tmp-PID`, and older
    // versions left `.FILE.tmp-PID` files. PID 99999999 is above Linux's pid_max: dead.
    let dir = std::env::temp_dir().join(format!("scallop-leftovers-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("a.toml"), job(0.05)).unwrap();
    assert!(run(&dir, "a.toml", "out").wait().unwrap().success());
    std::fs::write(dir.join("out/mine.txt"), "the user's own file").unwrap();
    std::fs::rename(dir.join("out"), dir.join(".out.old-99999999")).unwrap();
    std::fs::create_dir(dir.join(".out.tmp-99999999")).unwrap();
    std::fs::write(dir.join(".out.tmp-99999999/program.nc"), "half a program").unwrap();
    assert!(run(&dir, "a.toml", "out").wait().unwrap().success());
    // The previous set was put back, then replaced; the user's file survived; nothing is left.
    assert_eq!(std::fs::read_to_string(dir.join("out/mine.txt")).unwrap(), "the user's own file");
    assert_eq!(temporaries(&dir), Vec::<PathBuf>::new());
    std::fs::write(dir.join("out/.report.html.tmp-99999999"), "half a page").unwrap();
    assert!(run(&dir, "a.toml", "out").wait().unwrap().success());
    assert_eq!(temporaries(&dir), Vec::<PathBuf>::new());
    for file in FILES {
        assert!(dir.join("out").join(file).is_file(), "{file}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
