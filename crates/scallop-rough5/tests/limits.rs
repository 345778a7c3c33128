//! The limit passes' tilt where it pays (docs/rough5.md, "Limit passes: the
//! tilt where it pays"): the step a vertical tool leaves along a draft is the
//! draft's horizontal run over the level's height; on a closed pocket whose
//! drafts leave steps thinner than the flank allowance the program is cut
//! with the axis +Z and proven, where steeper drafts keep the tilted limit
//! passes; and a vertical stretch of a pass keeps no pair that its
//! neighbours make redundant within a span and a chord.
#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

mod common;

use proptest::prelude::*;
use scallop_geom::{Point3, Vec3};
use scallop_parts::{FaceTag, PocketParams, closed_pocket};
use scallop_rough5::{ProofSettings, Rough5Settings, SyncPoint, limit_step, plan_rough5, prove, thin_vertical};
use scallop_toolpath::MoveKind;

fn settings(depth: f64, thin_steps: bool) -> Rough5Settings {
    Rough5Settings { vertical_thin_steps: thin_steps, ..common::settings(depth) }
}

/// A 60 x 60 x 20 mm block with a closed pocket whose four walls have the
/// draft `deg` (degrees), on a flat bottom.
fn drafted_pocket(deg: f64) -> scallop_parts::TestPart {
    closed_pocket(&PocketParams {
        stock: [60.0, 60.0, 20.0],
        bottom_z: 6.0,
        wall: 8.0,
        corner_radius: 6.0,
        walls: [deg.to_radians(); 4],
        tilt: 0.0,
        dome: 0.0,
        ..Default::default()
    })
    .unwrap()
}

/// The largest tilt (degrees) of the program's cutting moves, and whether
/// the program is proven (no gouge beyond the simulation's tolerance, no
/// rapid into the stock, no shank or holder collision).
fn largest_tilt_and_proof(part: &scallop_parts::TestPart, thin_steps: bool) -> (f64, bool) {
    let bottom = part.faces(&[FaceTag::Bottom]).unwrap();
    let flanks = part.faces(&[FaceTag::Flank]).unwrap();
    let depth = part.stock.max.z - bottom.bounds().min.z;
    let tool = common::torus(20.0, 100.0);
    let plan = plan_rough5(&bottom, &flanks, &part.stock, &tool, &settings(depth, thin_steps), &|_, _| {}).unwrap();
    let path = &plan.toolpath;
    let tilt = (0..path.moves().len())
        .filter(|&i| matches!(path.moves()[i].kind, MoveKind::Feed))
        .map(|i| path.axis(i).angle(&Vec3::z()).to_degrees())
        .fold(0.0, f64::max);
    let proof = ProofSettings { resolution: 0.5, axis_tolerance: 0.05 };
    let proven = prove(path, &tool, &part.stock, &part.mesh, &proof, &|_, _| {}).is_ok_and(|p| p.gouge_depth <= 0.05);
    (tilt, proven)
}

#[test]
fn a_draft_under_the_allowance_is_cut_vertical_and_a_steep_one_tilted() {
    // 3 deg: a vertical tool leaves 4 tan 3 deg = 0.21 mm between levels,
    // under the 0.5 mm allowance; the guide curves lean 3 to 4.5 deg.
    let shallow = drafted_pocket(3.0);
    let (tilt, proven) = largest_tilt_and_proof(&shallow, true);
    assert!(proven, "the vertical program of the 3 deg pocket is not proven");
    assert!(tilt < 1.0, "the 3 deg pocket's program leans {tilt:.2} deg");
    let (tilt_plain, _) = largest_tilt_and_proof(&shallow, false);
    assert!(tilt_plain > 2.0, "without the rule the limit passes lean {tilt_plain:.2} deg only");
    // 12 deg: 4 tan 12 deg = 0.85 mm, more than the allowance: the limit
    // passes keep the guide curves' tilt.
    let steep = drafted_pocket(12.0);
    let (tilt, proven) = largest_tilt_and_proof(&steep, true);
    assert!(proven, "the 12 deg pocket's program is not proven");
    assert!(tilt > 9.0, "the 12 deg pocket's limit passes lean {tilt:.2} deg only");
}

fn pair(x: f64, y: f64, axis: Vec3) -> SyncPoint {
    SyncPoint { path: Point3::new(x, y, 0.0), tilt: None, normal: Vec3::z(), tangent: Vec3::x(), axis }
}

