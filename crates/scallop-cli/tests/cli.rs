//! Smoke tests of the `scallop` binary: outputs, exit codes, bad input.

use std::path::{Path, PathBuf};

mod common;

use common::{pyramid_stl, rejected, run_job, run_json, scallop, scratch};

#[test]
fn demo_writes_a_program() {
    let dir = scratch("demo");
    let out = scallop().args(["demo", "-o"]).arg(&dir).output().expect("run");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let nc = std::fs::read_to_string(dir.join("program.nc")).expect("program.nc");
    assert!(nc.lines().filter(|l| l.starts_with("G1")).count() > 1000);
    assert!(String::from_utf8_lossy(&out.stdout).contains("passes"));
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).expect("report")).expect("json");
    // Every figure of the plan, each a number (a missing or null one fails to read).
    let plan: scallop_strategy::Report = serde_json::from_value(report["plan"].clone()).expect("report.json's plan");
    assert!(plan.max_scallop_mm <= 0.01);
    let csv = std::fs::read_to_string(dir.join("toolpath.csv")).expect("toolpath.csv");
    assert!(csv.starts_with("kind,x,y,z\n"));
    let html = std::fs::read_to_string(dir.join("report.html")).expect("report.html");
    assert!(html.starts_with("<!DOCTYPE html>") && html.contains("id=\"scene-data\""));
    let glb = std::fs::read(dir.join("scene.glb")).expect("scene.glb");
    assert_eq!(&glb[..4], b"glTF");
    assert_eq!(u32::from_le_bytes(glb[8..12].try_into().expect("4 bytes")) as usize, glb.len());
}

#[test]
fn render_writes_the_same_png_twice_and_rejects_a_bad_size() {
    let dir = scratch("render");
    std::fs::write(dir.join("p.stl"), pyramid_stl()).expect("write");
    std::fs::write(dir.join("t.csv"), "kind,x,y,z\nrapid,0,0,10\nplunge,0,0,1\nfeed,10,0,1\nlink,10,2,1\nfeed,0,2,1\n")
        .expect("write");
    let render = |name: &str| {
        let out = scallop()
            .current_dir(&dir)
            .args(["render", "p.stl", "--toolpath", "t.csv", "--size", "160x120", "-o", name])
            .output()
            .expect("run");
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        std::fs::read(dir.join(name)).expect("png")
    };
    let a = render("a.png");
    assert_eq!(&a[..8], b"\x89PNG\r\n\x1a\n");
    assert_eq!(a, render("b.png"));
    assert_rejected(&["render", "p.stl", "--size", "0x10", "-o", "c.png"], &dir, "--size");
    assert!(!dir.join("c.png").exists());
    std::fs::write(dir.join("bad.csv"), "kind,x,y,z\nwobble,0,0,0\n").expect("write");
    assert_rejected(&["render", "p.stl", "--toolpath", "bad.csv", "-o", "d.png"], &dir, "bad.csv: line 2");
    assert!(!dir.join("d.png").exists());
}

#[test]
fn drop_writes_the_grid_x_fastest_and_is_thread_independent() {
    let dir = scratch("drop");
    std::fs::write(dir.join("p.stl"), pyramid_stl()).expect("write");
    let run = |threads: &str, name: &str| {
        let out = scallop()
            .current_dir(&dir)
            .args(["drop", "--mesh", "p.stl", "--cutter", "bull", "--diameter", "2", "--corner-radius", "0.5"])
            .args(["--x=-1:11:0.5", "--y=0:10:1", "--floor=-1", "--threads", threads, "-o", name, "--json"])
            .output()
            .expect("run");
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let report: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
        assert_eq!(report["points"], 25 * 11);
        std::fs::read_to_string(dir.join(name)).expect("csv")
    };
    let one = run("1", "a.csv");
    let two = run("2", "b.csv");
    assert_eq!(one, two);
    let rows: Vec<&str> = one.lines().collect();
    assert_eq!(rows[0], "x,y,z");
    assert_eq!(rows.len(), 1 + 25 * 11);
    assert!(rows[1].starts_with("-1,0,"), "{}", rows[1]);
    assert!(rows[2].starts_with("-0.5,0,"), "{}", rows[2]);
    // At the apex the bull-nose's flat bottom rests on the apex: z = 5.
    let apex = rows.iter().find(|r| r.starts_with("5,5,")).expect("apex row");
    assert_eq!(*apex, "5,5,5");
}

fn assert_rejected(args: &[&str], dir: &PathBuf, needle: &str) {
    let err = rejected(&scallop().current_dir(dir).args(args).output().expect("run"));
    assert!(err.contains(needle), "{args:?}: '{err}' lacks '{needle}'");
}

