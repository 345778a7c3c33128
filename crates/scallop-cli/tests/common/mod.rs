//! What the CLI's integration tests share: the binary, scratch folders and a
//! small mesh.

#![allow(dead_code, reason = "each test binary uses a subset")]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The `scallop` binary, as under CI (no progress bars).
pub fn scallop() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_scallop"));
    c.env("CI", "true");
    c
}

/// An empty scratch folder of this test process.
pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("scallop-cli-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

/// A binary STL of a 10 x 10 pyramid of height 5 (4 faces, slopes of 45 degrees).
pub fn pyramid_stl() -> Vec<u8> {
    let apex = [5.0f32, 5.0, 5.0];
    let base = [[0.0f32, 0.0, 0.0], [10.0, 0.0, 0.0], [10.0, 10.0, 0.0], [0.0, 10.0, 0.0]];
    let mut out = vec![0u8; 80];
    out.extend_from_slice(&4u32.to_le_bytes());
    for k in 0..4 {
        out.extend_from_slice(&[0u8; 12]);
        for p in [base[k], base[(k + 1) % 4], apex] {
            for c in p {
                out.extend_from_slice(&c.to_le_bytes());
            }
        }
        out.extend_from_slice(&[0u8; 2]);
    }
    out
}

/// The standard error of a run the binary rejected: exit code 1, no panic.
pub fn rejected(out: &std::process::Output) -> String {
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    err
}

/// `scallop run JOB -o OUT EXTRA...`.
pub fn run_job(job: &Path, out: &Path, extra: &[&str]) -> Output {
    scallop().arg("run").arg(job).arg("-o").arg(out).args(extra).output().expect("run")
}

/// [`run_job`] with `--json`, which must succeed: the report it prints.
pub fn run_json(job: &Path, out: &Path, extra: &[&str]) -> serde_json::Value {
    let done = run_job(job, out, &[&["--json"], extra].concat());
    assert!(done.status.success(), "{}", String::from_utf8_lossy(&done.stderr));
    serde_json::from_slice(&done.stdout).expect("json")
}
