//! Issue 21: every bad input of the corpus, generated here, is refused by the
//! `scallop` binary with exit code 1 and a message naming the file, the place and the
//! fix (never a panic, an abort or a run without end). The inputs are equivalents of
//! the files in the issue (same numbers, same structure), built by the test itself.

#![allow(clippy::unwrap_used, reason = "tests fail loudly by design")]

use std::path::Path;

mod common;

use common::{rejected, scallop, scratch};

/// Runs `scallop ARGS` in `dir`; asserts exit code 1, no panic, and that stderr names
/// every string of `expect`. Returns stderr.
fn refused(dir: &Path, args: &[&str], expect: &[&str]) -> String {
    let stderr = rejected(&scallop().current_dir(dir).args(args).output().unwrap());
    for e in expect {
        assert!(stderr.contains(e), "scallop {args:?}: `{e}` not in: {stderr}");
    }
    stderr
}

const UCP710: &str = include_str!("../../../machines/mikron-ucp710.toml");

/// A short 3+2 cutter-location file (tilted tool axis).
const CL: &str = "kind,x,y,z,i,j,k\nrapid,0,0,50,0,0.5,0.8660254\nplunge,0,0,0,0,0.5,0.8660254\n\
                  feed,10,0,0,0,0.5,0.8660254\nfeed,10,10,0,0,0.5,0.8660254\nretract,10,10,50,0,0.5,0.8660254\n";

#[test]
fn machine_descriptions_with_nan_inf_or_huge_numbers() {
    let dir = scratch("machine");
    std::fs::write(dir.join("cl.csv"), CL).unwrap();
    let frame = "part_frame = { origin = [0, 0, 0], rotation = [[1, 0, 0], [0, 1, 0], [0, 0, 1]] }";
    let spindle = "spindle = { gauge_point = [0, 0, 0], tool_axis = [0, 0, 1] }";
    let pivot = "point = [0, 0, -100]";
    assert!(UCP710.contains(frame) && UCP710.contains(spindle) && UCP710.contains(pivot));
    let f = |origin: &str, rotation: &str| format!("part_frame = {{ origin = {origin}, rotation = {rotation} }}");
    let cases = [
        (frame, f("[0, 0, 0]", "[[1, 0, 0], [0, nan, 0], [0, 0, 1]]"), "part_frame.rotation"),
        (frame, f("[0, 0, 0]", "[[1, 0, 0], [0, 1, 0], [0, 0, inf]]"), "part_frame.rotation"),
        (frame, f("[nan, 0, 0]", "[[1, 0, 0], [0, 1, 0], [0, 0, 1]]"), "part_frame.origin"),
        (spindle, "spindle = { gauge_point = [nan, 0, 0], tool_axis = [0, 0, 1] }".into(), "spindle.gauge_point"),
        (pivot, "point = [0, 0, nan]".into(), "axes.A.point"),
        (pivot, "point = [0, 0, 1e308]".into(), "axes.A.point"),
    ];
    for (k, (from, to, key)) in cases.iter().enumerate() {
        let name = format!("m{k}.toml");
        std::fs::write(dir.join(&name), UCP710.replacen(from, to, 1)).unwrap();
        refused(&dir, &["post", "cl.csv", "--machine", &name, "--dialect", "siemens840d", "-o", "x.nc"], &[&name, key]);
    }
    assert!(!dir.join("x.nc").exists());
}

#[test]
fn gcode_coordinates_that_overflow() {
    let dir = scratch("gcode");
    let big = "9".repeat(308);
    let cases = [
        (format!("G21 G90\nG0 X10 Y10 Z50\nG1 Z38 F100\nG20\nG1 X{big}\nG21\nG0 Z60\n"), "line 5"),
        (format!("G21 G90\nG0 X10 Y10 Z50\nG1 Z38 F100\nG91\nG1 X{big}\nG1 X{big}\nG1 Y5\nG90\nG0 Z60\n"), "line 5"),
        (format!("G21 G90\nG0 X10 Y10 Z50\nG1 Z45 F100\nG2 X10 Y10 I17{}\nG0 Z60\n", "0".repeat(307)), "line 4"),
    ];
    for (k, (program, line)) in cases.iter().enumerate() {
        let name = format!("p{k}.nc");
        std::fs::write(dir.join(&name), program).unwrap();
        let args = [
            "simulate",
            "--part",
            "choi",
            "--program",
            &name,
            "--cutter",
            "ball",
            "--diameter",
            "6",
            "--flute-length",
            "60",
            "--resolution",
            "0.5",
            "-o",
            "s",
        ];
        refused(&dir, &args, &[&name, line, "outside"]);
    }
}

