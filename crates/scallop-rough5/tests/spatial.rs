//! The spatial collision correction (Jousselin 2020, Ch. 3 §3, step 2,
//! Fig. 3.32, Eq. 3.32) on the thesis's cause (a) (Fig. 3.30): a flank that
//! bulges into the pocket above the levels of the pass hits the tool of a
//! lower level. A vertical wall `x = 10` with a block `6 <= x <= 10`,
//! `|y| <= w`, standing out of it from `z = z0` up: the limit curves of the
//! levels from `z0` up go round the block (its section offset by R + s), those
//! below are the line `x = 4.5`. The material is the union of the half-space
//! `x >= 10` and the block, so the distance of a point of the pocket to it is
//! known exactly, independently of the flank mesh and of `BodyCheck`.
#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

mod common;
use common::floor;

use proptest::prelude::*;
use scallop_cutter::{Cutter, CutterShape};
use scallop_geom::{Point3, Vec3};
use scallop_mesh::{Polyline3, TriMesh};
use scallop_rough5::{
    BodyCheck, Placer, SyncPoint, TRANSLATION_MAX, correct_pairs_spatial, correct_spatial, limit_angular_step,
    pitch_angle,
};

/// The largest axis change between pairs (rad).
const STEP: f64 = 2.0 * std::f64::consts::PI / 180.0;
/// Tool radius R and flank allowance s of the limit curves.
const R: f64 = 5.0;
const S: f64 = 0.5;
/// Flank height (mm) and level spacing a_p.
const TOP: f64 = 30.0;
const AP: f64 = 4.0;

fn p(x: f64, y: f64, z: f64) -> Point3 {
    Point3::new(x, y, z)
}

/// A quad as two triangles.
fn quad(a: Point3, b: Point3, c: Point3, d: Point3) -> [[Point3; 3]; 2] {
    [[a, b, c], [a, c, d]]
}

/// The flank: the wall x = 10 and the block's front, sides and underside.
fn flank(w: f64, z0: f64) -> TriMesh {
    let mut tris = Vec::new();
    tris.extend(quad(p(10., -100., 0.), p(10., 100., 0.), p(10., 100., TOP), p(10., -100., TOP)));
    tris.extend(quad(p(6., -w, z0), p(6., w, z0), p(6., w, TOP), p(6., -w, TOP)));
    tris.extend(quad(p(6., w, z0), p(10., w, z0), p(10., w, TOP), p(6., w, TOP)));
    tris.extend(quad(p(6., -w, z0), p(10., -w, z0), p(10., -w, TOP), p(6., -w, TOP)));
    tris.extend(quad(p(6., -w, z0), p(10., -w, z0), p(10., w, z0), p(6., w, z0)));
    TriMesh::from_soup(&tris).unwrap().0
}

/// Exact distance from a point of the pocket to the material.
fn to_material(q: &Point3, w: f64, z0: f64) -> f64 {
    let wall = (10.0 - q.x).max(0.0);
    let block = Vec3::new((6.0 - q.x).max(0.0), (q.y.abs() - w).max(0.0), (z0 - q.z).max(0.0)).norm();
    wall.min(block)
}

/// The limit curve of the level at height `z`: the flank's section there
/// offset by R + s (arcs every half degree round the block's edges).
fn limit_curve(z: f64, w: f64, z0: f64) -> Polyline3 {
    let d = R + S;
    let x = 10.0 - d;
    if z < z0 {
        return Polyline3::new(vec![p(x, -60., z), p(x, 60., z)], false);
    }
    let end = (x - 6.0) / d; // cos of the arcs' end angles
    let phi1 = end.acos(); // from +x, where the arc meets x = 4.5
    let mut pts = vec![p(x, -60., z)];
    let n = 180;
    for k in 0..=n {
        let f = -phi1 - (std::f64::consts::PI - phi1) * f64::from(k) / f64::from(n);
        pts.push(p(6.0 + d * f.cos(), -w + d * f.sin(), z));
    }
    for k in 0..=n {
        let f = std::f64::consts::PI - (std::f64::consts::PI - phi1) * f64::from(k) / f64::from(n);
        pts.push(p(6.0 + d * f.cos(), w + d * f.sin(), z));
    }
    pts.push(p(x, 60., z));
    Polyline3::new(pts, false)
}

/// The limit curves of the levels above the pass's (z = a_p, 2 a_p, ...).
fn upper(w: f64, z0: f64) -> Vec<Polyline3> {
    (1..).map(|k| f64::from(k) * AP).take_while(|&z| z < TOP).map(|z| limit_curve(z, w, z0)).collect()
}

fn torus() -> Cutter {
    Cutter::new(CutterShape::Bull { radius: R, corner: 1.5 }, TOP).unwrap()
}

