//! Issue 22, "machines by file everywhere": a job with tools from the library, two
//! operations and a machine file writes the right T/M6/S/M3/F words for LinuxCNC, Fanuc
//! and grbl (read back from the program), an inch program replays to the mm program's
//! path, and travel, spindle and name errors name the fix.

use std::path::{Path, PathBuf};

use scallop_io::gcode::{GcodeOptions, read_gcode};
use scallop_io::tools::parse_tool_library;
use scallop_machine::Described;

mod common;

use common::{rejected, run_job, scratch};

fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(rel)
}

/// Two finishes of the Choi surface with library tools 6 (ball D8) and 5 (bull-nose
/// D10 r2), coarse and fast; `machine` is the job's machine key, `extra` more top-level keys and tables.
fn job(machine: &str, extra: &str) -> String {
    format!(
        "tool_library = {:?}\nmachine = {machine:?}\n[part]\nbuiltin = \"choi\"\n\
         [stock]\nmargin = 4\ntop = 2\nbottom = 1\n\
         [[operation]]\nkind = \"finish\"\nname = \"ball D8\"\ntool = 6\n[operation.finishing]\nscallop_height = 0.4\nmax_step = 2\n\
         [[operation]]\nkind = \"finish\"\nname = \"bull D10\"\ntool = 5\n[operation.finishing]\nscallop_height = 0.3\nmax_step = 2\n\
         [tolerances]\npath = 0.05\n[verify]\nresolution = 0.5\n{extra}",
        repo("examples/tools.toml").display().to_string()
    )
}

/// Runs a job file; the program text, or the error text.
fn run(dir: &Path, name: &str, text: &str) -> Result<String, String> {
    let file = dir.join(format!("{name}.toml"));
    std::fs::write(&file, text).expect("write job");
    let out_dir = dir.join(name);
    let out = run_job(&file, &out_dir, &[]);
    if !out.status.success() {
        let err = rejected(&out);
        assert!(!out_dir.join("program.nc").exists(), "a refused job wrote a program");
        return Err(err);
    }
    Ok(std::fs::read_to_string(out_dir.join("program.nc")).expect("program.nc"))
}

/// Writes the shipped machine `shipped` with `edit.0` replaced by `edit.1` as `dir/name`.
fn edited_machine(dir: &Path, shipped: &str, edit: (&str, &str), name: &str) {
    let text = std::fs::read_to_string(repo(&format!("machines/{shipped}.toml"))).expect("shipped machine");
    let edited = text.replace(edit.0, edit.1);
    assert_ne!(edited, text, "{shipped}: {} not found", edit.0);
    std::fs::write(dir.join(name), edited).expect("write machine");
}

/// The number after `letter` in a word of `line` (`S9549` in `S9549 M3`).
fn word(line: &str, letter: char) -> Option<f64> {
    line.split_whitespace().find_map(|w| w.strip_prefix(letter).and_then(|v| v.parse().ok()))
}

/// The program cut at each tool's section: the lines from one tool change to the next.
fn sections<'a>(text: &'a str, is_change: &dyn Fn(&str) -> bool) -> Vec<Vec<&'a str>> {
    let mut out: Vec<Vec<&str>> = Vec::new();
    for line in text.lines() {
        if is_change(line) {
            out.push(Vec::new());
        }
        if let Some(s) = out.last_mut() {
            s.push(line);
        }
    }
    out
}

/// The tool-tip positions of every section (mm), read back by the G-code reader,
/// each section in the program's units.
fn positions(text: &str, units: &str) -> Vec<Vec<[f64; 3]>> {
    sections(text, &|l| l.contains("M6"))
        .iter()
        .map(|s| {
            let body = format!("{units}\n{}\n", s.join("\n"));
            let path = read_gcode(&body, &GcodeOptions::default()).expect("the program reads back");
            path.moves().iter().map(|m| [m.to.x, m.to.y, m.to.z]).collect()
        })
        .collect()
}