#[test]
fn surface_degrees_beyond_the_control_net() {
    let dir = scratch("surface");
    for degree in ["2147483648", "9223372036854775807"] {
        let text = format!(
            "units = \"mm\"\n\n[[patch]]\nname = \"p\"\nkind = \"bezier\"\ndegree = [2, {degree}]\ncontrol = [\n\
             [[0.0, -15.32, -12.85], [0.0, -6.42, 7.66], [0.0, 15.32, 12.85]],\n\
             [[40.0, -18.53, -9.02], [40.0, -9.64, 11.49], [40.0, 12.10, 16.68]],\n\
             [[80.0, -28.17, 2.46], [80.0, -22.49, 26.81], [80.0, 2.46, 28.17]],\n]\n"
        );
        std::fs::write(dir.join("s.toml"), text).unwrap();
        refused(&dir, &["analyze", "s.toml"], &["s.toml", "degree in v", degree, "line 3"]);
    }
}

/// An ASCII STL of a bumpy `n x n` grid over `[0, size]^2`, with `corner` moved to `far`.
fn grid_stl(n: usize, size: f64, far: Option<[f64; 3]>) -> String {
    #[allow(clippy::cast_precision_loss)]
    let at = |i: usize, j: usize| {
        let (x, y) = (size * i as f64 / n as f64, size * j as f64 / n as f64);
        [x, y, 2.0 * (x * 0.13).sin() * (y * 0.11).cos()]
    };
    let mut s = String::from("solid grid\n");
    let mut first = true;
    for i in 0..n {
        for j in 0..n {
            for tri in [[at(i, j), at(i + 1, j), at(i + 1, j + 1)], [at(i, j), at(i + 1, j + 1), at(i, j + 1)]] {
                s.push_str("facet normal 0 0 1\nouter loop\n");
                for (k, p) in tri.iter().enumerate() {
                    let p = if first && k == 0 { far.unwrap_or(*p) } else { *p };
                    s.push_str(&format!("vertex {} {} {}\n", p[0], p[1], p[2]));
                }
                first = false;
                s.push_str("endloop\nendfacet\n");
            }
        }
    }
    s.push_str("endsolid grid\n");
    s
}

#[test]
fn absurd_job_values_are_refused_before_the_work() {
    let dir = scratch("jobs");
    std::fs::write(dir.join("grid.stl"), grid_stl(24, 120.0, None)).unwrap();
    let part = "[part]\nbuiltin = \"choi\"\n\n";
    let ball = "[cutter]\nshape = \"ball\"\ndiameter = 10\n\n";
    let cases = [
        (
            format!(
                "{part}[cutter]\nshape = \"bull\"\ndiameter = 1e308\ncorner_radius = 1\nflute_length = 30\n\n\
                 [finishing]\nscallop_height = 0.05\n"
            ),
            vec!["cutter", "outside the range of real cutters"],
        ),
        (
            format!("{part}[cutter]\nshape = \"ball\"\ndiameter = 1e12\n\n[finishing]\nscallop_height = 0.05\n"),
            vec!["cutter", "outside the range of real cutters"],
        ),
        (
            format!("{part}[cutter]\nshape = \"ball\"\ndiameter = 1e6\n\n[finishing]\nscallop_height = 0.05\n"),
            vec!["cutter", "outside the range of real cutters"],
        ),
        (
            format!("{part}{ball}[finishing]\nscallop_height = 0.05\nmax_step = 1e-6\n"),
            vec!["drop-cutter queries", "budget", "finishing.max_step"],
        ),
        (
            format!("{part}{ball}[finishing]\nscallop_height = 0.05\n\n[verify]\nresolution = 0.0085\n"),
            vec!["z-map", "budget", "verify.resolution"],
        ),
        (
            "[part]\nfile = \"grid.stl\"\nunits = \"mm\"\n\n[cutter]\nshape = \"ball\"\ndiameter = 10\nflute_length = 40\n\n\
             [finishing]\nscallop_height = 0.2\ndirection = 30\nmax_step = 2.0\n\n[tolerances]\npath = 1e-12\ngouge = 0.0\n\n\
             [verify]\nresolution = 0.5\n"
                .to_string(),
            vec!["tolerances.path", "1e-12"],
        ),
    ];
    for (k, (job, expect)) in cases.iter().enumerate() {
        let name = format!("j{k}.toml");
        std::fs::write(dir.join(&name), job).unwrap();
        let mut expect: Vec<&str> = expect.clone();
        expect.push(&name);
        refused(&dir, &["run", &name, "-o", "out"], &expect);
        assert!(!dir.join("out").exists(), "{name}: a rejected job leaves no output");
    }
}