/// A pair of the limit pass of the level z = 0 travelling along +y, its tilt
/// point on the level above.
fn pair(at: Point3, axis: Vec3) -> SyncPoint {
    let axis = axis.normalize();
    SyncPoint { path: at, tilt: Some(at + axis * (AP / axis.z)), normal: Vec3::z(), tangent: Vec3::y(), axis }
}

/// Whether the tool placed at pair `s` keeps its radius from the material at
/// every height of its flutes above the corner (every 0.1 mm), measured
/// against the exact solid; `None` when it cannot be placed.
fn clears_exactly(placer: &Placer, s: &SyncPoint, w: f64, z0: f64) -> Option<bool> {
    let t = placer.place(&s.path, &s.axis)?;
    Some((15..=10 * TOP as usize).all(|k| to_material(&(t.tip + t.axis * (k as f64 * 0.1)), w, z0) >= R - 1e-9))
}

fn collides(placer: &Placer, body: &BodyCheck, s: &SyncPoint) -> bool {
    placer.place(&s.path, &s.axis).is_none_or(|t| body.collides(&t.tip, &t.axis))
}

/// Cause (a) at the end of the block: the vertical tool of the limit pass
/// 2 mm past the block's edge (y = 8, the block |y| <= 6 from z = 16 up)
/// meets the block's edge. Without step 2 it intrudes 2.625 mm: more than the
/// axis translation may move it (step 3 would drop it). With step 2 its axis
/// passes through the point of the limit curve at z = 16 closest to it, on
/// the arc round the edge: leaning away from the block and ahead along the
/// feed, so its pitch angle goes from 0 to atan2(2.4, 16) and its tool clears
/// the block (by `BodyCheck` and against the exact solid).
#[test]
fn a_tool_under_a_bulging_flank_is_turned_through_the_limit_curve_above() {
    let (w, z0) = (6.0, 16.0);
    let (level, cutter) = (floor(), torus());
    let placer = Placer::new(&level, &cutter, 0.0).unwrap();
    let body = BodyCheck::new(&flank(w, z0), &cutter, 0.0);
    let s = pair(p(4.5, 8.0, 0.0), Vec3::z());
    let placed = placer.place(&s.path, &s.axis).unwrap();
    let (deficit, _) = body.intrusion(&placed.tip, &placed.axis).expect("the vertical tool meets the block");
    // sqrt(1.5^2 + 2^2) = 2.5 mm from the edge, 5.125 needed (R and half the sample step).
    assert!((deficit - 2.625).abs() < 0.02, "deficit {deficit}");
    assert!(deficit + 0.05 > TRANSLATION_MAX, "step 3 alone would clear it");
    assert_eq!(clears_exactly(&placer, &s, w, z0), Some(false));

    let c = correct_spatial(&placer, &body, &s, &upper(w, z0)).expect("the limit curve at z = 16 gives a free axis");
    assert!(!collides(&placer, &body, &c));
    assert_eq!(clears_exactly(&placer, &c, w, z0), Some(true));
    // The candidate: the arc point of the level z = 16 closest to the axis,
    // (6, 6) + 5.5 (-1.5, 2) / 2.5 = (2.7, 10.4).
    let q = c.tilt.unwrap();
    assert!((q - p(2.7, 10.4, 16.0)).norm() < 0.01, "tilt point {q:?}");
    assert!((c.axis - (q - c.path).normalize()).norm() < 1e-12 && c.path == s.path);
    let pitch = pitch_angle(&c.axis, &c.tangent, &c.normal);
    assert!(pitch_angle(&s.axis, &s.tangent, &s.normal).abs() < 1e-12);
    assert!((pitch - 2.4f64.atan2(16.0)).abs() < 1e-3, "pitch {} deg", pitch.to_degrees());
    // Away from the block: towards -x and +y.
    assert!(c.axis.x < 0.0 && c.axis.y > 0.0);
    // The levels above z = 16 give the same point higher up: a smaller lean
    // whose tool still meets the edge; the levels below, the pair's own axis.
    let higher = pair(p(4.5, 8.0, 0.0), p(2.7, 10.4, 20.0) - p(4.5, 8.0, 0.0));
    assert!(collides(&placer, &body, &higher));
}

/// A free pair and a pair without a tilt point are left alone.
#[test]
fn free_and_untilted_pairs_are_not_corrected() {
    let (w, z0) = (6.0, 16.0);
    let (level, cutter) = (floor(), torus());
    let placer = Placer::new(&level, &cutter, 0.0).unwrap();
    let body = BodyCheck::new(&flank(w, z0), &cutter, 0.0);
    let free = pair(p(4.5, 30.0, 0.0), Vec3::z());
    assert!(!collides(&placer, &body, &free));
    assert!(correct_spatial(&placer, &body, &free, &upper(w, z0)).is_none());
    let untilted = SyncPoint { tilt: None, ..pair(p(4.5, 8.0, 0.0), Vec3::z()) };
    assert!(collides(&placer, &body, &untilted));
    assert!(correct_spatial(&placer, &body, &untilted, &upper(w, z0)).is_none());
}