#[test]
fn bad_input_is_rejected_with_the_place_and_no_output() {
    let dir = scratch("bad");
    let stl = pyramid_stl();
    std::fs::write(dir.join("short.stl"), &stl[..stl.len() - 7]).expect("write");
    std::fs::write(dir.join("nan.stl"), b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex nan 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid x\n").expect("write");
    std::fs::write(dir.join("ok.stl"), &stl).expect("write");
    std::fs::write(dir.join("knots.toml"), "units = \"mm\"\n[[patch]]\nname = \"p\"\nkind = \"nurbs\"\ndegree = [1, 1]\ncontrol = [[[0,0,0],[0,1,0]],[[1,0,0],[1,1,0]]]\nknots_u = [0, 1, 0, 1]\nknots_v = [0, 0, 1, 1]\n").expect("write");
    // A drop command on `part` with a ball D1 over a small grid, with `change` replacing defaults.
    let drop_cmd = |part: &[&'static str], change: &[(&'static str, &'static str)]| -> Vec<&'static str> {
        let mut opts = vec![("--cutter", "ball"), ("--diameter", "1"), ("--x", "0:1:0.5"), ("--y", "0:1:0.5")];
        for (key, value) in change {
            match opts.iter_mut().find(|(k, _)| k == key) {
                Some(slot) => slot.1 = value,
                None => opts.push((key, value)),
            }
        }
        let mut v = vec!["drop"];
        v.extend_from_slice(part);
        v.extend(opts.iter().flat_map(|(k, val)| [*k, *val]));
        v.extend_from_slice(&["-o", "out.csv"]);
        v
    };
    let ok = ["--mesh", "ok.stl"];
    assert_rejected(&drop_cmd(&["--mesh", "short.stl"], &[]), &dir, "short.stl");
    assert_rejected(&drop_cmd(&["--mesh", "nan.stl"], &[]), &dir, "line 5");
    assert_rejected(&drop_cmd(&["--mesh", "missing.stl"], &[]), &dir, "missing.stl");
    assert_rejected(&drop_cmd(&["--mesh", "notes.txt"], &[]), &dir, "unknown part format");
    assert_rejected(&drop_cmd(&["--surface", "knots.toml"], &[]), &dir, "knots.toml");
    assert_rejected(&drop_cmd(&ok, &[("--cutter", "bull")]), &dir, "--corner-radius");
    assert_rejected(&drop_cmd(&ok, &[("--diameter", "-1")]), &dir, "--diameter");
    assert_rejected(&drop_cmd(&ok, &[("--x", "0:1:0")]), &dir, "--x");
    assert_rejected(&drop_cmd(&ok, &[("--x", "0:1e12:1e-6")]), &dir, "larger STEP");
    assert_rejected(&drop_cmd(&ok, &[("--cutter", "cone"), ("--angle", "180")]), &dir, "--angle");
    assert_rejected(&drop_cmd(&ok, &[("--threads", "0")]), &dir, "--threads");
    assert!(!dir.join("out.csv").exists(), "a rejected job must not leave an output file");
    assert!(
        std::fs::read_dir(&dir).expect("dir").all(|e| !e
            .expect("entry")
            .file_name()
            .to_string_lossy()
            .contains(".tmp-"))
    );
}

#[test]
fn inspect_reports_mesh_diagnostics() {
    let dir = scratch("inspect");
    std::fs::write(dir.join("p.stl"), pyramid_stl()).expect("write");
    let out = scallop().current_dir(&dir).args(["inspect", "p.stl", "--json"]).output().expect("run");
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    assert_eq!(v["triangles"], 4);
    assert_eq!(v["vertices"], 5);
    assert_eq!(v["boundary_edges"], 4);
    let inches =
        scallop().current_dir(&dir).args(["inspect", "p.stl", "--units", "in", "--json"]).output().expect("run");
    let v: serde_json::Value = serde_json::from_slice(&inches.stdout).expect("json");
    assert_eq!(v["bounds_max"][0], 254.0);
}

#[test]
fn analyze_recommends_the_spec_tool_for_choi_and_rubio() {
    let dir = scratch("analyze");
    for (part, expected) in [("choi", "toroidal_along_slope"), ("rubio", "ball_along_principal")] {
        let out = scallop()
            .current_dir(&dir)
            .args(["analyze", part, "--json", "--plot", &format!("{part}.svg")])
            .output()
            .expect("run");
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
        assert_eq!(v["recommendation"], expected, "{part}");
        let svg = std::fs::read_to_string(dir.join(format!("{part}.svg"))).expect("svg");
        assert!(svg.starts_with("<svg") || svg.starts_with("<?xml"), "{part}: not an SVG");
    }
    let png = scallop().current_dir(&dir).args(["analyze", "rubio", "--plot", "rubio.png"]).output().expect("run");
    assert!(png.status.success());
    assert!(std::fs::read(dir.join("rubio.png")).expect("png").starts_with(b"\x89PNG"));
    let bad = scallop().current_dir(&dir).args(["analyze", "choi", "--scallop", "-1"]).output().expect("run");
    assert_eq!(bad.status.code(), Some(1));
}

#[test]
fn simulate_passes_the_demo_and_catches_a_lowered_copy() {
    let dir = scratch("simulate");
    let out = scallop().args(["demo", "--raster", "-o"]).arg(&dir).output().expect("run");
    assert!(out.status.success());
    let nc = std::fs::read_to_string(dir.join("demo.nc")).expect("demo.nc");
    // The same program 0.05 mm lower on every feed move.
    let lowered: String = nc
        .lines()
        .map(|l| {
            if !l.starts_with("G1") {
                return format!("{l}\n");
            }
            let words: Vec<String> = l
                .split(' ')
                .map(|w| match w.strip_prefix('Z') {
                    Some(z) => format!("Z{:.3}", z.parse::<f64>().expect("z") - 0.05),
                    None => w.to_string(),
                })
                .collect();
            format!("{}\n", words.join(" "))
        })
        .collect();
    std::fs::write(dir.join("low.nc"), lowered).expect("write");
    let sim = |program: &str, out: &str| {
        scallop()
            .current_dir(&dir)
            .args(["simulate", "--part", "choi", "--program", program, "--cutter", "ball", "--diameter", "6"])
            .args(["--flute-length", "30", "--gouge-tolerance", "0.003", "-o", out, "--json"])
            .output()
            .expect("run")
    };
    let good = sim("demo.nc", "good");
    assert!(good.status.success(), "{}", String::from_utf8_lossy(&good.stderr));
    let v: serde_json::Value = serde_json::from_slice(&good.stdout).expect("json");
    assert_eq!(v["verdict"][0], "ok");
    assert!(v["max_scallop_mm"].as_f64().expect("number") < 0.03);
    assert!(std::fs::read(dir.join("good/deviation.png")).expect("png").starts_with(b"\x89PNG"));
    let bad = sim("low.nc", "bad");
    assert!(rejected(&bad).contains("gouge"));
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("bad/sim.json")).expect("sim.json")).expect("json");
    let verdict = v["verdict"][0].as_str().expect("text");
    assert!(verdict.contains("gouge"), "{verdict}");
    // The fault names the G-code line of the move, and that line is a cutting move.
    let at = verdict.find("(G-code line ").expect("a G-code line") + "(G-code line ".len();
    let line: usize = verdict[at..].split(')').next().and_then(|n| n.parse().ok()).expect("a line number");
    let text = std::fs::read_to_string(dir.join("low.nc")).expect("low.nc");
    assert!(text.lines().nth(line - 1).is_some_and(|l| l.starts_with("G1")), "line {line}");
    assert!(v["min_deviation_mm"].as_f64().expect("number") < -0.04);
}

