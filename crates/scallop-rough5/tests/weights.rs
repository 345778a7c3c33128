//! Per-pass weights (spec module H; Jousselin 2020, Ch. 3 §2.3): the passes
//! that leave the finished faces' stock (the bottom level's and each level's
//! limit passes) optimised with their own weighting, the bulk passes kept.

#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

mod common;

use scallop_parts::closed_pocket;
use scallop_rough5::{OrientSettings, Rough5Settings, TiltMode, Weights, level_passes_with, plan_rough5};

/// On the closed pocket, SPU for the bulk and the thesis's mixed weighting
/// for the limit passes: the two programs have the same passes, and the
/// first pass (in cutting order) where they differ is a limit pass or a pass
/// of the bottom level (the passes before it see the same cursor and the
/// same orientation), and some pass's pitch angles change.
#[test]
fn limit_passes_take_their_own_weights() {
    let part = closed_pocket(&Default::default()).unwrap();
    let (bottom, flanks, depth) = common::bottom_flanks(&part);
    let tool = common::torus(30.0, 100.0);
    let spu = Rough5Settings { tilt: TiltMode::Guides, ..common::settings(depth) };
    let mixed = OrientSettings::new(Weights { bounds: 15.0, fluidity: 1.2, pitch: 1.0 });
    let weighted = Rough5Settings { limit_orientation: Some(mixed), ..spu };
    let a = plan_rough5(&bottom, &flanks, &part.stock, &tool, &spu, &|_, _| {}).unwrap();
    let b = plan_rough5(&bottom, &flanks, &part.stock, &tool, &weighted, &|_, _| {}).unwrap();
    let levels = level_passes_with(&bottom, &flanks, &spu.guides, spu.tilt, &spu.levels).unwrap();
    assert_eq!(a.passes.len(), b.passes.len());
    let first = a.passes.iter().zip(&b.passes).position(|(x, y)| x != y).expect("no pass changed");
    let p = &a.passes[first];
    let level = &levels[p.level];
    let limit = p.pass + level.outer >= level.passes.len();
    assert!(p.level == 0 || limit, "pass {} of level {} changed first", p.pass, p.level);
    // And the weighting changed some pass's pitch angles (min, max, mean)
    // by more than rounding (the first may be optimised to SPU itself).
    let moved =
        a.passes.iter().zip(&b.passes).any(|(x, y)| x.pitch.iter().zip(&y.pitch).any(|(p, q)| (p - q).abs() > 1e-6));
    assert!(moved, "no pass's pitch changed");
}