proptest! {
    /// Every pose the spatial correction returns clears the flank (by the
    /// planner's check and against the exact solid at every 0.1 mm of its
    /// flutes) or, when no candidate clears it, intrudes less than the pose
    /// it replaces (left to step 3, which the planner reports); its axis runs
    /// from P_T through its tilt point, which lies on one of the upper limit
    /// curves.
    #[test]
    fn every_corrected_pose_is_collision_free(
        w in 3.0f64..10.0,
        z0k in 2usize..5,
        y in -20.0f64..20.0,
        x in 3.0f64..4.5,
        lean in (-0.15f64..0.15, -0.15f64..0.15),
    ) {
        let z0 = z0k as f64 * AP;
        let (level, cutter) = (floor(), torus());
        let placer = Placer::new(&level, &cutter, 0.0).unwrap();
        let body = BodyCheck::new(&flank(w, z0), &cutter, 0.0);
        let s = pair(p(x, y, 0.0), Vec3::new(lean.0, lean.1, 1.0));
        prop_assume!(collides(&placer, &body, &s));
        let curves = upper(w, z0);
        if let Some(c) = correct_spatial(&placer, &body, &s, &curves) {
            let deficit = |s: &SyncPoint| {
                let t = placer.place(&s.path, &s.axis).unwrap();
                body.intrusion(&t.tip, &t.axis).map_or(0.0, |d| d.0)
            };
            if collides(&placer, &body, &c) {
                // No candidate cleared: the one kept intrudes less (step 3's part).
                prop_assert!(deficit(&c) < deficit(&s), "{} -> {}", deficit(&s), deficit(&c));
            } else {
                prop_assert_eq!(clears_exactly(&placer, &c, w, z0), Some(true));
            }
            let q = c.tilt.unwrap();
            prop_assert!((c.axis - (q - c.path).normalize()).norm() < 1e-12);
            let on_curve = curves.iter().any(|l| {
                l.points.windows(2).any(|ab| {
                    let (a, b) = (ab[0], ab[1]);
                    let t = ((q - a).dot(&(b - a)) / (b - a).norm_squared()).clamp(0.0, 1.0);
                    (a + (b - a) * t - q).norm() < 1e-9
                })
            });
            prop_assert!(on_curve, "tilt point {:?} off the curves", q);
        }
    }
}

/// The limit pass along the wall, vertical axes every 1 mm: the pairs under
/// the block and past its ends collide. The correction loop of the planner
/// (correct, limit the angular step again, at most 3 rounds) turns them
/// through the limit curves above (the pairs between them lean in): no pair
/// collides any more, every pair clears the exact solid, and no two
/// consecutive axes differ by more than the angular step.
#[test]
fn a_pass_under_the_block_is_corrected_and_keeps_the_angular_step() {
    let (w, z0) = (6.0, 16.0);
    let (level, cutter) = (floor(), torus());
    let placer = Placer::new(&level, &cutter, 0.0).unwrap();
    let body = BodyCheck::new(&flank(w, z0), &cutter, 0.0);
    let curves = upper(w, z0);
    let pass: Vec<SyncPoint> = (-30..=30).map(|k| pair(p(4.5, f64::from(k), 0.0), Vec3::z())).collect();
    let before = pass.iter().filter(|s| collides(&placer, &body, s)).count();
    assert!(before > 20, "{before} pairs collide");
    let mut pairs = pass.clone();
    let mut corrected = 0;
    for _ in 0..3 {
        let (turned, count) = correct_pairs_spatial(&placer, &body, &pairs, &curves, STEP);
        if count.corrected == 0 {
            break;
        }
        corrected += count.corrected;
        pairs = limit_angular_step(&turned, STEP, 5f64.to_radians());
    }
    assert!(corrected >= before, "{corrected} of {before}");
    let after = pairs.iter().filter(|s| collides(&placer, &body, s)).count();
    assert_eq!(after, 0, "{after} pairs still collide");
    for (k, s) in pairs.iter().enumerate() {
        assert_eq!(clears_exactly(&placer, s, w, z0), Some(true), "pair {k}");
        if k > 0 {
            let turn = s.axis.angle(&pairs[k - 1].axis);
            assert!(turn <= STEP + 1e-9, "pairs {} and {k} differ by {} deg", k - 1, turn.to_degrees());
        }
    }
    assert_eq!(pairs.first().map(|s| s.axis), Some(Vec3::z()));
    assert_eq!(pairs.last().map(|s| s.axis), Some(Vec3::z()));
}
