//! What the CLI's integration tests share: the binary, scratch folders and a
//! small mesh.

#![allow(dead_code, reason = "each test binary uses a subset")]

use std::path::PathBuf;
use std::process::Command;

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
