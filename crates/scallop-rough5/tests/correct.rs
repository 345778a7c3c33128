//! The collision correction (Jousselin 2020, Ch. 3 §3, step 1, Eq. 3.31): a
//! colliding axis is turned in its correction plane to a free one, with the
//! pitch angle kept; a free pair is left alone; a pair with no free axis in
//! its plane is not corrected.
#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

mod common;
use common::floor;

use proptest::prelude::*;
use scallop_cutter::{Cutter, CutterShape};
use scallop_geom::{Point3, Vec3};
use scallop_mesh::TriMesh;
use scallop_rough5::{BodyCheck, Placer, SyncPoint, correct_pairs, correct_planar, pitch_angle};

/// The largest axis change between pairs (rad).
const STEP: f64 = 2.0 * std::f64::consts::PI / 180.0;

fn p(x: f64, y: f64, z: f64) -> Point3 {
    Point3::new(x, y, z)
}

/// Vertical walls `x = c` for each c, 40 mm high, 200 mm long.
fn walls(xs: &[f64]) -> TriMesh {
    let tris: Vec<[Point3; 3]> = xs
        .iter()
        .flat_map(|&c| {
            [[p(c, -100., 0.), p(c, 100., 0.), p(c, 100., 40.)], [p(c, -100., 0.), p(c, 100., 40.), p(c, -100., 40.)]]
        })
        .collect();
    TriMesh::from_soup(&tris).unwrap().0
}

fn torus() -> Cutter {
    Cutter::new(CutterShape::Bull { radius: 5.0, corner: 1.5 }, 30.0).unwrap()
}

fn pair(at: Point3, axis: Vec3) -> SyncPoint {
    let axis = axis.normalize();
    SyncPoint { path: at, tilt: Some(at + axis * 6.0), normal: Vec3::z(), tangent: Vec3::y(), axis }
}

fn collides(placer: &Placer, body: &BodyCheck, s: &SyncPoint) -> bool {
    placer.place(&s.path, &s.axis).is_none_or(|t| body.collides(&t.tip, &t.axis))
}

proptest! {
    /// A tool leaning towards a wall is turned clear of it, in the plane that
    /// keeps its pitch, and leans towards the wall no more than before.
    #[test]
    fn a_leaning_tool_is_turned_clear(
        x in -2.0f64..2.0,
        lean in 0.25f64..0.8,
        pitch in -0.3f64..0.3,
    ) {
        let (level, flanks, cutter) = (floor(), walls(&[10.0]), torus());
        let placer = Placer::new(&level, &cutter, 0.0).unwrap();
        let body = BodyCheck::new(&flanks, &cutter, 0.0);
        let s = pair(p(x, 0.0, 0.0), Vec3::new(lean, pitch, 1.0));
        prop_assume!(collides(&placer, &body, &s));
        let c = correct_planar(&placer, &body, &s).expect("a vertical tool is free, so the plane has a free axis");
        prop_assert!(!collides(&placer, &body, &c));
        let before = pitch_angle(&s.axis, &s.tangent, &s.normal);
        let after = pitch_angle(&c.axis, &c.tangent, &c.normal);
        prop_assert!((before - after).abs() < 1e-9, "pitch {before} -> {after}");
        prop_assert!(c.axis.x < s.axis.x, "the axis still leans towards the wall: {} -> {}", s.axis.x, c.axis.x);
        prop_assert!((c.axis.norm() - 1.0).abs() < 1e-12);
        let d = c.tilt.unwrap() - c.path;
        prop_assert!((d.normalize() - c.axis).norm() < 1e-9 && (d.norm() - 6.0).abs() < 1e-9);
    }
}

