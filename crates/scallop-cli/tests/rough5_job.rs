//! `kind = "rough5"` operations in job files (`scallop run`, docs/job.md):
//! a coarse job of the closed test pocket plans, proves and posts (840D,
//! TRAORI) with its metrics in the report; bad jobs exit 1 naming the key and
//! write nothing.

mod common;

use common::{read_json, rejected, run_job, scratch, succeeded};

/// A coarse rough5 job of the closed pocket: levels 8 mm apart, coarse fields,
/// CL points every 2 mm, a 1 mm tri-dexel proof.
const JOB: &str = "machine = \"ucp710\"\n[part]\ntest_part = \"pocket\"\n\
[[operation]]\nkind = \"rough5\"\nname = \"coarse\"\ntool = 3\nspindle = 15000\n\
[operation.cutter]\nshape = \"bull\"\ndiameter = 10\ncorner_radius = 1.5\nflute_length = 30\nshank_length = 11\n\
[[operation.cutter.holder]]\nlength = 192\ndiameter = 27\n\
[operation.rough5]\nap = 8\nae = 4.5\ntilt = \"zero\"\nvoxel = 1.5\nstep = 2\nresolution = 1\n\
teeth = 2\nfeed_per_tooth = 0.08\n";

fn write_job(dir: &std::path::Path, text: &str) -> std::path::PathBuf {
    std::fs::create_dir_all(dir).expect("dir");
    let path = dir.join("job.toml");
    std::fs::write(&path, text).expect("job");
    path
}

#[test]
fn a_rough5_job_plans_proves_and_posts() {
    let dir = scratch("rough5-job");
    let job = write_job(&dir, JOB);
    let out = dir.join("out");
    succeeded(common::scallop().arg("run").arg(&job).arg("-o").arg(&out).arg("--json"));
    let report = read_json(&out.join("report.json"));
    let op = &report["operations"][0];
    assert_eq!(op["kind"], "rough5");
    assert_eq!(op["feed_mm_min"].as_f64(), Some(2400.0));
    let m = &op["metrics"];
    let num = |k: &str| m[k].as_f64().unwrap_or(f64::NAN);
    assert!(num("remaining_percent") > 0.0 && num("remaining_percent") < 100.0, "{m}");
    assert!(num("gouge_depth_mm") <= 0.05, "{m}");
    assert!(num("out_of_material_percent") >= 0.0 && num("out_of_material_percent") < 100.0, "{m}");
    // The machine's time is at least the time at the programmed feeds, and the removal rate is over it.
    let t = num("machining_time_s");
    assert!(t > 0.0 && t >= num("feed_time_s") && num("feed_time_s") >= 0.999 * num("estimated_time_at_feed_s") - 1.0);
    assert!((num("removal_rate_mm3_s") * t - num("removed_volume_mm3")).abs() <= 1e-6 * num("removed_volume_mm3"));
    assert_eq!(report["total_time_s"].as_f64(), Some(t));
    // Entered by helices where they fit (`entry = "auto"` by default), the ramps counted twice.
    let entries = &op["entries"];
    assert!(entries["helix"].as_u64().unwrap_or(0) > 0, "{entries}");
    assert_eq!(entries["ramp"], op["ramps"], "{op}");
    // Spec 10.1 per face: quartiles in order, crests from the allowance up.
    let faces = m["faces"].as_array().expect("faces");
    assert_eq!(faces.len(), 2, "{m}");
    for f in faces {
        let q: Vec<f64> =
            f["deviation_quartiles_mm"].as_array().expect("q").iter().filter_map(|v| v.as_f64()).collect();
        assert!(q.len() == 5 && q.windows(2).all(|w| w[0] <= w[1]), "{f}");
        let crest = |k: &str| f[k].as_f64().unwrap_or(f64::NAN);
        assert!(crest("crest_mean_mm") >= 0.0 && crest("crest_mean_mm") <= crest("crest_max_mm"), "{f}");
        assert!(f["samples"].as_u64().unwrap_or(0) > f["corner_samples"].as_u64().unwrap_or(u64::MAX), "{f}");
    }
    let nc = std::fs::read_to_string(out.join("program.nc")).expect("program");
    assert!(nc.contains("TRAORI") && nc.contains("T3"), "{}", &nc[..nc.len().min(2000)]);
    assert!(op["replay_tip_deviation_mm"].as_f64().unwrap_or(f64::NAN) < 0.01);
    let csv = std::fs::read_to_string(out.join("toolpath.csv")).expect("toolpath");
    assert_eq!(csv.lines().count() - 1, op["cl_points"].as_u64().unwrap_or(0) as usize);
    // Another dialect of the post, from the job.
    let fanuc = write_job(&dir.join("fanuc"), &JOB.replace("[part]", "[output]\ndialect = \"fanuc\"\n[part]"));
    let out = dir.join("out-fanuc");
    succeeded(common::scallop().arg("run").arg(&fanuc).arg("-o").arg(&out));
    assert!(std::fs::read_to_string(out.join("program.nc")).expect("program").contains("G43.4"));
}

#[test]
fn bad_rough5_jobs_exit_1_naming_the_key() {
    let dir = scratch("rough5-job-bad");
    let cases: [(&str, &str, &str); 9] = [
        ("test_part = \"pocket\"", "test_part = \"gear\"", "unknown variant `gear`"),
        ("ap = 8", "ap = 500", "rough5.ap"),
        ("ap = 8", "ap = -4", "rough5.ap"),
        ("ap = 8", "ap = nan", "rough5.ap"),
        ("ae = 4.5", "ae = 40", "rough5.ae"),
        ("resolution = 1", "resolution = inf", "rough5.resolution"),
        ("shape = \"bull\"", "shape = \"cone\"", "cutter.shape"),
        ("test_part = \"pocket\"", "builtin = \"choi\"", "part.test_part"),
        ("machine = \"ucp710\"", "machine = \"grbl-3axis\"", "5-axis"),
    ];
    for (k, (from, to, needle)) in cases.iter().enumerate() {
        let job = write_job(&dir.join(k.to_string()), &JOB.replace(from, to));
        let out = dir.join(format!("out-{k}"));
        let done = run_job(&job, &out, &[]);
        let err = rejected(&done);
        assert!(err.contains(needle), "case {k} ({to}): {err}");
        assert!(!out.join("program.nc").exists(), "case {k}: a rejected job writes nothing");
    }
    // No machine named, and a rough5 operation next to a finishing one.
    let job = write_job(&dir.join("nomachine"), &JOB.replace("machine = \"ucp710\"\n", ""));
    assert!(rejected(&run_job(&job, &dir.join("o1"), &[])).contains("5-axis machine"));
    let two = JOB.to_string()
        + "[[operation]]\nkind = \"finish\"\n[operation.cutter]\nshape = \"ball\"\ndiameter = 4\n\
        [operation.finishing]\nscallop_height = 0.01\n";
    let job = write_job(&dir.join("two"), &two);
    assert!(rejected(&run_job(&job, &dir.join("o2"), &[])).contains("exactly one [[operation]]"));
}
