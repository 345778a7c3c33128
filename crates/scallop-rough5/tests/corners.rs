//! Rounded corners of the vertical stretches (docs/rough5.md, "Corners and
//! blocks"): the convex corners of inner passes get fillets whose chords turn
//! by less than the time model's smooth junction, the fillets stay inside the
//! ring, and the tool on the rounded rings covers everything the tool on the
//! sharp rings covered.
#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

mod common;

use proptest::prelude::*;
use scallop_geom::{Point3, Vec3};
use scallop_parts::{PocketParams, closed_pocket};
use scallop_rough5::{Rough5Settings, SyncPoint, plan_rough5, round_corners, tol};
use scallop_toolpath::MoveKind;

/// A closed counter-clockwise ring of vertical pairs through the corners
/// `c`, each side cut every `step` mm.
fn ring(c: &[[f64; 2]], step: f64) -> Vec<SyncPoint> {
    let mut out = Vec::new();
    for k in 0..c.len() {
        let (a, b) = (c[k], c[(k + 1) % c.len()]);
        let len = (b[0] - a[0]).hypot(b[1] - a[1]);
        let n = (len / step).ceil().max(1.0) as usize;
        let t = Vec3::new((b[0] - a[0]) / len, (b[1] - a[1]) / len, 0.0);
        for i in 0..n {
            let w = i as f64 / n as f64;
            let path = Point3::new(a[0] + (b[0] - a[0]) * w, a[1] + (b[1] - a[1]) * w, 10.0);
            out.push(SyncPoint { path, tilt: None, normal: Vec3::z(), tangent: t, axis: Vec3::z() });
        }
    }
    // Closed: the start, halfway along the first side, again at the end.
    let half = out.len() / (2 * c.len()).max(1);
    out.rotate_left(half);
    out.push(out[0]);
    out
}

/// A rectangle's corners, counter-clockwise, `(w, h)` around `(x, y)`.
fn rect(x: f64, y: f64, w: f64, h: f64) -> Vec<[f64; 2]> {
    vec![[x - w / 2.0, y - h / 2.0], [x + w / 2.0, y - h / 2.0], [x + w / 2.0, y + h / 2.0], [x - w / 2.0, y + h / 2.0]]
}

/// Largest turn (rad) between consecutive segments of `pairs` in plan.
fn largest_turn(pairs: &[SyncPoint]) -> f64 {
    pairs
        .windows(3)
        .map(|w| {
            let (a, b) = (w[1].path - w[0].path, w[2].path - w[1].path);
            if a.norm() < 1e-9 || b.norm() < 1e-9 { 0.0 } else { a.angle(&b) }
        })
        .fold(0.0, f64::max)
}

