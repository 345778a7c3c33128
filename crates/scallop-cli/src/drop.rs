//! `scallop drop`: drop-cutter on an XY grid, written as CSV.

use std::io::Write;
use std::path::PathBuf;

use clap::{Args, ValueEnum};
use scallop_cutter::{Contact, Cutter, CutterShape, drop_grid};
use scallop_engine::{GridAxis, prepare_part};
use scallop_geom::Tolerances;
use serde::Serialize;

use crate::output::{print_report, progress_bar, write_atomic};
use crate::part::{UnitsArg, load};
use crate::{CliResult, Failure};

/// Cutter shapes on the command line.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum CutterArg {
    /// Ball end mill.
    Ball,
    /// Flat end mill.
    Flat,
    /// Bull-nose (toroidal) end mill; needs --corner-radius.
    Bull,
    /// Cone (V) cutter; --angle is its included tip angle.
    Cone,
}

/// The cutter on the command line.
#[derive(Args, Debug)]
pub struct CutterArgs {
    /// Cutter shape.
    #[arg(long, value_enum)]
    cutter: CutterArg,
    /// Cutter diameter D (mm).
    #[arg(long, allow_hyphen_values = true)]
    diameter: f64,
    /// Corner radius r of a bull-nose cutter (mm), 0 < r <= D/2.
    #[arg(long, allow_hyphen_values = true)]
    corner_radius: Option<f64>,
    /// Included tip angle of a cone cutter (degrees), 0 < angle < 180.
    #[arg(long, default_value_t = 90.0, allow_hyphen_values = true)]
    angle: f64,
    /// Flute length (mm); default 4 D or the cone's height if longer.
    #[arg(long, allow_hyphen_values = true)]
    flute_length: Option<f64>,
}

/// Arguments of `scallop drop`.
#[derive(Args, Debug)]
pub struct DropArgs {
    /// Mesh file (.stl .obj .ply .3mf).
    #[arg(long, conflicts_with = "surface", required_unless_present = "surface")]
    mesh: Option<String>,
    /// Surface file (.toml) or built-in surface (choi, rubio), dropped on through its tessellation.
    #[arg(long)]
    surface: Option<String>,
    #[command(flatten)]
    tool: CutterArgs,
    /// X samples MIN:MAX:STEP (mm).
    #[arg(long, allow_hyphen_values = true)]
    x: String,
    /// Y samples MIN:MAX:STEP (mm).
    #[arg(long, allow_hyphen_values = true)]
    y: String,
    /// Tip height where the cutter touches nothing (mm); default: the part's lowest z.
    #[arg(long, allow_hyphen_values = true)]
    floor: Option<f64>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Unit of mesh coordinates.
    #[arg(long, value_enum, default_value = "mm")]
    units: UnitsArg,
    /// Path tolerance (mm); a quarter of it is the tessellation budget for surfaces.
    #[arg(long, default_value_t = 0.01, allow_hyphen_values = true)]
    tolerance: f64,
    /// Output CSV (`x,y,z` rows, x fastest).
    #[arg(short, long)]
    output: PathBuf,
    /// Print a JSON summary on stdout.
    #[arg(long)]
    json: bool,
}

#[derive(Serialize)]
struct DropReport {
    command: &'static str,
    part: String,
    triangles: usize,
    chordal_error_mm: f64,
    cutter: String,
    points: usize,
    threads: usize,
    drop_seconds: f64,
    points_per_second: f64,
    contacts_floor: usize,
    contacts_vertex: usize,
    contacts_edge: usize,
    contacts_facet: usize,
    output: String,
}

impl CutterArgs {
    /// The validated cutter and a short description.
    pub fn build(&self) -> CliResult<(Cutter, String)> {
        cutter_from(self)
    }
}

fn cutter_from(args: &CutterArgs) -> CliResult<(Cutter, String)> {
    let d = args.diameter;
    if !(d.is_finite() && d > 0.0) {
        return Err(Failure::rejected(format!("--diameter {d}: must be a finite number > 0 mm")));
    }
    let radius = 0.5 * d;
    let (shape, text) = match args.cutter {
        CutterArg::Ball => (CutterShape::Ball { radius }, format!("ball D{d}")),
        CutterArg::Flat => (CutterShape::Flat { radius }, format!("flat D{d}")),
        CutterArg::Bull => {
            let corner = args
                .corner_radius
                .ok_or_else(|| Failure::rejected("--cutter bull needs --corner-radius r (0 < r <= D/2)"))?;
            (CutterShape::Bull { radius, corner }, format!("bull D{d} r{corner}"))
        }
        CutterArg::Cone => {
            let a = args.angle;
            if !(a.is_finite() && a > 0.0 && a < 180.0) {
                return Err(Failure::rejected(format!("--angle {a}: the included angle must lie in (0, 180) degrees")));
            }
            (CutterShape::Cone { radius, half_angle: (0.5 * a).to_radians() }, format!("cone D{d} {a}°"))
        }
    };
    let flute = args.flute_length.unwrap_or_else(|| (4.0 * d).max(shape.profile_height()));
    let cutter = Cutter::new(shape, flute).map_err(|e| Failure::rejected(format!("cutter: {e}")))?;
    Ok((cutter, text))
}

