//! The impeller channel (docs/rough5.md, "The impeller's inlet and the
//! neighbouring channels"): an open pocket's levels are the offsets of its
//! bottom extended across its open edge, so the levels over the steep hub
//! reach the inlet section; the shank and holder keep their radius from the
//! top of the blank beyond the pocket (the neighbouring channels stay full in
//! the proof), the hub level keeps the tilt curves of the first level of the
//! hub alone, and the whole program is proven from the channel's blank.
#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

mod common;

use proptest::prelude::*;
use scallop_cutter::Cutter;
use scallop_geom::{Point3, Vec3};
use scallop_mesh::TriMesh;
use scallop_parts::{FaceTag, ImpellerParams, impeller_channel};
use scallop_rough5::{
    BodyCheck, LevelOptions, ProofSettings, TiltMode, level_passes_with, plan_rough5_in, prove_from_blank,
};

/// The default tool of `scallop rough5`: torus R 5 r 1.5, 30 mm flutes, 41 mm
/// stick-out, holder 27 x 192 mm.
fn tool() -> Cutter {
    common::torus(30.0, 192.0)
}

const ALL: LevelOptions = LevelOptions { centre_offsets: true, pair_by_rank: true, open_bottom: true };

/// The hub rises at 52 deg at the inlet (r 25 mm): the offset of the hub
/// alone by d ends on the ruled surface of its normals there, at r 25 + d sin
/// 52 deg (31.3 mm at d = 8). The levels of the extended hub reach the inlet.
#[test]
fn the_impeller_levels_reach_its_inlet() {
    let part = impeller_channel(&ImpellerParams::default()).unwrap();
    let bottom = part.faces(&[FaceTag::Bottom]).unwrap();
    let flanks = part.faces(&[FaceTag::Flank]).unwrap();
    let depth = part.stock.max.z - bottom.bounds().min.z;
    let levels = level_passes_with(&bottom, &flanks, &common::guides(depth), TiltMode::Guides, &ALL).unwrap();
    let mut checked = 0;
    for level in levels.iter().filter(|l| (8.0..=20.0).contains(&l.distance)) {
        let inner = level
            .passes
            .iter()
            .flat_map(|(c, _)| c.line.points.iter())
            .map(|p| p.x.hypot(p.y))
            .fold(f64::INFINITY, f64::min);
        assert!(inner < 26.0, "level {} mm: its passes start at r {inner:.2} mm", level.distance);
        checked += 1;
    }
    assert!(checked >= 3, "{checked} levels between 8 and 20 mm");
}

/// The hub level's tilt curves are those of the first level of the hub
/// alone, which starts beyond the inlet section (r 25 mm) and ends within a
/// millimetre of the outlet (r 75 mm): the extended level's curves run over
/// the strips beyond both (r 19.5 to 80.5 mm), where they turned the hub
/// level's axes into the blades.
#[test]
fn the_impeller_hub_level_leans_towards_the_first_level_of_the_hub() {
    let part = impeller_channel(&ImpellerParams::default()).unwrap();
    let bottom = part.faces(&[FaceTag::Bottom]).unwrap();
    let flanks = part.faces(&[FaceTag::Flank]).unwrap();
    let depth = part.stock.max.z - bottom.bounds().min.z;
    let levels = level_passes_with(&bottom, &flanks, &common::guides(depth), TiltMode::Guides, &ALL).unwrap();
    let hub = &levels[0];
    assert!(hub.distance.abs() < 1e-12, "level 0 at {} mm", hub.distance);
    let tilts: Vec<f64> = hub
        .passes
        .iter()
        .filter_map(|(_, t)| t.as_ref())
        .flat_map(|t| t.line.points.iter())
        .map(|p| p.x.hypot(p.y))
        .collect();
    assert!(!tilts.is_empty(), "the hub level has no tilt curve");
    let inner = tilts.iter().copied().fold(f64::INFINITY, f64::min);
    let outer = tilts.iter().copied().fold(0.0, f64::max);
    assert!(inner > 25.0 && outer < 76.0, "the hub level's tilt curves span r {inner:.2} to {outer:.2} mm");
}

/// A square plane at z = 0 facing up, 1000 mm wide.
fn plane() -> TriMesh {
    let p = |x, y| Point3::new(x, y, 0.0);
    let h = 500.0;
    TriMesh::from_soup(&[[p(-h, -h), p(h, -h), p(h, h)], [p(-h, -h), p(h, h), p(-h, h)]]).unwrap().0
}

/// A flank far from everything (a small facet 400 mm away).
fn far_flank() -> TriMesh {
    let p = |x, y, z| Point3::new(x, y, z);
    TriMesh::from_soup(&[[p(400.0, 0.0, 0.0), p(401.0, 0.0, 0.0), p(400.0, 1.0, 0.0)]]).unwrap().0
}

proptest! {
    /// Against stock below the tool, only the shank (radius 5 from 30 to 41
    /// mm up the axis) and the holder (radius 13.5 from 41 mm) count, each
    /// with the check's half sample step (0.125 mm): the flutes may cut it
    /// (the tip below the stock's top). An axis that crosses the top is
    /// sampled within the distance every 0.25 mm, so it collides too.
    #[test]
    fn the_stock_is_kept_from_the_shank_and_holder_only(
        h in -45.0f64..40.0,
        tilt in 0.0f64..1.2,
        azimuth in 0.0f64..std::f64::consts::TAU,
    ) {
        let axis = Vec3::new(tilt.sin() * azimuth.cos(), tilt.sin() * azimuth.sin(), tilt.cos());
        let tip = Point3::new(0.0, 0.0, h);
        let low = |s: f64, rho: f64| h + s * tilt.cos() - (rho + 0.125);
        let margin = low(30.0, 5.0).min(low(41.0, 13.5));
        prop_assume!(margin.abs() > 1e-6);
        let free = BodyCheck::new(&far_flank(), &tool(), 0.0);
        prop_assert!(!free.collides(&tip, &axis));
        let check = free.with_stock(&plane());
        prop_assert_eq!(check.collides(&tip, &axis), margin < 0.0);
        prop_assert_eq!(check.intrusion(&tip, &axis).is_some(), margin < 0.0);
    }
}

/// The whole program of the channel, from its blank: no gouge beyond the
/// tolerance, no rapid into the stock, no shank or holder collision with the
/// in-process stock (the neighbouring channels full up to the blank). Its
/// levels reach the inlet, where the tilted tools' holders lean over the
/// neighbouring channels: without the check against the blank beyond the
/// pocket the proof refuses the holder there.
#[test]
fn the_impeller_program_is_proven_from_its_blank() {
    let part = impeller_channel(&ImpellerParams::default()).unwrap();
    let bottom = part.faces(&[FaceTag::Bottom]).unwrap();
    let flanks = part.faces(&[FaceTag::Flank]).unwrap();
    let depth = part.stock.max.z - bottom.bounds().min.z;
    let settings = common::settings(depth);
    let blank = part.blank.as_ref();
    let plan = plan_rough5_in(&bottom, &flanks, (&part.stock, blank), &tool(), &settings, &|_, _| {}).unwrap();
    let proof_settings = ProofSettings { resolution: 0.5, axis_tolerance: 0.05 };
    let proof =
        prove_from_blank(&plan.toolpath, &tool(), &part.stock, blank, &part.mesh, &proof_settings, &|_, _| {}).unwrap();
    assert!(proof.gouge_depth <= proof_settings.axis_tolerance, "gouge {} mm", proof.gouge_depth);
}
