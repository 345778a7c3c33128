//! The tool and the settings the rough5 tests share: each test states only
//! what it changes.

#![allow(dead_code, clippy::unwrap_used, reason = "shared by several test files; a panic is the failure report")]

use scallop_cutter::Cutter;
use scallop_guides::GuideSettings;
use scallop_mesh::TriMesh;
use scallop_parts::{FaceTag, PocketParams, TestPart};
use scallop_rough5::{Rough5Settings, TorusTool};

/// The torus R 5 r 1.5 of the thesis's pocket (spec 9) with `flutes` mm of
/// flutes, a shank R 5 of 11 mm and a cylindrical holder R 13.5 of
/// `holder` mm.
pub fn torus(flutes: f64, holder: f64) -> Cutter {
    TorusTool { flutes, stick_out: flutes + 11.0, holder_length: holder, ..TorusTool::THESIS }.cutter().unwrap()
}

/// The levels and curves of the torus R 5 on a pocket `depth` mm deep:
/// 0.5 mm flank allowance, a_p 4 mm, a_e 4.5 mm, voxel 1 mm.
pub fn guides(depth: f64) -> GuideSettings {
    GuideSettings { tool_radius: 5.0, flank_allowance: 0.5, axial_step: 4.0, radial_step: 4.5, voxel: 1.0, depth }
}

/// The settings of `scallop rough5` at 2400 mm/min on a pocket `depth` mm
/// deep ([`Rough5Settings::new`]).
pub fn settings(depth: f64) -> Rough5Settings {
    Rough5Settings::new(guides(depth), 2400.0)
}

/// A test part's bottom and flanks, and its depth: the stock's top over
/// the bottom's lowest point.
pub fn bottom_flanks(part: &TestPart) -> (TriMesh, TriMesh, f64) {
    let bottom = part.faces(&[FaceTag::Bottom]).unwrap();
    let flanks = part.faces(&[FaceTag::Flank]).unwrap();
    let depth = part.stock.max.z - bottom.bounds().min.z;
    (bottom, flanks, depth)
}

/// A closed pocket in a 60 x 60 mm block `height` mm high, its bottom at
/// `bottom_z`, walls 8 mm thick, corners of radius 6 mm; the rest as
/// [`PocketParams::default`].
pub fn small_pocket(height: f64, bottom_z: f64) -> PocketParams {
    PocketParams { stock: [60.0, 60.0, height], bottom_z, wall: 8.0, corner_radius: 6.0, ..Default::default() }
}

/// The plane z = 0 over a 200 mm square (the level of a pass).
pub fn floor() -> TriMesh {
    let p = scallop_geom::Point3::new;
    let (m, _) = TriMesh::from_soup(&[
        [p(-100., -100., 0.), p(100., -100., 0.), p(100., 100., 0.)],
        [p(-100., -100., 0.), p(100., 100., 0.), p(-100., 100., 0.)],
    ])
    .unwrap();
    m
}