/// Budget of one `scallop drop` grid: 20 million points, about 2 GB with the CSV text
/// ([`BYTES_PER_POINT`]) and a few minutes of drop-cutter on 2 cores.
const MAX_DROP_POINTS: usize = 20_000_000;

/// Memory per grid point: the cutter location (with its contact) and its CSV row.
const BYTES_PER_POINT: usize = 100;

/// `scallop drop`.
pub fn run(args: &DropArgs) -> CliResult<()> {
    let (cutter, cutter_text) = args.tool.build()?;
    let xs = GridAxis::parse(&args.x).map_err(|e| Failure::rejected(format!("--x {e}")))?;
    let ys = GridAxis::parse(&args.y).map_err(|e| Failure::rejected(format!("--y {e}")))?;
    let total = xs.len().saturating_mul(ys.len());
    let cap = MAX_DROP_POINTS.min(scallop_engine::MAX_GRID_POINTS);
    if total > cap {
        return Err(Failure::rejected(format!(
            "--x {} --y {}: the grid has {total} points (about {} MB of cutter locations and CSV), \
             over the budget of {cap} points; use larger steps or split the grid",
            args.x,
            args.y,
            total.saturating_mul(BYTES_PER_POINT) >> 20
        )));
    }
    if let Some(f) = args.floor.filter(|f| !f.is_finite()) {
        return Err(Failure::rejected(format!("--floor {f}: must be a finite height")));
    }
    let threads = args.threads.unwrap_or(0);
    if args.threads == Some(0) {
        return Err(Failure::rejected("--threads 0: give at least 1"));
    }
    let spec = args.mesh.as_deref().or(args.surface.as_deref()).unwrap_or_default();
    let loaded = load(spec, args.units)?;
    let tol = Tolerances { path: args.tolerance, gouge: 0.0 };
    let prepared = prepare_part(&loaded.part, &tol).map_err(|e| Failure::rejected(format!("{spec}: {e}")))?;
    let floor = args.floor.unwrap_or(prepared.mesh.bounds().min.z);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Failure::Io(anyhow::anyhow!("cannot start worker threads: {e}")))?;
    let (xv, yv) = (xs.values(), ys.values());
    let bar = progress_bar(yv.len() as u64, "drop-cutter");
    let start = std::time::Instant::now();
    let cl =
        pool.install(|| drop_grid(&cutter, &prepared.index, &xv, &yv, floor, &|done| bar.set_position(done as u64)));
    let seconds = start.elapsed().as_secs_f64();
    bar.finish_and_clear();

    write_atomic(&args.output, |w| {
        w.write_all(b"x,y,z\n")?;
        for p in &cl {
            writeln!(w, "{},{},{}", p.tip.x, p.tip.y, p.tip.z)?;
        }
        Ok(())
    })?;
    let count = |f: fn(&Contact) -> bool| cl.iter().filter(|c| f(&c.contact)).count();
    let report = DropReport {
        command: "drop",
        part: loaded.description,
        triangles: prepared.mesh.triangles().len(),
        chordal_error_mm: prepared.chordal_error,
        cutter: cutter_text,
        points: cl.len(),
        threads: pool.current_num_threads(),
        drop_seconds: seconds,
        #[allow(clippy::cast_precision_loss)]
        points_per_second: cl.len() as f64 / seconds.max(f64::MIN_POSITIVE),
        contacts_floor: count(|c| matches!(c, Contact::Floor)),
        contacts_vertex: count(|c| matches!(c, Contact::Vertex { .. })),
        contacts_edge: count(|c| matches!(c, Contact::Edge { .. })),
        contacts_facet: count(|c| matches!(c, Contact::Facet { .. })),
        output: args.output.display().to_string(),
    };
    print_report(&report, args.json, |r| {
        format!(
            "{} points dropped in {:.3} s ({:.0} points/s, {} threads) on {}\n  cutter {}; contacts: {} facet, {} edge, {} vertex, {} floor\n  wrote {}\n",
            r.points,
            r.drop_seconds,
            r.points_per_second,
            r.threads,
            r.part,
            r.cutter,
            r.contacts_facet,
            r.contacts_edge,
            r.contacts_vertex,
            r.contacts_floor,
            r.output
        )
    })
}