#[test]
fn run_plans_a_job_file_and_rejects_bad_keys() {
    let dir = scratch("run");
    let job = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/jobs/choi.toml");
    let v = run_json(Path::new(job), &dir.join("out"), &[]);
    assert!(v["plan"]["max_scallop_mm"].as_f64().expect("number") <= 0.01);
    assert!(dir.join("out/program.nc").exists());
    std::fs::write(dir.join("bad.toml"), "[part]\nbuiltin = \"choi\"\n[cutter]\nshape = \"ball\"\ndiameter = 6\n[finishing]\nscallop_height = 0.01\nscallop = 2\n").expect("write");
    let err = rejected(&run_job(&dir.join("bad.toml"), &dir.join("bad"), &[]));
    assert!(err.contains("bad.toml") && err.contains("scallop"), "{err}");
    assert!(!dir.join("bad").exists(), "a rejected job writes nothing");
}

#[test]
fn run_with_the_network_planner_writes_a_verified_program() {
    let dir = scratch("run-network");
    let job = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/jobs/choi-network.toml");
    let v = run_json(Path::new(job), &dir.join("out"), &[]);
    let bound = v["sim_resolution_bound_mm"].as_f64().expect("number");
    let scallop = v["plan"]["max_scallop_mm"].as_f64().expect("number");
    assert!(scallop > 0.0 && scallop <= 0.01 + bound, "{scallop} {bound}");
    assert!(v["plan"]["passes"].as_u64().expect("passes") > 50);
    let program = std::fs::read_to_string(dir.join("out/program.nc")).expect("program");
    assert!(program.lines().filter(|l| l.starts_with("G1")).count() > 1000);
}

#[test]
fn optimize_writes_the_study_and_rejects_bad_settings() {
    let dir = scratch("optimize");
    let job = "[part]\nbuiltin = \"rubio\"\n[cutter]\nshape = \"bull\"\ndiameter = 10\ncorner_radius = 2\nflute_length = 50\n\
               [finishing]\nscallop_height = 0.01\n[optimize]\nformulation = \"3axis\"\nk_min = 2\nk_max = 3\n\
               budget = 8\ngrid = [20, 20]\nsurrogate_grid = [10, 10]\nstep = 1.5\n";
    std::fs::write(dir.join("small.toml"), job).expect("write");
    let out =
        scallop().current_dir(&dir).args(["optimize", "small.toml", "-o", "out", "--json"]).output().expect("run");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    let results = v["study"]["results"].as_array().expect("results");
    assert_eq!(results.len(), 2);
    for r in results {
        assert!(r["f_best"].as_f64().expect("f_best") <= r["f0"].as_f64().expect("f0"));
        assert!(r["evaluations"].as_u64().expect("evaluations") <= 8);
        // Every black-box evaluation timed: count, and ordered statistics.
        let t = &r["black_box_times"];
        assert_eq!(t["count"].as_u64(), r["evaluations"].as_u64(), "{t}");
        let ms = |k: &str| t[k].as_f64().expect("milliseconds");
        assert!(ms("mean_ms") > 0.0 && ms("median_ms") <= ms("p95_ms") && ms("p95_ms") <= ms("max_ms"), "{t}");
        assert!(ms("mean_ms") <= ms("max_ms"), "{t}");
    }
    for file in ["study.json", "report.json", "convergence.svg", "zones.svg", "report.html", "toolpath.csv"] {
        assert!(dir.join("out").join(file).exists(), "{file}");
    }
    // The best plan's drop-cutter program: it parses, and report.json holds its proof.
    let text = std::fs::read_to_string(dir.join("out/program.nc")).expect("program.nc");
    let path = scallop_io::gcode::read_gcode(&text, &scallop_io::gcode::GcodeOptions::default()).expect("parses");
    assert!(path.moves().len() > 100, "{}", path.moves().len());
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("out/report.json")).expect("report.json")).expect("json");
    let program = &report["program"];
    let simulated = program["sim_max_scallop_mm"].as_f64().expect("simulated scallop");
    let limit = program["sim_scallop_limit_mm"].as_f64().expect("limit");
    assert!(simulated > 0.0 && simulated <= limit && limit < 0.0115, "{program}");
    assert!(program["plan"]["max_scallop_mm"].as_f64().expect("planner scallop") <= 0.01 * (1.0 + 1e-6));
    assert!(program["predicted_time_s"].as_f64().expect("network time") > 0.0);
    assert!(program["plan"]["total_time_s"].as_f64().expect("program time") > 0.0);
    let zones = program["zones"].as_array().expect("zones");
    let written = &report["written"];
    assert!(zones.len() == written["zones_planned"].as_u64().expect("zones planned") as usize, "{written}");
    assert!(zones.iter().any(|z| z["passes"].as_u64() > Some(0)));
    if let Some(k) = written["k"].as_u64() {
        let planned = report["result"]["plan"]["zones"].as_array().expect("the study's zones");
        assert_eq!((zones.len(), report["k"].as_u64()), (planned.len(), Some(k)));
    }
    assert!(report["gcode"].as_str().expect("gcode").starts_with("program.nc"));
    assert_eq!(program["indexed"].as_bool(), Some(false));
    // The final choice (issue 20): the written program is the fastest proven
    // candidate, and a single zone is among them.
    let programs = v["programs"].as_array().expect("programs");
    let time = |c: &serde_json::Value| c["program_time_s"].as_f64();
    let fastest = programs.iter().filter_map(time).fold(f64::INFINITY, f64::min);
    let chosen: Vec<_> = programs.iter().filter(|c| c["written"].as_bool() == Some(true)).collect();
    assert_eq!(chosen.len(), 1, "{programs:?}");
    assert_eq!(time(chosen[0]).map(f64::to_bits), Some(fastest.to_bits()));
    assert_eq!(report["program_time_s"].as_f64().map(f64::to_bits), Some(fastest.to_bits()));
    assert!(programs.iter().any(|c| c["k"].is_null() && time(c).is_some()), "{programs:?}");
    assert!(fastest <= report["single_zone_time_s"].as_f64().expect("single zone"));

    // 3+2: indexed setups, each zone proven in its own frame.
    let tilted = job
        .replace("formulation = \"3axis\"", "formulation = \"3+2\"")
        .replace("flute_length = 50", "flute_length = 90");
    std::fs::write(dir.join("tilted.toml"), &tilted).expect("write");
    let out = scallop().current_dir(&dir).args(["optimize", "tilted.toml", "-o", "out32"]).output().expect("run");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("out32/report.json")).expect("report.json")).expect("json");
    let program = &report["program"];
    let limit = program["sim_scallop_limit_mm"].as_f64().expect("limit");
    // A tilted zone plan is written as indexed setups; when a single zone is
    // faster (the final choice), the program is 3-axis.
    if program["indexed"].as_bool() == Some(true) {
        for z in program["zones"].as_array().expect("zones").iter().filter(|z| z["passes"].as_u64() > Some(0)) {
            let own = z["sim_zone_scallop_mm"].as_f64().expect("each zone proven in its frame");
            assert!(own > 0.0 && own <= limit, "{z}");
        }
        let text = std::fs::read_to_string(dir.join("out32/program.nc")).expect("program.nc");
        assert!(text.lines().any(|l| l.contains(" A")), "rotary words");
        let csv = std::fs::read_to_string(dir.join("out32/toolpath.csv")).expect("toolpath.csv");
        let rows = scallop_io::cl::read_cl_csv(&csv).expect("a cutter-location file with tool axes");
        assert!(rows.len() > 100 && csv.starts_with("kind,x,y,z,i,j,k"));
    } else {
        assert!(report["written"]["k"].is_null(), "{report}");
        let simulated = program["sim_max_scallop_mm"].as_f64().expect("simulated scallop");
        assert!(simulated > 0.0 && simulated <= limit, "{program}");
    }
    for (bad, key) in [
        (job.replace("k_max = 3", "k_max = 1").replace("k_min = 2", "k_min = 1"), "optimize.k_max"),
        (job.replace("budget = 8", "budget = 0"), "optimize.budget"),
        (format!("{job}omega = [1, 2, 1, 1]\n"), "optimize.omega"),
        (job.replace("[optimize]\nformulation = \"3axis\"\nk_min = 2\nk_max = 3\nbudget = 8\ngrid = [20, 20]\nsurrogate_grid = [10, 10]\nstep = 1.5\n", ""), "[optimize]"),
    ] {
        std::fs::write(dir.join("bad.toml"), &bad).expect("write");
        assert_rejected(&["optimize", "bad.toml", "-o", "bad"], &dir, key);
        assert!(!dir.join("bad").exists(), "a rejected job writes nothing");
    }
}

