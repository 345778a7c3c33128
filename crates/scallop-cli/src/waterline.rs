//! `scallop waterline`: the closed contours where a cutter with its tip at
//! height z touches a mesh, written as CSV (`loop,x,y,z`) or JSON.

use std::io::Write;
use std::path::PathBuf;

use clap::Args;
use scallop_engine::{GridAxis, prepare_part};
use scallop_geom::Tolerances;
use scallop_waterline::{Loop, WaterlineError, WaterlineGrid, WaterlineOptions, tol};
use serde::Serialize;

use crate::drop::CutterArgs;
use crate::output::{print_report, progress_bar, write_atomic};
use crate::part::{UnitsArg, load};
use crate::{CliResult, Failure};

/// Arguments of `scallop waterline`.
#[derive(Args, Debug)]
pub struct WaterlineArgs {
    /// Mesh file (.stl .obj .ply .3mf).
    #[arg(long)]
    mesh: String,
    #[command(flatten)]
    tool: CutterArgs,
    /// Tip height Z (mm), or levels MIN:MAX:STEP; repeat for more levels.
    #[arg(long, required = true, allow_hyphen_values = true)]
    z: Vec<String>,
    /// Grid step of the drop-cutter sampling (mm); default a quarter of the cutter radius.
    /// Islands and pockets of the contour narrower than the step may be missed.
    #[arg(long, allow_hyphen_values = true)]
    step: Option<f64>,
    /// Largest deviation of a chord from the contour at its midpoint (mm).
    #[arg(long, default_value_t = tol::CHORD_TOLERANCE, allow_hyphen_values = true)]
    chord_tolerance: f64,
    /// Width of the bisection bracket of each contour point (mm).
    #[arg(long, default_value_t = tol::CROSSING_TOLERANCE, allow_hyphen_values = true)]
    crossing_tolerance: f64,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Unit of mesh coordinates.
    #[arg(long, value_enum, default_value = "mm")]
    units: UnitsArg,
    /// Output file: `.json` for JSON loops, anything else for CSV (`loop,x,y,z` rows).
    #[arg(short, long)]
    output: PathBuf,
    /// Print a JSON summary on stdout.
    #[arg(long)]
    json: bool,
}

#[derive(Serialize)]
struct LevelReport {
    z: f64,
    loops: usize,
    outer_loops: usize,
    points: usize,
    seconds: f64,
}

#[derive(Serialize)]
struct WaterlineReport {
    command: &'static str,
    part: String,
    triangles: usize,
    cutter: String,
    step_mm: f64,
    grid_samples: usize,
    chord_tolerance_mm: f64,
    crossing_tolerance_mm: f64,
    threads: usize,
    levels: Vec<LevelReport>,
    loops: usize,
    points: usize,
    /// Building the grid: its blocks' bounds (each block is sampled by the
    /// first level that needs it, in that level's seconds).
    grid_seconds: f64,
    contour_seconds: f64,
    seconds: f64,
    /// CPU time of the process (all threads) spent on the waterline computation: the
    /// part's preparation (mesh copy and XY index build), the drop-cutter grid and every
    /// level's loops; the mesh file's parse, the output writing and the process start are
    /// outside it. `None` where the process CPU clock is not read (not Linux).
    kernel_cpu_seconds: Option<f64>,
    output: String,
}

#[derive(Serialize)]
struct JsonLoop {
    r#loop: usize,
    z: f64,
    outer: bool,
    points: Vec<[f64; 2]>,
}

/// The heights of `--z`: single values or `MIN:MAX:STEP` ranges, in the order given.
fn parse_levels(specs: &[String]) -> CliResult<Vec<f64>> {
    let mut levels = Vec::new();
    for spec in specs {
        if spec.contains(':') {
            let axis = GridAxis::parse(spec).map_err(|e| Failure::rejected(format!("--z {e}")))?;
            levels.extend(axis.values());
        } else {
            let z: f64 = spec
                .trim()
                .parse()
                .map_err(|_| Failure::rejected(format!("--z {spec}: not a number; give Z or MIN:MAX:STEP in mm")))?;
            levels.push(z);
        }
    }
    Ok(levels)
}

/// The CPU time used so far by this process, all threads (s): `clock_gettime` with
/// `CLOCK_PROCESS_CPUTIME_ID` (POSIX), on Linux only.
#[cfg(target_os = "linux")]
fn process_cpu_seconds() -> Option<f64> {
    let t = rustix::time::clock_gettime(rustix::time::ClockId::ProcessCPUTime);
    #[allow(clippy::cast_precision_loss)] // seconds of CPU time: far below 2^52
    Some(t.tv_sec as f64 + t.tv_nsec as f64 * 1e-9)
}

#[cfg(not(target_os = "linux"))]
fn process_cpu_seconds() -> Option<f64> {
    None
}

fn reject(what: &str, e: &WaterlineError) -> Failure {
    Failure::rejected(format!("{what}: {e}"))
}

