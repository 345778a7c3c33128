//! Reading parts: mesh files, surface files and built-ins.

use std::path::Path;

use clap::{Args, ValueEnum};
use scallop_engine::Part;
use scallop_io::{MeshFormat, Units, read_mesh};
use serde::Serialize;

use crate::{CliResult, Failure, output};

/// Length unit of mesh files.
#[derive(Debug, Clone, Copy, ValueEnum, PartialEq, Eq)]
pub enum UnitsArg {
    /// Millimetres.
    Mm,
    /// Inches (scaled by 25.4).
    In,
    /// Metres (scaled by 1000).
    M,
    /// Centimetres (scaled by 10).
    Cm,
}

impl From<scallop_io::job::UnitsWord> for UnitsArg {
    fn from(u: scallop_io::job::UnitsWord) -> UnitsArg {
        match u {
            scallop_io::job::UnitsWord::Mm => UnitsArg::Mm,
            scallop_io::job::UnitsWord::In => UnitsArg::In,
            scallop_io::job::UnitsWord::M => UnitsArg::M,
            scallop_io::job::UnitsWord::Cm => UnitsArg::Cm,
        }
    }
}

impl From<UnitsArg> for Units {
    fn from(u: UnitsArg) -> Units {
        match u {
            UnitsArg::Mm => Units::Millimetres,
            UnitsArg::In => Units::Inches,
            UnitsArg::M => Units::Metres,
            UnitsArg::Cm => Units::Centimetres,
        }
    }
}

/// A loaded part and what to say about it.
pub struct LoadedPart {
    /// The part.
    pub part: Part,
    /// Human description.
    pub description: String,
    /// Mesh diagnostics when it is a mesh.
    pub diagnostics: Option<scallop_mesh::MeshDiagnostics>,
}

/// Loads `spec`: a mesh file (.stl .obj .ply .3mf), a surface file (.toml) or a built-in name.
pub fn load(spec: &str, units: UnitsArg) -> CliResult<LoadedPart> {
    let path = Path::new(spec);
    if !path.exists()
        && let Some(part) = Part::builtin(spec)
    {
        return Ok(LoadedPart { part, description: format!("built-in surface '{spec}'"), diagnostics: None });
    }
    let is_toml = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("toml"));
    let format = MeshFormat::from_extension(spec);
    if !is_toml && format.is_none() {
        return Err(Failure::rejected(format!(
            "{spec}: unknown part format; use a mesh file (.stl, .obj, .ply, .3mf), a surface file (.toml) \
             or a built-in surface ({})",
            scallop_surface::BUILTIN_NAMES.join(", ")
        )));
    }
    let bytes = crate::input::read_bytes(path, spec, "the file")?;
    if is_toml {
        if units != UnitsArg::Mm {
            return Err(Failure::rejected(format!(
                "{spec}: a surface file states its own units (units = \"mm\" or \"in\"); drop --units"
            )));
        }
        let text = std::str::from_utf8(&bytes)
            .map_err(|e| Failure::rejected(format!("{spec}: byte {}: the file is not UTF-8 text", e.valid_up_to())))?;
        let set = scallop_surface::toml_format::parse_surfaces(text)
            .map_err(|e| Failure::rejected(format!("{spec}: {e}")))?;
        let n = set.len();
        return Ok(LoadedPart {
            part: Part::Surfaces(set),
            description: format!("{spec} ({n} patches)"),
            diagnostics: None,
        });
    }
    // INVARIANT: format is Some when the file is not TOML (checked above).
    let format = format.ok_or_else(|| Failure::rejected(format!("{spec}: unknown format")))?;
    let loaded = read_mesh(&bytes, format, units.into()).map_err(|e| Failure::rejected(format!("{spec}: {e}")))?;
    let n = loaded.mesh.triangles().len();
    Ok(LoadedPart {
        description: format!("{spec} ({format}, {n} triangles, {})", loaded.units_note),
        part: Part::Mesh(loaded.mesh),
        diagnostics: Some(loaded.diagnostics),
    })
}

/// Arguments of `scallop inspect`.
#[derive(Args, Debug)]
pub struct InspectArgs {
    /// Part: mesh file (.stl .obj .ply .3mf), surface file (.toml) or built-in name (choi, rubio).
    part: String,
    /// Unit of mesh coordinates.
    #[arg(long, value_enum, default_value = "mm")]
    units: UnitsArg,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

#[derive(Serialize)]
struct InspectReport {
    part: String,
    kind: &'static str,
    bounds_min: [f64; 3],
    bounds_max: [f64; 3],
    area_mm2: f64,
    triangles: Option<usize>,
    vertices: Option<usize>,
    degenerate_dropped: Option<usize>,
    kept_unwelded: Option<usize>,
    boundary_edges: Option<usize>,
    non_manifold_edges: Option<usize>,
    weld_distance_mm: Option<f64>,
    patches: Option<usize>,
}

/// `scallop inspect`.
pub fn inspect(args: &InspectArgs) -> CliResult<()> {
    let loaded = load(&args.part, args.units)?;
    let (b, area, kind, tris, verts, patches) = match &loaded.part {
        Part::Mesh(m) => (m.bounds(), m.area(), "mesh", Some(m.triangles().len()), Some(m.vertices().len()), None),
        Part::Surfaces(s) => (s.bounds(), s.area(), "surfaces", None, None, Some(s.len())),
    };
    let d = loaded.diagnostics.as_ref();
    let report = InspectReport {
        part: loaded.description.clone(),
        kind,
        bounds_min: [b.min.x, b.min.y, b.min.z],
        bounds_max: [b.max.x, b.max.y, b.max.z],
        area_mm2: area,
        triangles: tris,
        vertices: verts,
        degenerate_dropped: d.map(|d| d.degenerate_dropped),
        kept_unwelded: d.map(|d| d.kept_unwelded),
        boundary_edges: d.map(|d| d.boundary_edges),
        non_manifold_edges: d.map(|d| d.non_manifold_edges),
        weld_distance_mm: d.map(|d| d.weld_distance),
        patches,
    };
    if args.json {
        return output::print_json(&report);
    }
    let mut text = format!(
        "{}\n  bounds   x {:.3} .. {:.3}   y {:.3} .. {:.3}   z {:.3} .. {:.3} mm\n  area     {:.3} mm²\n",
        report.part, b.min.x, b.max.x, b.min.y, b.max.y, b.min.z, b.max.z, area
    );
    if let Some(d) = d {
        text.push_str(&format!(
            "  welded   {} vertex references -> {} vertices (weld distance {:.3e} mm); {} triangles kept unwelded\n  dropped  {} degenerate triangles\n  edges    {} open (boundary), {} non-manifold\n",
            d.input_vertices, d.welded_vertices, d.weld_distance, d.kept_unwelded, d.degenerate_dropped, d.boundary_edges, d.non_manifold_edges
        ));
    }
    output::print_text(&text)
}