#[test]
fn post_writes_a_proven_program_with_a_time_report() {
    let dir = scratch("post");
    // A 5-axis circle with a swinging tool axis, in the CL format with axes and feeds.
    let mut cl = String::from("kind,x,y,z,i,j,k,feed\nrapid,20,0,80,0,0,1,\n");
    for i in 0..=360 {
        let t = f64::from(i).to_radians();
        let a = 0.3 * (2.0 * t).sin();
        cl.push_str(&format!("feed,{},{},40,{},0,{},1500\n", 20.0 * t.cos(), 20.0 * t.sin(), a.sin(), a.cos()));
    }
    std::fs::write(dir.join("circle.csv"), cl).expect("write");
    let out = scallop()
        .args(["post", "--machine", "ucp710", "--dialect", "linuxcnc", "--json", "-o"])
        .arg(dir.join("circle.nc"))
        .arg(dir.join("circle.csv"))
        .output()
        .expect("run");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    let total = report["total_time_s"].as_f64().expect("time");
    let floor = report["feed_floor_s"].as_f64().expect("floor");
    // 125.7 mm of circle at 1500 mm/min is 5.03 s: the machine can only be slower.
    assert!(floor > 5.0 && total >= floor, "{report}");
    assert!(report["replay_tip_deviation_mm"].as_f64().expect("dev") <= 0.01);
    let axes = report["axes"].as_array().expect("axes");
    assert_eq!(axes.len(), 5);
    assert!(axes.iter().all(|a| a["time_lost_s"].as_f64().expect("lost") >= 0.0));
    let nc = std::fs::read_to_string(dir.join("circle.nc")).expect("program");
    assert!(nc.contains("G93") && nc.lines().filter(|l| l.contains('A')).count() > 100);
    let written: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("post.json")).expect("post.json")).expect("json");
    assert_eq!(written["blocks"], report["blocks"]);

    // A bad row names the line and the column, exit 1, nothing written.
    std::fs::write(dir.join("bad.csv"), "kind,x,y,z\nrapid,0,0,10\nfeed,1,oops,0\n").expect("write");
    let out = scallop()
        .args(["post", "--machine", "ucp710", "--dialect", "fanuc", "-o"])
        .arg(dir.join("bad.nc"))
        .arg(dir.join("bad.csv"))
        .output()
        .expect("run");
    let err = rejected(&out);
    assert!(err.contains("line 3, column `y`"), "{err}");
    assert!(!dir.join("bad.nc").exists());
    // An unknown machine is rejected with the fix.
    assert_rejected(&["post", "--machine", "nosuch", "--dialect", "fanuc", "circle.csv"], &dir, "nosuch");
}