#[test]
fn mesh_outliers_and_instancing() {
    let dir = scratch("mesh");
    for far in [1e10, 1e12] {
        std::fs::write(dir.join("o.stl"), grid_stl(8, 150.0, Some([far, 0.0, 0.0]))).unwrap();
        refused(&dir, &["inspect", "o.stl"], &["o.stl", "triangle 0, vertex 0", "outlier", &format!("{far:e}")]);
    }
    // Nine levels of four copies of a 36-triangle mesh: 9.4 million triangles from a few kB.
    std::fs::write(dir.join("i.3mf"), scallop_fuzz::threemf_instancing(9, 4)).unwrap();
    refused(&dir, &["inspect", "i.3mf"], &["i.3mf", "9437184 triangles", "instancing"]);
    // A truncated 3MF: the zip error in words, no internal type names.
    let whole = scallop_fuzz::threemf_instancing(1, 2);
    for cut in [whole.len() / 2, whole.len() - 10] {
        std::fs::write(dir.join("t.3mf"), &whole[..cut]).unwrap();
        let e = refused(&dir, &["inspect", "t.3mf"], &["t.3mf", "zip"]);
        assert!(!e.contains("::"), "{e}");
    }
}

#[test]
fn grids_over_the_budget() {
    let dir = scratch("grids");
    refused(&dir, &["analyze", "choi", "--cells", "1000000"], &["1000000 x 1000000", "budget"]);
    std::fs::write(dir.join("g.stl"), grid_stl(2, 10.0, None)).unwrap();
    let args = [
        "drop",
        "--mesh",
        "g.stl",
        "--cutter",
        "ball",
        "--diameter",
        "6",
        "--x",
        "0:70000:1",
        "--y",
        "0:7000:1",
        "-o",
        "d.csv",
    ];
    refused(&dir, &args, &["--x 0:70000:1", "budget"]);
    assert!(!dir.join("d.csv").exists());
}

#[test]
fn messages_name_the_line_and_byte() {
    let dir = scratch("places");
    std::fs::write(dir.join("bad.csv"), b"kind,x,y,z\nfeed,1,\xff,3\n").unwrap();
    refused(
        &dir,
        &["post", "bad.csv", "--machine", "ucp710", "--dialect", "siemens840d", "-o", "x.nc"],
        &["bad.csv", "line 2, byte 18"],
    );
    let mut machine = UCP710.as_bytes()[..300].to_vec();
    machine.extend_from_slice(b"\xfe\n");
    std::fs::write(dir.join("m.toml"), &machine).unwrap();
    let line = format!("line {}", 1 + machine[..300].iter().filter(|&&b| b == b'\n').count());
    std::fs::write(dir.join("cl.csv"), CL).unwrap();
    refused(
        &dir,
        &["post", "cl.csv", "--machine", "m.toml", "--dialect", "siemens840d", "-o", "x.nc"],
        &["m.toml", &line, "byte 300"],
    );
    std::fs::write(dir.join("h.csv"), "# exported by hand\n\n# columns\nkind,x,y\nfeed,1,2\n").unwrap();
    refused(
        &dir,
        &["post", "h.csv", "--machine", "ucp710", "--dialect", "siemens840d", "-o", "x.nc"],
        &["h.csv", "line 4", "no `z` column"],
    );
}
