//! The whole slice on the closed test pocket: the three variants (zero
//! tilt, guide curves by SPU, guide curves with the optimised orientation)
//! plan, place every CL point on or above its level, keep the angular step,
//! do not depend on the thread count, and prove themselves on a tri-dexel
//! stock (no
//! rapid into stock, no shank or holder collision, nothing removed outside
//! the volume to remove beyond the rays' rounding).
#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

mod common;

use scallop_guides::GuideSettings;
use scallop_parts::{FaceTag, closed_pocket};
use scallop_rough5::{OrientSettings, ProofSettings, Rough5Settings, TiltMode, Weights, plan_rough5, prove};
use scallop_toolpath::MoveKind;

/// The slice without the refinements, coarser: a_p 6 mm, voxel 1.5 mm, CL
/// points every 2 mm, angular steps of 3 and 10 deg.
fn settings(tilt: TiltMode, depth: f64) -> Rough5Settings {
    Rough5Settings {
        tilt,
        guides: GuideSettings { axial_step: 6.0, voxel: 1.5, ..common::guides(depth) },
        step: 2.0,
        max_angle_step: 3f64.to_radians(),
        max_azimuth_step: 10f64.to_radians(),
        ..common::settings(depth).with_refinements(false)
    }
}

#[test]
fn every_variant_proves_itself_on_the_closed_pocket() {
    let part = closed_pocket(&Default::default()).unwrap();
    let bottom = part.faces(&[FaceTag::Bottom]).unwrap();
    let flanks = part.faces(&[FaceTag::Flank]).unwrap();
    let tool = common::torus(30.0, 100.0);
    let depth = part.stock.max.z - bottom.bounds().min.z;
    let mut remaining = Vec::new();
    // The optimised orientation: the thesis's mixed weighting (Ch. 3 §2.3, case 2).
    let mixed = OrientSettings::new(Weights { bounds: 15.0, fluidity: 1.2, pitch: 1.0 });
    // And the guide curves with the collision correction (Ch. 3 §3, step 1),
    // and with its step 2 (the upper levels' limit curves).
    let variants = [
        (TiltMode::Zero, None, false, false),
        (TiltMode::Guides, None, false, false),
        (TiltMode::Guides, Some(mixed), false, false),
        (TiltMode::Guides, None, true, false),
        (TiltMode::Guides, None, false, true),
    ];
    for (tilt, orientation, correct, spatial) in variants {
        let s = Rough5Settings { orientation, correct, spatial, ..settings(tilt, depth) };
        let plan = plan_rough5(&bottom, &flanks, &part.stock, &tool, &s, &|_, _| {}).unwrap();
        let path = &plan.toolpath;
        assert!(plan.passes.iter().map(|p| p.points).sum::<usize>() > 100);
        let turned: usize = plan.passes.iter().map(|p| p.spatial).sum();
        assert_eq!(turned > 0, spatial, "{turned} pairs turned by step 2");
        for (i, m) in path.moves().iter().enumerate().skip(1) {
            if matches!(m.kind, MoveKind::Feed | MoveKind::Link) {
                let angle = path.axis(i - 1).angle(&path.axis(i));
                assert!(angle <= s.max_angle_step + 1e-9, "move {i}: {angle}");
            }
            assert!(part.stock.min.z <= m.to.z);
        }
        if tilt == TiltMode::Zero {
            assert!(!path.has_tool_axes());
        }
        // The same plan on one thread.
        let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
        let again = one.install(|| plan_rough5(&bottom, &flanks, &part.stock, &tool, &s, &|_, _| {}).unwrap());
        assert_eq!(again.toolpath, plan.toolpath);
        let proof_settings = ProofSettings { resolution: 1.0, axis_tolerance: 0.05 };
        let proof = prove(path, &tool, &part.stock, &part.mesh, &proof_settings, &|_, _| {}).unwrap();
        assert!(proof.gouge_depth <= 1.0, "{proof:?}");
        assert!(proof.remaining_percent < 100.0 && proof.removed_volume > 0.0, "{proof:?}");
        assert!((0.0..=100.0).contains(&proof.air_percent));
        remaining.push(proof.remaining_percent);
    }
    assert!(remaining.iter().all(|v| v.is_finite()));
}