#[test]
fn bad_jobs_name_the_key_and_the_fix_and_write_nothing() {
    let dir = scratch("badjobs");
    let tiny = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 0.05 0 0\nvertex 0 0.05 0\nendloop\nendfacet\nendsolid t\n";
    std::fs::write(dir.join("tiny.stl"), tiny).expect("write");
    let base = "[part]\nbuiltin = \"choi\"\n[cutter]\nshape = \"ball\"\ndiameter = 6\nflute_length = 60\n[finishing]\nscallop_height = 0.01\n";
    let cases: [(&str, String, &[&str]); 11] = [
        ("unknown key", format!("{base}colour = \"red\"\n"), &["colour"]),
        ("negative size", base.replace("diameter = 6", "diameter = -6"), &["cutter.diameter", "> 0"]),
        (
            "sh over the radius",
            base.replace("scallop_height = 0.01", "scallop_height = 4"),
            &["finishing.scallop_height", "radius"],
        ),
        (
            "unreachable",
            base.replace("\"ball\"", "\"flat\"")
                .replace("scallop_height = 0.01", "scallop_height = 0.0001\ndirection = 90"),
            &["cannot reach", "finishing.scallop_height", "ball or bull-nose"],
        ),
        (
            "empty region",
            base.replace("builtin = \"choi\"", "file = \"tiny.stl\"")
                .replace("scallop_height = 0.01", "scallop_height = 0.01\ndirection = 0"),
            &["region to machine is empty", "finishing.max_step"],
        ),
        ("short flutes", base.replace("flute_length = 60", "flute_length = 8"), &["shank", "cutter.flute_length"]),
        (
            "flutes under the profile",
            base.replace("flute_length = 60", "flute_length = 2"),
            &["flute_length", "profile"],
        ),
        ("unknown dialect", format!("{base}[output]\ndialect = \"haas\"\n"), &["output.dialect", "linuxcnc"]),
        ("plain-language 3-axis", format!("{base}[output]\ndialect = \"heidenhain\"\n"), &["ISO dialect", "[output]"]),
        (
            "arcs in 3+2",
            format!(
                "{base}[setup]\nrotation_deg = [10, 0, 0]\nmachine = \"linuxcnc-xyzac-trt\"\n[output]\narc_fitting = true\n"
            ),
            &["output.arc_fitting", "false"],
        ),
        (
            "unknown machine",
            format!("{base}[setup]\nrotation_deg = [10, 0, 0]\nmachine = \"mill\"\n"),
            &["setup.machine", "mill"],
        ),
    ];
    for (what, text, needles) in cases {
        std::fs::write(dir.join("job.toml"), &text).expect("write");
        let err = rejected(&run_job(&dir.join("job.toml"), &dir.join("out"), &[]));
        for n in needles {
            assert!(err.contains(n), "{what}: '{err}' lacks '{n}'");
        }
        assert!(!dir.join("out").exists(), "{what}: a rejected job writes nothing");
    }
}

/// A 20 x 20 plane at z = 0 as an ASCII STL (two triangles: a height field).
fn plane_stl() -> String {
    let tri = |a: [f64; 3], b: [f64; 3], c: [f64; 3]| {
        format!(
            "facet normal 0 0 1\nouter loop\nvertex {} {} {}\nvertex {} {} {}\nvertex {} {} {}\nendloop\nendfacet\n",
            a[0], a[1], a[2], b[0], b[1], b[2], c[0], c[1], c[2]
        )
    };
    format!(
        "solid plane\n{}{}endsolid plane\n",
        tri([0.0, 0.0, 0.0], [20.0, 0.0, 0.0], [20.0, 20.0, 0.0]),
        tri([0.0, 0.0, 0.0], [20.0, 20.0, 0.0], [0.0, 20.0, 0.0])
    )
}

/// A 3+2 raster of a ball tilted 20 degrees over the plane, its sphere
/// touching the plane, every `step` mm; `lower` mm lower on pass `lowered`.
fn tilted_raster_csv(step: f64, lowered: usize, lower: f64) -> String {
    let (r, tilt) = (2.0f64, 20f64.to_radians());
    let a = [0.0, -tilt.sin(), tilt.cos()];
    let mut csv = String::from("kind,x,y,z,i,j,k,feed\n");
    let mut row = |kind: &str, x: f64, y: f64, cz: f64| {
        let tip = [x - r * a[0], y - r * a[1], cz - r * a[2]];
        csv.push_str(&format!(
            "{kind},{:.6},{:.6},{:.6},{},{:.9},{:.9},1000\n",
            tip[0], tip[1], tip[2], a[0], a[1], a[2]
        ));
    };
    row("rapid", -3.0, -1.0, 10.0);
    let passes = (22.0 / step) as usize;
    for k in 0..passes {
        let y = -1.0 + step * k as f64;
        let cz = r - if k == lowered { lower } else { 0.0 };
        let (x0, x1) = if k % 2 == 0 { (-3.0, 23.0) } else { (23.0, -3.0) };
        row("plunge", x0, y, cz);
        row("feed", x1, y, cz);
    }
    csv
}