/// Distance in plan from `p` to the polyline of `pairs`.
fn distance(p: [f64; 2], pairs: &[SyncPoint]) -> f64 {
    pairs
        .windows(2)
        .map(|w| {
            let (a, b) = ([w[0].path.x, w[0].path.y], [w[1].path.x, w[1].path.y]);
            let ab = [b[0] - a[0], b[1] - a[1]];
            let l2 = ab[0] * ab[0] + ab[1] * ab[1];
            let t = if l2 > 0.0 { (((p[0] - a[0]) * ab[0] + (p[1] - a[1]) * ab[1]) / l2).clamp(0.0, 1.0) } else { 0.0 };
            (p[0] - a[0] - ab[0] * t).hypot(p[1] - a[1] - ab[1] * t)
        })
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn a_small_ring_gets_its_fillets() {
    let pairs = ring(&rect(46.0, 53.7, 9.7, 7.9), 1.0);
    let out = round_corners(pairs.clone(), 4.0, 0.05, 1.5);
    let junction = scallop_geom::tol::machine::SMOOTH_JUNCTION;
    assert!(largest_turn(&pairs) > 1.5);
    assert!(largest_turn(&out) < junction, "{}", largest_turn(&out).to_degrees());
    assert_eq!(out.first().unwrap().path, out.last().unwrap().path);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, failure_persistence: None, ..ProptestConfig::default() })]

    /// Concentric rectangular rings a_e apart (the inner passes of a level),
    /// each rounded with the fillet of 0.8 R, R the tool radius, a_e <= R:
    /// every chord turns by less than the time model's smooth junction, every point of
    /// a rounded ring lies inside its sharp ring, and every point within R of
    /// a sharp ring is within R of a rounded ring or of the outermost
    /// (unrounded, the limit pass).
    #[test]
    fn rounded_rings_cover_what_the_sharp_rings_covered(
        w in 8.0f64..30.0,
        h in 8.0f64..30.0,
        rings in 2usize..5,
        ae_share in 0.5f64..1.0,
        step in 0.5f64..2.0,
    ) {
        let r = 5.0;
        let ae = ae_share * r;
        let sharp: Vec<Vec<SyncPoint>> =
            (0..rings).map(|k| ring(&rect(50.0, 50.0, w + 2.0 * ae * k as f64, h + 2.0 * ae * k as f64), step)).collect();
        let junction = scallop_geom::tol::machine::SMOOTH_JUNCTION;
        let rounded: Vec<Vec<SyncPoint>> = sharp
            .iter()
            .enumerate()
            .map(|(k, p)| if k + 1 < rings { round_corners(p.clone(), tol::CORNER_FILLET_RADII * r, 0.05, 1.5 * step) } else { p.clone() })
            .collect();
        for (k, p) in rounded.iter().enumerate().take(rings - 1) {
            prop_assert!(largest_turn(p) < junction, "ring {}: {}", k, largest_turn(p).to_degrees());
            let (hw, hh) = ((w + 2.0 * ae * k as f64) / 2.0, (h + 2.0 * ae * k as f64) / 2.0);
            for s in p {
                prop_assert!((s.path.x - 50.0).abs() <= hw + 1e-9 && (s.path.y - 50.0).abs() <= hh + 1e-9);
                prop_assert_eq!(s.axis, Vec3::z());
            }
        }
        let (hw, hh) = ((w + 2.0 * ae * rings as f64) / 2.0 + r, (h + 2.0 * ae * rings as f64) / 2.0 + r);
        let n = 120;
        for i in 0..=n {
            for j in 0..=n {
                let p = [50.0 - hw + 2.0 * hw * i as f64 / n as f64, 50.0 - hh + 2.0 * hh * j as f64 / n as f64];
                let before = sharp.iter().any(|s| distance(p, s) <= r);
                let after = rounded.iter().any(|s| distance(p, s) <= r + 1e-9);
                prop_assert!(!before || after, "({:.2}, {:.2}) is no longer covered", p[0], p[1]);
            }
        }
    }
}

/// On a 60 x 60 x 20 mm pocket with the rounded corners on, a link between
/// two passes whose tool stays vertical and whose points lie within the
/// thinning's chord of the straight line is one block (it was written in
/// pieces of `--step`, the points the link was checked at); without, it is
/// in pieces, and the program is the same but for those links.
#[test]
fn straight_vertical_links_are_one_block() {
    let part = closed_pocket(&PocketParams { dome: 1.0, ..common::small_pocket(20.0, 6.0) }).unwrap();
    let (bottom, flanks, depth) = common::bottom_flanks(&part);
    let tool = common::torus(20.0, 100.0);
    let s = common::settings(depth);
    let chord = tol::THIN_CHORD_ALLOWANCES * s.guides.flank_allowance;
    let pieces = |on: bool| {
        let s = Rough5Settings { round_corners: on, ..s };
        let path = plan_rough5(&bottom, &flanks, &part.stock, &tool, &s, &|_, _| {}).unwrap().toolpath;
        let moves = path.moves();
        // Every run of links between two cutting moves: its moves, all vertical and within the chord?
        let mut runs = Vec::new();
        let mut i = 1;
        while i < moves.len() {
            if moves[i].kind != MoveKind::Link || moves[i - 1].kind != MoveKind::Feed {
                i += 1;
                continue;
            }
            let start = i - 1;
            while i < moves.len() && moves[i].kind == MoveKind::Link {
                i += 1;
            }
            if i < moves.len() && moves[i].kind == MoveKind::Feed {
                let (a, b) = (moves[start].to, moves[i - 1].to);
                let ab = b - a;
                let straight = (start..i).all(|k| {
                    let t = ((moves[k].to - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
                    (moves[k].to - (a + ab * t)).norm() <= chord && path.axis(k).angle(&Vec3::z()) <= 1e-12
                });
                if straight {
                    runs.push(i - 1 - start);
                }
            }
        }
        runs
    };
    let (on, off) = (pieces(true), pieces(false));
    assert!(!on.is_empty() && on.iter().all(|&n| n == 1), "{on:?}");
    assert!(off.iter().any(|&n| n > 1), "{off:?}");
}
