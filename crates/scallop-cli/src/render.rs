//! `scallop render`: a PNG of a part (and a toolpath) from the deterministic
//! software rasteriser of `scallop-report`, without a browser.

use std::path::{Path, PathBuf};

use clap::Args;
use scallop_engine::prepare_part;
use scallop_geom::{Point3, Tolerances};
use scallop_io::gcode::{GcodeOptions, read_gcode};
use scallop_report::ReportData;
use scallop_toolpath::{Move, MoveKind, Toolpath};

use crate::output::{print_text, write_atomic};
use crate::part::{UnitsArg, load};
use crate::{CliResult, Failure};

/// Arguments of `scallop render`.
#[derive(Args, Debug)]
pub struct RenderArgs {
    /// The part: mesh file, surface file (.toml), built-in name (choi, rubio), or a job file (its part).
    part: String,
    /// The picture to write (PNG).
    #[arg(short, long, default_value = "out/render.png")]
    output: PathBuf,
    /// A toolpath to draw on top: `toolpath.csv` (kind,x,y,z) or a G-code program.
    #[arg(long)]
    toolpath: Option<PathBuf>,
    /// Picture size WIDTHxHEIGHT in pixels.
    #[arg(long, default_value = "1200x800")]
    size: String,
    /// Unit of mesh coordinates.
    #[arg(long, value_enum, default_value = "mm")]
    units: UnitsArg,
}

/// Largest picture side (pixels).
const MAX_SIDE: usize = 8192;
/// Path tolerance of the tessellation of surfaces for a picture (mm): finer
/// than a pixel of any picture of a part of normal size.
const DISPLAY_TOLERANCE: f64 = 0.05;

fn parse_size(text: &str) -> CliResult<(usize, usize)> {
    let bad = || Failure::rejected(format!("--size '{text}': give WIDTHxHEIGHT in pixels, each 1 to {MAX_SIDE}"));
    let (w, h) = text.split_once(['x', 'X']).ok_or_else(bad)?;
    let (w, h): (usize, usize) = (w.trim().parse().map_err(|_| bad())?, h.trim().parse().map_err(|_| bad())?);
    if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
        return Err(bad());
    }
    Ok((w, h))
}

/// Reads `toolpath.csv` as written by `scallop run` (`kind,x,y,z`).
fn parse_csv(name: &str, text: &str) -> CliResult<Toolpath> {
    let mut path = Toolpath::new(0.0);
    for (k, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || (k == 0 && line.starts_with("kind")) {
            continue;
        }
        let bad = || Failure::rejected(format!("{name}: line {}: expected kind,x,y,z", k + 1));
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        let [kind, x, y, z] = fields.as_slice() else { return Err(bad()) };
        let kind = match *kind {
            "rapid" => MoveKind::Rapid,
            "plunge" => MoveKind::Plunge,
            "feed" => MoveKind::Feed,
            "link" => MoveKind::Link,
            "retract" => MoveKind::Retract,
            _ => {
                return Err(Failure::rejected(format!(
                    "{name}: line {}: unknown move kind '{kind}' (rapid, plunge, feed, link, retract)",
                    k + 1
                )));
            }
        };
        let c: Vec<f64> = [x, y, z].iter().map(|t| t.parse::<f64>()).collect::<Result<_, _>>().map_err(|_| bad())?;
        if c.iter().any(|v| !v.is_finite()) {
            return Err(bad());
        }
        path.push(Move::new(kind, Point3::new(c[0], c[1], c[2])));
    }
    Ok(path)
}

fn read_text(path: &Path) -> CliResult<String> {
    let name = path.display().to_string();
    let bytes = crate::input::read_bytes(path, &name, "the file")?;
    String::from_utf8(bytes)
        .map_err(|e| Failure::rejected(format!("{name}: byte {}: not UTF-8 text", e.utf8_error().valid_up_to())))
}

/// The part named by a job file, if `spec` is one.
fn job_part(spec: &str) -> Option<(String, UnitsArg)> {
    let path = Path::new(spec);
    if !path.extension().is_some_and(|e| e.eq_ignore_ascii_case("toml")) {
        return None;
    }
    let (_, job) = crate::run::read_job(path).ok()?;
    let units = UnitsArg::from(job.part.units);
    match (&job.part.file, &job.part.builtin) {
        (Some(file), _) => {
            Some((path.parent().unwrap_or(Path::new(".")).join(file).to_string_lossy().into_owned(), units))
        }
        (None, Some(name)) => Some((name.clone(), UnitsArg::Mm)),
        (None, None) => None,
    }
}

/// `scallop render`.
pub fn run(args: &RenderArgs) -> CliResult<()> {
    let (width, height) = parse_size(&args.size)?;
    let (spec, units) = job_part(&args.part).unwrap_or_else(|| (args.part.clone(), args.units));
    let loaded = load(&spec, units)?;
    let prepared = prepare_part(&loaded.part, &Tolerances { path: DISPLAY_TOLERANCE, gouge: 0.0 })
        .map_err(|e| Failure::rejected(format!("{spec}: {e}")))?;
    let mut data = ReportData::new(&loaded.description);
    data.part = Some(prepared.mesh);
    if let Some(file) = &args.toolpath {
        let name = file.display().to_string();
        let text = read_text(file)?;
        let is_csv = file.extension().is_some_and(|e| e.eq_ignore_ascii_case("csv"));
        data.toolpath = Some(if is_csv {
            parse_csv(&name, &text)?
        } else {
            read_gcode(&text, &GcodeOptions::default()).map_err(|e| Failure::rejected(format!("{name}: {e}")))?
        });
    }
    let png = scallop_report::render::render(&data, width, height).to_png();
    write_atomic(&args.output, |w| std::io::Write::write_all(w, &png))?;
    print_text(&format!("{}: {width} x {height} pixels\n", args.output.display()))
}