#[test]
fn simulate_runs_a_3_plus_2_toolpath_on_tri_dexels() {
    let dir = scratch("simulate-dexel");
    std::fs::write(dir.join("plane.stl"), plane_stl()).expect("write");
    std::fs::write(dir.join("good.csv"), tilted_raster_csv(1.0, usize::MAX, 0.0)).expect("write");
    std::fs::write(dir.join("low.csv"), tilted_raster_csv(1.0, 9, 0.05)).expect("write");
    let sim = |toolpath: &str, out: &str| {
        scallop()
            .current_dir(&dir)
            .args(["simulate", "--part", "plane.stl", "--toolpath", toolpath, "--cutter", "ball", "--diameter", "4"])
            .args(["--flute-length", "10", "--stock", "0,0,-2,20,20,1", "--resolution", "0.25"])
            .args(["--gouge-tolerance", "0.005", "-o", out, "--json"])
            .output()
            .expect("run")
    };
    let good = sim("good.csv", "good");
    assert!(good.status.success(), "{}", String::from_utf8_lossy(&good.stderr));
    let v: serde_json::Value = serde_json::from_slice(&good.stdout).expect("json");
    assert_eq!(v["stock_model"], "tri-dexel");
    assert_eq!(v["verdict"][0], "ok");
    // Scallop of a ball R = 2 between passes 1 mm apart, within the grid's
    // bound at the cusp (slope 0.26 times half a cell diagonal).
    let theory = 2.0 - (4.0f64 - 0.25).sqrt();
    let s = v["max_scallop_mm"].as_f64().expect("number");
    assert!(s <= theory + 1e-6 && s >= theory - 0.26 * 0.18, "{s} vs {theory}");
    for key in ["rays", "removed_volume_mm3", "remaining_volume_mm3", "max_thickness_mm", "sweeps"] {
        assert!(!v[key].is_null(), "{key}");
    }
    assert!(std::fs::read(dir.join("good/deviation.png")).expect("png").starts_with(b"\x89PNG"));
    let bad = sim("low.csv", "bad");
    let err = rejected(&bad);
    // Pass 9's feed is move 1 + 2 * 9 + 1 = 20 (its plunge ends beyond the part, at x = 23).
    assert!(err.contains("gouge") && err.contains("cut by move 20 "), "{err}");
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("bad/sim.json")).expect("sim.json")).expect("json");
    assert_eq!(v["stock_model"], "tri-dexel");
    assert!(v["min_deviation_mm"].as_f64().expect("number") < -0.04);
    // A z-map cannot hold a tilted program.
    let zmap = ["simulate", "--part", "plane.stl", "--toolpath", "good.csv", "--cutter", "ball", "--diameter", "4"];
    assert_rejected(&[&zmap[..], &["--stock-model", "zmap", "-o", "z"]].concat(), &dir, "--stock-model dexel");
}

/// A job of two operations on a pyramid mesh: one program with two tool
/// changes, a report per operation, and the second operation meeting the
/// stock the first left; the written CL file reads back and is accepted by
/// `simulate --toolpath` (the same CL format in and out).
#[test]
fn run_machines_two_operations_on_one_stock() {
    let dir = scratch("two-operations");
    std::fs::write(dir.join("pyramid.stl"), pyramid_stl()).expect("write");
    let job = "[part]\nfile = \"pyramid.stl\"\n[stock]\ntop = 3\n\
        [[operation]]\nkind = \"finish\"\nname = \"coarse\"\n[operation.cutter]\nshape = \"ball\"\ndiameter = 6\n\
        [operation.finishing]\nscallop_height = 0.3\nstrategy = \"parallel\"\n\
        [[operation]]\nkind = \"finish\"\nname = \"fine\"\nspindle = 10000\n[operation.cutter]\nshape = \"ball\"\ndiameter = 4\n\
        [operation.finishing]\nscallop_height = 0.05\nstrategy = \"parallel\"\n[verify]\nresolution = 0.1\n";
    std::fs::write(dir.join("job.toml"), job).expect("write");
    let report = run_json(&dir.join("job.toml"), &dir.join("out"), &[]);
    let ops = report["operations"].as_array().expect("operations");
    assert_eq!(ops.len(), 2);
    let (a, b) = (&ops[0]["stock"], &ops[1]["stock"]);
    let left = a["volume_before_mm3"].as_f64().unwrap() - a["removed_mm3"].as_f64().unwrap();
    assert!((b["volume_before_mm3"].as_f64().unwrap() - left).abs() <= 1e-6 * left, "{report}");
    assert!(b["removed_mm3"].as_f64().unwrap() < a["removed_mm3"].as_f64().unwrap(), "{report}");
    // Each operation's planning time is measured, and the page shows one colour per operation.
    assert!(ops.iter().all(|o| o["plan"]["planning_time_s"].as_f64().unwrap() > 0.0), "{report}");
    let page = std::fs::read_to_string(dir.join("out/report.html")).expect("report.html");
    assert!(page.contains("Machining time per operation") && page.contains("2. fine"), "the job's page");
    assert!(dir.join("out/scene.glb").exists());
    // The estimate before planning (--plan-only) expects each operation's pass count within 10 %.
    let estimate = run_json(&dir.join("job.toml"), &dir.join("est"), &["--plan-only"]);
    assert!(!dir.join("est").exists(), "--plan-only writes nothing");
    for (op, e) in ops.iter().zip(estimate.as_array().expect("list")) {
        let (real, expected) = (op["plan"]["passes"].as_f64().unwrap(), e["estimate"]["passes"].as_f64().unwrap());
        assert!((expected - real).abs() <= 0.1 * real, "estimated {expected} passes, planned {real}");
    }
    let program = std::fs::read_to_string(dir.join("out/program.nc")).expect("program");
    let (t1, t2) = (program.find("T1 M6").expect("T1"), program.find("T2 M6").expect("T2"));
    assert!(t1 < t2 && program[t2..].contains("S10000 M3"), "{program}");
    let csv = std::fs::read_to_string(dir.join("out/toolpath.csv")).expect("toolpath.csv");
    let path = scallop_io::cl::read_cl(&csv, 1000.0).expect("the CL file reads back");
    assert_eq!(path.moves().len(), csv.lines().count() - 1);
    // Both operations' moves cut with the smaller ball from the part's box: the
    // same CL file accepted by the simulator (no gouge, no rapid into stock).
    let sim = scallop()
        .args(["simulate", "--toolpath"])
        .arg(dir.join("out/toolpath.csv"))
        .arg("--part")
        .arg(dir.join("pyramid.stl"))
        .args(["--cutter", "ball", "--diameter", "4", "-o"])
        .arg(dir.join("sim"))
        .output()
        .expect("simulate");
    assert!(sim.status.success(), "{}", String::from_utf8_lossy(&sim.stderr));
}

