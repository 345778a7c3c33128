//! Levels of the test parts: offsets of a pocket bottom within h / 2 of their
//! distance on the material side, morph levels between bottom and lid inside
//! the pocket's height.

#![allow(clippy::unwrap_used, reason = "tests")]

mod common;

use common::brute_distance;
use scallop_field::{LevelOptions, Side, Surface, morph_levels, offset_levels};
use scallop_parts::{FaceTag, FittingParams, PocketParams, closed_pocket, fitting_pocket};

#[test]
fn pocket_bottom_levels_lie_above_the_bottom_within_half_a_voxel() {
    let part = closed_pocket(&PocketParams::default()).unwrap();
    let bottom = part.faces(&[FaceTag::Bottom]).unwrap();
    let h = 1.0;
    // The volume to remove is behind the bottom's outward (downward) normals.
    let options = LevelOptions { voxel: h, side: Side::Against, ..LevelOptions::default() };
    let levels = offset_levels(&Surface::new(&bottom), &[4.0, 8.0], &options).unwrap();
    for (level, d) in levels.iter().zip([4.0, 8.0]) {
        let above = level.vertices().iter().filter(|v| v.z > bottom.bounds().max.z).count();
        assert!(above > level.vertices().len() / 2, "level {d} is not above the bottom");
        for v in level.vertices().iter().step_by(7) {
            let e = brute_distance(v, &bottom) - d;
            assert!(e.abs() <= 0.5 * h, "{v:?}: {e}");
        }
    }
}

#[test]
fn fitting_bottom_level_is_a_plane_over_the_non_convex_outline() {
    let params = FittingParams::default();
    let part = fitting_pocket(&params).unwrap();
    let bottom = part.faces(&[FaceTag::Bottom]).unwrap();
    let options = LevelOptions { voxel: 1.0, side: Side::Against, ..LevelOptions::default() };
    let level = &offset_levels(&Surface::new(&bottom), &[4.0], &options).unwrap()[0];
    // Over the bottom's inside the offset of a plane is exact (a linear field)
    // up to the interpolation clamp (here the level passes through samples).
    let tol = 2.0 * scallop_field::tol::INTERP_CLAMP * options.voxel;
    let flat = level.vertices().iter().filter(|v| (v.z - params.bottom_z - 4.0).abs() <= tol).count();
    assert!(flat > level.vertices().len() / 2);
}

#[test]
fn morph_levels_of_the_pocket_stay_between_bottom_and_lid() {
    let part = closed_pocket(&PocketParams::default()).unwrap();
    let (bottom, top) = (part.faces(&[FaceTag::Bottom]).unwrap(), part.faces(&[FaceTag::Top]).unwrap());
    let options = LevelOptions { voxel: 1.0, ..LevelOptions::default() };
    let levels = morph_levels(&Surface::new(&bottom), &Surface::new(&top), 2, &options).unwrap();
    assert_eq!(levels.len(), 2);
    let (lo, hi) = (bottom.bounds().min.z, top.bounds().max.z);
    let mut previous = lo;
    for level in &levels {
        let b = level.bounds();
        assert!(b.min.z > lo && b.max.z < hi, "{b:?} outside ({lo}, {hi})");
        let mean = level.vertices().iter().map(|v| v.z).sum::<f64>() / level.vertices().len() as f64;
        assert!(mean > previous, "levels not ordered bottom to top");
        previous = mean;
    }
}