proptest! {
    #![proptest_config(ProptestConfig { failure_persistence: None, ..ProptestConfig::default() })]

    /// A pair along a flank with draft `alpha` whose tilt point is `rise`
    /// above its path point on the flank's offset: the vertical tool's step
    /// is rise tan alpha, whatever the azimuth (and the levels' spacing is
    /// used without a tilt point).
    #[test]
    fn the_step_is_the_drafts_run(
        alpha in 0.0f64..0.6,
        rise in 0.5f64..8.0,
        azimuth in 0.0f64..std::f64::consts::TAU,
    ) {
        let out = Vec3::new(azimuth.cos(), azimuth.sin(), 0.0);
        let path = Point3::new(3.0, -2.0, 7.0);
        let tilt = path + out * (rise * alpha.tan()) + Vec3::z() * rise;
        let axis = (tilt - path).normalize();
        let s = SyncPoint { path, tilt: Some(tilt), normal: Vec3::z(), tangent: out.cross(&Vec3::z()), axis };
        prop_assert!((limit_step(&s, 99.0) - rise * alpha.tan()).abs() < 1e-9);
        let bare = SyncPoint { tilt: None, ..s };
        prop_assert!((limit_step(&bare, rise) - rise * alpha.tan()).abs() < 1e-9);
    }

    /// Along a pass with pairs 0.01 to 0.8 mm apart, wavering across by up
    /// to `waver`, some tilted: the thinned pairs are a subsequence with the
    /// first and last pairs, every tilted pair and its neighbours; two kept
    /// pairs are no farther apart than the span unless they were neighbours;
    /// every dropped pair lies within the chord of the segment between the
    /// kept pairs on either side; and on a straight vertical pass two pairs
    /// kept two apart are more than the span apart, so a straight vertical
    /// pass of length L keeps at most 2 L / span + 3 pairs.
    #[test]
    fn a_vertical_stretch_keeps_no_redundant_pair(
        gaps in prop::collection::vec(0.01f64..0.8, 3..300),
        tilted in prop::collection::vec(prop::bool::weighted(0.05), 300),
        across in prop::collection::vec(-1.0f64..1.0, 300),
        which in 0usize..3,
    ) {
        let (span, chord) = (5.0, 0.05);
        let waver = [0.0, 0.03, 0.3][which];
        let lean = Vec3::new(0.05, 0.0, 1.0).normalize();
        let mut x = 0.0;
        let mut pairs = vec![pair(0.0, 0.0, Vec3::z())];
        for (k, g) in gaps.iter().enumerate() {
            x += g;
            pairs.push(pair(x, waver * across[k], if tilted[k] { lean } else { Vec3::z() }));
        }
        let n = pairs.len();
        let kept = thin_vertical(pairs.clone(), span, chord);
        // The original index of every kept pair (x grows strictly).
        let idx: Vec<usize> =
            kept.iter().map(|k| pairs.iter().position(|p| p.path == k.path).unwrap()).collect();
        prop_assert!(idx.windows(2).all(|w| w[0] < w[1]));
        prop_assert_eq!(idx[0], 0);
        prop_assert_eq!(idx[idx.len() - 1], n - 1);
        let vertical = |i: usize| pairs[i].axis == Vec3::z();
        for i in 0..n {
            let near_tilt = (i.saturating_sub(1)..=(i + 1).min(n - 1)).any(|j| !vertical(j));
            if near_tilt {
                prop_assert!(idx.contains(&i), "pair {} by a tilted pair was dropped", i);
            }
        }
        for w in idx.windows(2) {
            let (a, b) = (pairs[w[0]].path, pairs[w[1]].path);
            prop_assert!(w[1] == w[0] + 1 || (b - a).norm() <= span + 1e-12, "kept {} and {}: {}", w[0], w[1], (b - a).norm());
            for p in &pairs[w[0] + 1..w[1]] {
                let ab = b - a;
                let t = ((p.path - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
                prop_assert!((p.path - (a + ab * t)).norm() <= chord + 1e-12, "a dropped pair is off the chord");
            }
        }
        if which == 0 && (0..n).all(vertical) {
            for w in idx.windows(3) {
                let d = pairs[w[2]].path.x - pairs[w[0]].path.x;
                prop_assert!(d > span, "kept pairs {} and {} are {} apart, {} between them", w[0], w[2], d, w[1]);
            }
            prop_assert!(kept.len() as f64 <= 2.0 * x / span + 3.0, "{} pairs kept on {} mm", kept.len(), x);
        }
    }
}