/// `--plan-only` on a roughing operation (a generated pyramid in a stock box)
/// expects the planner's levels exactly and its passes within 10 %; on a
/// rest operation after it (a smaller end mill on what the first left), the
/// planner's levels, and fewer passes than the same operation from the box.
#[test]
fn plan_only_estimates_the_levels_and_passes_of_roughing() {
    let dir = scratch("rough-estimate");
    std::fs::write(dir.join("pyramid.stl"), pyramid_stl()).expect("write");
    let head = "[part]\nfile = \"pyramid.stl\"\n[stock]\nmargin = 4\ntop = 2\n[verify]\nresolution = 0.1\n";
    let rough = "[[operation]]\nkind = \"rough\"\n[operation.cutter]\nshape = \"flat\"\ndiameter = 4\nflute_length = 20\n\
        [operation.roughing]\nstepdown = 1\nstepover = 0.3\nstock_to_leave = 0.3\n";
    let rest = "[[operation]]\nkind = \"rest\"\n[operation.cutter]\nshape = \"flat\"\ndiameter = 2\nflute_length = 20\n\
        [operation.roughing]\nstepdown = 0.5\nstepover = 0.3\nstock_to_leave = 0.3\n";
    let job = format!("{head}{rough}{rest}");
    std::fs::write(dir.join("job.toml"), job).expect("write");
    let run = |extra: &[&str]| run_json(&dir.join("job.toml"), &dir.join("out"), extra);
    let estimate = run(&["--plan-only"]);
    let report = run(&[]);
    for k in 0..2 {
        let (e, plan) = (&estimate[k]["estimate"], &report["operations"][k]["plan"]);
        assert_eq!(e["strategy"], "rough", "{estimate}");
        assert_eq!(e["levels"].as_u64(), plan["planes"].as_u64(), "levels: {estimate} {plan}");
    }
    let (e, plan) = (&estimate[0]["estimate"], &report["operations"][0]["plan"]);
    let (expected, real) = (e["passes"].as_f64().unwrap(), plan["passes"].as_f64().unwrap());
    assert!((expected - real).abs() <= 0.1 * real, "estimated {expected} passes, planned {real}");
    // The rest operation alone (from the whole box) has more to cut.
    let alone = format!("{head}{}", rest.replace("kind = \"rest\"", "kind = \"rough\""));
    std::fs::write(dir.join("job.toml"), alone).expect("write");
    let whole = run(&["--plan-only"]);
    let (after, from_box) = (&estimate[1]["estimate"]["passes"], &whole[0]["estimate"]["passes"]);
    assert!(after.as_u64() < from_box.as_u64(), "rest {after} vs from the box {from_box}: {whole}");
}

/// The words of a G-code line without its comments: `(letter, number)` pairs.
fn nc_words(line: &str) -> Vec<(char, f64)> {
    let mut text = String::new();
    let mut depth = 0;
    for c in line.chars() {
        match c {
            '(' => depth += 1,
            ')' => depth -= 1,
            _ if depth == 0 => text.push(c),
            _ => {}
        }
    }
    let mut words = Vec::new();
    let mut chars = text.trim().chars().peekable();
    while let Some(c) = chars.next() {
        if !c.is_ascii_alphabetic() {
            continue;
        }
        let mut number = String::new();
        while let Some(&d) = chars.peek() {
            if d.is_ascii_digit() || d == '.' || d == '-' {
                number.push(d);
                chars.next();
            } else {
                break;
            }
        }
        words.push((c.to_ascii_uppercase(), number.parse().expect("a number after a letter")));
    }
    words
}

