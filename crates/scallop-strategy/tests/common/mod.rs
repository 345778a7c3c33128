//! Shared fixtures of the strategy tests.
#![allow(dead_code, clippy::unwrap_used)]

use scallop_analysis::MachineLimits;
use scallop_cutter::{Cutter, CutterShape};
use scallop_geom::Point3;
use scallop_mesh::{MeshIndex, TriMesh};
use scallop_strategy::{Boundary, FinishingParams, Pattern};

/// The spec's inclined rectangle (finishing.md 14.1): w = 56 along Y, h = 28
/// along the slope (X, Z), s = 60 degrees, centred at the origin; two triangles.
pub fn inclined_plane(width: f64, height: f64, slope_deg: f64) -> MeshIndex {
    let (c, s) = (slope_deg.to_radians().cos(), slope_deg.to_radians().sin());
    let p = |u: f64, v: f64| Point3::new((v - 0.5) * height * c, (u - 0.5) * width, (v - 0.5) * height * s);
    let (mesh, _) =
        TriMesh::from_soup(&[[p(0., 0.), p(0., 1.), p(1., 0.)], [p(0., 1.), p(1., 1.), p(1., 0.)]]).unwrap();
    MeshIndex::build(&mesh)
}

/// The spec's machine and typical settings.
pub fn params(direction: f64, pattern: Pattern, scallop_height: f64, max_step: f64) -> FinishingParams {
    FinishingParams {
        direction,
        pattern,
        scallop_height,
        boundary: Boundary::ContactInside,
        max_step,
        clearance: 5.0,
        machine: MachineLimits::default(),
        plunge_feed: 20.0,
        rapid_rate: 500.0,
        sharp_corner: 30f64.to_radians(),
        blend_tolerance: 0.01,
    }
}

pub fn bull(radius: f64, corner: f64) -> Cutter {
    Cutter::new(CutterShape::Bull { radius, corner }, 30.0).unwrap()
}

pub fn ball(radius: f64) -> Cutter {
    Cutter::new(CutterShape::Ball { radius }, 30.0).unwrap()
}

pub fn flat(radius: f64) -> Cutter {
    Cutter::new(CutterShape::Flat { radius }, 30.0).unwrap()
}

/// The demo's job (finishing.md 14.3): the Choi surface indexed at the path
/// tolerance `tol`, and its analysis for the machine (V = 5 m/min,
/// A = 6 m/s^2, J = 40 m/s^3) at sh = 0.01 mm.
pub fn choi_analysed(tol: &scallop_geom::Tolerances) -> (MeshIndex, scallop_analysis::AnalysisReport) {
    use scallop_analysis::{GridOptions, ToolOptions, analyze, sample_patch};
    let set = scallop_surface::builtin("choi").unwrap();
    let index = MeshIndex::build(&set.tessellate(tol.tessellation()).unwrap().mesh);
    let samples = sample_patch(&set.patches()[0], &GridOptions::default()).unwrap();
    let machine = MachineLimits::from_thesis_units(5.0, 6.0, 40.0);
    (index, analyze(&samples, &ToolOptions::default(), &machine, 0.01).unwrap())
}