#[test]
fn library_tools_on_three_machines_write_their_words_and_an_inch_program_replays() {
    let dir = scratch("machine-file");
    let library =
        parse_tool_library(&std::fs::read_to_string(repo("examples/tools.toml")).expect("tools")).expect("library");
    let mut times = Vec::new();
    for (machine, manual) in [("linuxcnc-3axis", false), ("fanuc-3axis", false), ("grbl-3axis", true)] {
        let described = Described::builtin(machine).expect("shipped");
        assert_eq!(described.nc().tool_changer, !manual);
        let text = run(&dir, machine, &job(machine, "")).expect("the job runs");
        let change: &dyn Fn(&str) -> bool =
            if manual { &|l: &str| l.contains("tool change: load tool") } else { &|l: &str| l.contains("M6") };
        let parts = sections(&text, change);
        assert_eq!(parts.len(), 2, "{machine}: two tool changes\n{text}");
        for (section, number) in parts.iter().zip([6, 5]) {
            let tool = library.get(number).expect("library tool");
            let n = tool.spindle_speed().expect("speed");
            let max = described.max_spindle_speed().expect("max speed");
            let (s, f) =
                if n > max { (max, tool.feed().expect("feed") * max / n) } else { (n, tool.feed().expect("feed")) };
            if manual {
                assert!(section[0].contains(&format!("load tool {number}")), "{machine}: {}", section[0]);
                assert_eq!(section[1].trim(), "M0", "{machine}: the change pauses");
                assert!(!section.iter().any(|l| l.contains("M6")), "{machine}: no M6 without a changer");
            } else {
                assert_eq!((word(section[0], 'T'), word(section[0], 'M')), (Some(f64::from(number)), Some(6.0)));
            }
            let spindle = section.iter().find(|l| l.contains("M3")).expect("a spindle start");
            assert!((word(spindle, 'S').expect("S word") - s).abs() <= 0.5, "{machine}: {spindle} for S {s}");
            let feeds: Vec<f64> = section.iter().filter(|l| l.starts_with("G1")).filter_map(|l| word(l, 'F')).collect();
            assert!(feeds.iter().any(|v| (v - f).abs() <= 1.0), "{machine} tool {number}: F {f} not in {feeds:?}");
        }
        let report: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join(machine).join("report.json")).expect("report"))
                .expect("json");
        times.push(report["total_time_s"].as_f64().expect("time"));
    }
    // The same path on machines of different dynamics: the grbl router (0.3 m/s², 2 m/min)
    // takes longer than the Fanuc machining centre (3-4 m/s², 10 m/min).
    assert!(times[2] > times[1], "machine-aware times {times:?}");

    // Inches: the LinuxCNC job again with G20 output replays to the mm program's path
    // within the words' resolution (4 decimals of mm, 5 of inch).
    let mm = run(&dir, "linuxcnc-3axis", &job("linuxcnc-3axis", "")).expect("mm");
    let inch = run(&dir, "linuxcnc-in", &job("linuxcnc-3axis", "[output]\nunits = \"in\"\n")).expect("inch");
    assert!(inch.lines().any(|l| l.contains("G20")) && !inch.lines().any(|l| l.contains("G21")));
    let (a, b) = (positions(&mm, "G21"), positions(&inch, "G20"));
    let resolution = 0.5e-4 + 0.5e-5 * 25.4 + 1e-9;
    assert_eq!(a.iter().map(Vec::len).collect::<Vec<_>>(), b.iter().map(Vec::len).collect::<Vec<_>>());
    for (p, q) in a.iter().flatten().zip(b.iter().flatten()) {
        assert!((0..3).all(|i| (p[i] - q[i]).abs() <= resolution), "{p:?} vs {q:?}");
    }
}

#[test]
fn a_machine_file_by_path_clamps_library_speeds_and_the_jobs_dialect_wins() {
    let dir = scratch("machine-path");
    // A path relative to the job file: the shipped Fanuc machine with a 6000 1/min
    // spindle, and a LinuxCNC [output].
    edited_machine(&dir, "fanuc-3axis", ("max_speed = 12000", "max_speed = 6000"), "mill.toml");
    let text = run(&dir, "by-path", &job("mill.toml", "[output]\ndialect = \"linuxcnc\"\n")).expect("runs");
    assert!(text.contains("dialect: LinuxCNC") && !text.lines().any(|l| l.starts_with("O1")), "the job's dialect wins");
    // Tool 6 (7162 1/min from its Vc) is clamped to 6000 and its feed scaled with it.
    let library =
        parse_tool_library(&std::fs::read_to_string(repo("examples/tools.toml")).expect("tools")).expect("library");
    let tool = library.get(6).expect("tool 6");
    let (n, f) = (tool.spindle_speed().expect("n"), tool.feed().expect("f"));
    assert!(n > 6000.0);
    let first = &sections(&text, &|l| l.contains("M6"))[0];
    let spindle = first.iter().find(|l| l.contains("M3")).expect("S M3");
    assert_eq!(word(spindle, 'S'), Some(6000.0), "{spindle}");
    let feeds: Vec<f64> = first.iter().filter(|l| l.starts_with("G1")).filter_map(|l| word(l, 'F')).collect();
    assert!(feeds.iter().any(|v| (v - f * 6000.0 / n).abs() <= 1.0), "{feeds:?}");
}

#[test]
fn travel_spindle_and_name_errors_name_the_fix() {
    let dir = scratch("machine-errors");
    // Part zero 50 mm above Z home: the program is above the router's Z travel.
    edited_machine(&dir, "grbl-3axis", ("origin = [-150, -150, -60]", "origin = [-150, -150, 50]"), "low.toml");
    let err = run(&dir, "travel", &job("low.toml", "")).expect_err("outside the travel");
    assert!(err.contains("axis Z") && err.contains("travel") && err.contains("fix:"), "{err}");
    // A spindle speed the job gives above the machine's largest is refused.
    let fast = job("grbl-3axis", "").replace("tool = 6\n", "tool = 6\nspindle = 30000\n");
    let err = run(&dir, "spindle", &fast).expect_err("too fast");
    assert!(err.contains("30000") && err.contains("24000") && err.contains("refused"), "{err}");
    // An unknown name lists the shipped machines.
    let err = run(&dir, "name", &job("haas-3axis", "")).expect_err("unknown");
    assert!(err.contains("haas-3axis") && err.contains("linuxcnc-3axis") && err.contains("mx330"), "{err}");
    // [machine] acceleration with a machine file: the file wins, so the key is refused.
    let both = job("grbl-3axis", "").replace("machine = \"grbl-3axis\"\n", "")
        + "[machine]\ndescription = \"grbl-3axis\"\nacceleration = 3\n";
    let err = run(&dir, "both", &both).expect_err("both");
    assert!(err.contains("acceleration") && err.contains("remove"), "{err}");
}