/// A job of two operations whose tools come from a tool library (in another
/// folder, named relative to the job): the program of each dialect, parsed
/// back word by word, changes to each tool (`T.. M6`; grbl: a pause `M0`),
/// starts the spindle at `1000 Vc / (pi D)` (`S.. M3`) and feeds at
/// `f_z * teeth * n` (`F..`), stopping the spindle before the second change.
#[test]
fn run_takes_tools_and_cutting_data_from_the_library() {
    let dir = scratch("tool-library");
    std::fs::create_dir_all(dir.join("jobs")).expect("dir");
    std::fs::write(dir.join("jobs/pyramid.stl"), pyramid_stl()).expect("write");
    let library = "[[tool]]\nnumber = 3\nshape = \"ball\"\ndiameter = 6\nflutes = 2\nflute_length = 20\nvc = 150\nfz = 0.04\n\
        [[tool]]\nnumber = 12\nshape = \"ball\"\ndiameter = 4\nflutes = 3\nflute_length = 16\nspindle = 15000\nfz = 0.02\n";
    std::fs::write(dir.join("tools.toml"), library).expect("write");
    let n3 = 1000.0 * 150.0 / (std::f64::consts::PI * 6.0);
    let expected = [(3.0, n3, 0.04 * 2.0 * n3), (12.0, 15000.0, 0.02 * 3.0 * 15000.0)];
    for dialect in ["linuxcnc", "fanuc", "grbl"] {
        let job = format!(
            "tool_library = \"../tools.toml\"\n[part]\nfile = \"pyramid.stl\"\n[stock]\ntop = 3\n\
            [[operation]]\nkind = \"finish\"\ntool = 3\n[operation.finishing]\nscallop_height = 0.3\n\
            [[operation]]\nkind = \"finish\"\ntool = 12\n[operation.finishing]\nscallop_height = 0.05\n\
            [verify]\nresolution = 0.1\n[output]\ndialect = \"{dialect}\"\n"
        );
        std::fs::write(dir.join("jobs/job.toml"), &job).expect("write");
        let out = run_job(&dir.join("jobs/job.toml"), &dir.join(dialect), &[]);
        assert!(out.status.success(), "{dialect}: {}", String::from_utf8_lossy(&out.stderr));
        let program = std::fs::read_to_string(dir.join(dialect).join("program.nc")).expect("program");
        // Split the program at its tool changes and read each section's words.
        let lines: Vec<&str> = program.lines().collect();
        let changes: Vec<usize> = if dialect == "grbl" {
            let at: Vec<usize> = (0..lines.len()).filter(|&i| nc_words(lines[i]) == [('M', 0.0)]).collect();
            for (&i, (tool, ..)) in at.iter().zip(&expected) {
                assert!(lines[i - 1].contains(&format!("load tool {tool}")), "{dialect}: {}", lines[i - 1]);
            }
            at.iter().map(|i| i - 1).collect()
        } else {
            let at: Vec<usize> = (0..lines.len()).filter(|&i| nc_words(lines[i]).contains(&('M', 6.0))).collect();
            for (&i, (tool, ..)) in at.iter().zip(&expected) {
                assert!(nc_words(lines[i]).contains(&('T', *tool)), "{dialect}: {}", lines[i]);
            }
            at
        };
        assert_eq!(changes.len(), 2, "{dialect}: {program}");
        assert!(lines[changes[1] - 1].trim() == "M5", "{dialect}: the spindle stops before the second change");
        for (k, (_, n, f)) in expected.iter().enumerate() {
            let end = changes.get(k + 1).copied().unwrap_or(lines.len());
            let words: Vec<Vec<(char, f64)>> = lines[changes[k]..end].iter().map(|l| nc_words(l)).collect();
            let start = words.iter().find(|w| w.contains(&('M', 3.0))).expect("M3");
            let s = start.iter().find(|(c, _)| *c == 'S').expect("S word").1;
            assert!((s - n.round()).abs() < 0.5, "{dialect}: S{s}, expected {n}");
            let feeds: Vec<f64> = words.iter().flatten().filter(|(c, _)| *c == 'F').map(|w| w.1).collect();
            let resolution = if dialect == "grbl" { 1.0 } else { 0.1 }; // the dialects' feed decimals
            assert!(feeds.iter().any(|v| (v - f).abs() <= 0.5 * resolution + 1e-9), "{dialect}: {feeds:?} {f}");
        }
    }
    // An unknown tool number names the job file, the line and the fix.
    std::fs::write(
        dir.join("jobs/bad.toml"),
        "tool_library = \"../tools.toml\"\n[part]\nfile = \"pyramid.stl\"\n[[operation]]\nkind = \"finish\"\ntool = 7\n[operation.finishing]\nscallop_height = 0.3\n",
    )
    .expect("write");
    let err = rejected(&run_job(&dir.join("jobs/bad.toml"), &dir.join("bad"), &[]));
    assert!(err.contains("bad.toml: line 6: tool 7 is not in the tool library") && err.contains("[3, 12]"), "{err}");
    // A bad library names its own file and line.
    std::fs::write(dir.join("tools.toml"), library.replace("fz = 0.02", "fz = -0.02")).expect("write");
    let err = rejected(&run_job(&dir.join("jobs/job.toml"), &dir.join("bad"), &[]));
    assert!(err.contains("tools.toml: line 9: tool 12: `fz`"), "{err}");
}

/// Units out as in: a pyramid given in centimetres (0.5 cm high) is machined
/// as the 5 mm pyramid, the program written in inches (`G20`) replays in mm
/// within the words' resolution to the tool tips of `toolpath.csv`; and
/// `analyze` takes the job file (its part, cutter and scallop height).
#[test]
fn run_writes_inch_programs_and_reads_centimetres() {
    let dir = scratch("units");
    let cm: Vec<u8> = {
        // The pyramid STL with every coordinate divided by 10 (cm).
        let mm = pyramid_stl();
        let mut out = mm[..84].to_vec();
        for tri in mm[84..].chunks(50) {
            out.extend_from_slice(&tri[..12]);
            for c in tri[12..48].chunks(4) {
                let v = f32::from_le_bytes(c.try_into().expect("4 bytes")) / 10.0;
                out.extend_from_slice(&v.to_le_bytes());
            }
            out.extend_from_slice(&tri[48..50]);
        }
        out
    };
    std::fs::write(dir.join("pyramid.stl"), cm).expect("write");
    let job = "[part]\nfile = \"pyramid.stl\"\nunits = \"cm\"\n[cutter]\nshape = \"ball\"\ndiameter = 4\n\
        [finishing]\nscallop_height = 0.05\n[output]\nunits = \"in\"\nspindle = 10000\n";
    std::fs::write(dir.join("job.toml"), job).expect("write");
    let out = run_job(&dir.join("job.toml"), &dir.join("out"), &[]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let program = std::fs::read_to_string(dir.join("out/program.nc")).expect("program");
    assert!(program.lines().any(|l| l.split_whitespace().any(|w| w == "G20")), "{program}");
    let back = scallop_io::gcode::read_gcode(&program, &scallop_io::gcode::GcodeOptions::default()).expect("reads");
    let csv = std::fs::read_to_string(dir.join("out/toolpath.csv")).expect("csv");
    let path = scallop_io::cl::read_cl(&csv, 1000.0).expect("CL");
    assert_eq!(back.moves().len(), path.moves().len());
    let top = path.moves().iter().map(|m| m.to.z).fold(f64::NEG_INFINITY, f64::max);
    assert!(top > 5.0 && top < 20.0, "the part is 5 mm high: {top}");
    for (a, b) in back.moves().iter().zip(path.moves()) {
        assert!((a.to - b.to).abs().max() <= 0.5e-5 * 25.4 + 1e-9, "{:?} vs {:?}", a.to, b.to);
    }
    let analysis = scallop().args(["analyze", "--json"]).arg(dir.join("job.toml")).output().expect("analyze");
    assert!(analysis.status.success(), "{}", String::from_utf8_lossy(&analysis.stderr));
    let report: serde_json::Value = serde_json::from_slice(&analysis.stdout).expect("json");
    assert_eq!(report["scallop_height_mm"].as_f64(), Some(0.05), "{report}");
}