/// `scallop waterline`.
pub fn run(args: &WaterlineArgs) -> CliResult<()> {
    let (cutter, cutter_text) = args.tool.build()?;
    let levels = parse_levels(&args.z)?;
    if args.threads == Some(0) {
        return Err(Failure::rejected("--threads 0: give at least 1"));
    }
    let loaded = load(&args.mesh, args.units)?;
    let cpu_start = process_cpu_seconds();
    let prepared = prepare_part(&loaded.part, &Tolerances { path: tol::CHORD_TOLERANCE, gouge: 0.0 })
        .map_err(|e| Failure::rejected(format!("{}: {e}", args.mesh)))?;
    let bounds = prepared.mesh.bounds();
    for &z in &levels {
        if !(z.is_finite() && z >= bounds.min.z && z < bounds.max.z) {
            return Err(Failure::rejected(format!(
                "--z {z}: {} has heights [{}, {}); give levels in that range",
                args.mesh, bounds.min.z, bounds.max.z
            )));
        }
    }
    let options = WaterlineOptions {
        step: args.step,
        chord_tolerance: args.chord_tolerance,
        crossing_tolerance: args.crossing_tolerance,
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads.unwrap_or(0))
        .build()
        .map_err(|e| Failure::Io(anyhow::anyhow!("cannot start worker threads: {e}")))?;

    let start = std::time::Instant::now();
    let bar = progress_bar(0, "drop-cutter grid");
    let grid = pool
        .install(|| {
            WaterlineGrid::with_progress(&cutter, &prepared.index, &options, &|done, rows| {
                bar.set_length(rows as u64);
                bar.set_position(done as u64);
            })
        })
        .map_err(|e| reject(&args.mesh, &e))?;
    bar.finish_and_clear();
    let grid_seconds = start.elapsed().as_secs_f64();
    let bar = progress_bar(levels.len() as u64, "waterline levels");
    let mut all: Vec<Loop> = Vec::new();
    let mut reports = Vec::with_capacity(levels.len());
    for &z in &levels {
        let t = std::time::Instant::now();
        let loops = pool.install(|| grid.loops(z)).map_err(|e| reject(&format!("--z {z}"), &e))?;
        reports.push(LevelReport {
            z,
            loops: loops.len(),
            outer_loops: loops.iter().filter(|l| l.is_outer()).count(),
            points: loops.iter().map(|l| l.points.len()).sum(),
            seconds: t.elapsed().as_secs_f64(),
        });
        all.extend(loops);
        bar.inc(1);
    }
    bar.finish_and_clear();
    let seconds = start.elapsed().as_secs_f64();
    let kernel_cpu_seconds = cpu_start.zip(process_cpu_seconds()).map(|(a, b)| b - a);

    let json_out = args.output.extension().is_some_and(|e| e.eq_ignore_ascii_case("json"));
    write_atomic(&args.output, |w| {
        if json_out {
            let loops: Vec<JsonLoop> = all
                .iter()
                .enumerate()
                .map(|(k, l)| JsonLoop {
                    r#loop: k,
                    z: l.z,
                    outer: l.is_outer(),
                    points: l.points.iter().map(|p| [p.x, p.y]).collect(),
                })
                .collect();
            serde_json::to_writer(&mut *w, &serde_json::json!({ "loops": loops })).map_err(std::io::Error::other)?;
            w.write_all(b"\n")
        } else {
            w.write_all(b"loop,x,y,z\n")?;
            for (k, l) in all.iter().enumerate() {
                for p in &l.points {
                    writeln!(w, "{k},{},{},{}", p.x, p.y, l.z)?;
                }
            }
            Ok(())
        }
    })?;
    let (nx, ny) = grid.shape();
    let report = WaterlineReport {
        command: "waterline",
        part: loaded.description,
        triangles: prepared.mesh.triangles().len(),
        cutter: cutter_text,
        step_mm: grid.step(),
        grid_samples: nx * ny,
        chord_tolerance_mm: options.chord_tolerance,
        crossing_tolerance_mm: options.crossing_tolerance,
        threads: pool.current_num_threads(),
        loops: all.len(),
        points: reports.iter().map(|r| r.points).sum(),
        levels: reports,
        grid_seconds,
        contour_seconds: seconds - grid_seconds,
        seconds,
        kernel_cpu_seconds,
        output: args.output.display().to_string(),
    };
    print_report(&report, args.json, |r| {
        format!(
            "{} loops ({} points) at {} levels in {:.3} s (grid {}x{} step {} mm: {:.3} s; {} threads) on {}\n  cutter {}\n  wrote {}\n",
            r.loops,
            r.points,
            r.levels.len(),
            r.seconds,
            nx,
            ny,
            r.step_mm,
            r.grid_seconds,
            r.threads,
            r.part,
            r.cutter,
            r.output
        )
    })
}