#[test]
fn free_pairs_are_left_alone_and_a_blocked_plane_is_not_corrected() {
    let (level, cutter) = (floor(), torus());
    let placer = Placer::new(&level, &cutter, 0.0).unwrap();
    let open = BodyCheck::new(&walls(&[20.0]), &cutter, 0.0);
    let free = pair(p(0.0, 0.0, 0.0), Vec3::new(0.1, 0.05, 1.0));
    assert!(!collides(&placer, &open, &free));
    let (out, count) = correct_pairs(&placer, &open, &[free], STEP);
    assert_eq!(out, vec![free]);
    assert_eq!((count.colliding, count.corrected), (0, 0));
    // Walls 9 mm on either side of a 10 mm tool's axis path, leaning 30
    // degrees: the vertical tool clears them but the leaning one does not.
    let channel = BodyCheck::new(&walls(&[-9.0, 9.0]), &cutter, 0.0);
    let leaning = pair(p(0.0, 0.0, 0.0), Vec3::new(0.58, 0.0, 1.0));
    let (out, count) = correct_pairs(&placer, &channel, &[leaning], STEP);
    assert_eq!((count.colliding, count.corrected), (1, 1));
    assert!(!collides(&placer, &channel, &out[0]));
    // Walls 5 mm away: every axis of the plane touches one of them.
    let blocked = BodyCheck::new(&walls(&[-5.0, 5.0]), &cutter, 0.0);
    assert!(correct_planar(&placer, &blocked, &leaning).is_none());
    let (out, count) = correct_pairs(&placer, &blocked, &[leaning], STEP);
    assert_eq!(out, vec![leaning]);
    assert_eq!((count.colliding, count.corrected), (1, 0));
    // Without a tilt point (a level cut with the axis +Z) the axis is kept.
    let untilted = SyncPoint { tilt: None, ..leaning };
    assert!(correct_planar(&placer, &channel, &untilted).is_none());
}

/// A pass along a wall with a step towards it (x = 8 mm for |y| <= 10 mm,
/// 14 mm from |y| = 11 mm on): the pairs next to the step are corrected, their
/// neighbours lean in ahead of them, so no pair of the pass collides and no
/// two consecutive axes differ by more than the angular step.
#[test]
fn neighbours_lean_in_ahead_of_a_correction() {
    let (level, cutter) = (floor(), torus());
    let placer = Placer::new(&level, &cutter, 0.0).unwrap();
    let profile = [(-100.0, 14.0), (-11.0, 14.0), (-10.0, 8.0), (10.0, 8.0), (11.0, 14.0), (100.0, 14.0)];
    let tris: Vec<[Point3; 3]> = profile
        .windows(2)
        .flat_map(|w| {
            let ((y0, x0), (y1, x1)) = (w[0], w[1]);
            [[p(x0, y0, 0.), p(x1, y1, 0.), p(x1, y1, 25.)], [p(x0, y0, 0.), p(x1, y1, 25.), p(x0, y0, 25.)]]
        })
        .collect();
    let body = BodyCheck::new(&TriMesh::from_soup(&tris).unwrap().0, &cutter, 0.0);
    let pass: Vec<SyncPoint> = (-45..=45).map(|k| pair(p(0.0, f64::from(k), 0.0), Vec3::new(0.3, 0.1, 1.0))).collect();
    let before = pass.iter().filter(|s| collides(&placer, &body, s)).count();
    assert!(before > 0 && before < pass.len());
    let (out, count) = correct_pairs(&placer, &body, &pass, STEP);
    assert_eq!((count.colliding, count.corrected), (before, before));
    assert!(count.leaned_in > 0);
    for (k, s) in out.iter().enumerate() {
        assert!(!collides(&placer, &body, s), "pair {k} collides");
        let pitch = |s: &SyncPoint| pitch_angle(&s.axis, &s.tangent, &s.normal);
        assert!((pitch(s) - pitch(&pass[k])).abs() < 1e-9);
        assert!(s.axis.x <= pass[k].axis.x + 1e-12, "pair {k} leans further towards the wall");
        if k > 0 {
            let turn = s.axis.angle(&out[k - 1].axis);
            assert!(turn <= STEP + 1e-9, "pairs {} and {k} differ by {turn} rad", k - 1);
        }
    }
    assert_eq!(out.first(), pass.first());
    assert_eq!(out.last(), pass.last());
}
