//! Air moves (docs/rough5.md, "Air moves"): a move classified as air lies
//! outside the in-process stock by the clearance (analytic cases on a block,
//! with and without earlier cuts; property test), one well clear of it is
//! classified as air, a long entry is cut where it enters the stock, the
//! proof refuses an air move that cuts, and the closed pocket's program with
//! its air moves is proven and no slower at the programmed feeds.

#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

mod common;

use proptest::prelude::*;
use scallop_cutter::Cutter;
use scallop_geom::{Aabb3, Point3, Vec3};
use scallop_mesh::TriMesh;
use scallop_parts::closed_pocket;
use scallop_rough5::{
    AIR_CHUNK, AirSettings, ProofSettings, Rough5Settings, air_moves, is_air_move, plan_rough5, prove,
};
use scallop_toolpath::{Move, MoveKind, Toolpath};

/// The block [0, 40] x [0, 40] x [0, 20].
fn block() -> Aabb3 {
    Aabb3 { min: Point3::new(0.0, 0.0, 0.0), max: Point3::new(40.0, 40.0, 20.0) }
}

/// The closed mesh of a box, normals out.
fn box_mesh(b: &Aabb3) -> TriMesh {
    let c = |i: usize| {
        Point3::new(
            if i & 1 == 0 { b.min.x } else { b.max.x },
            if i & 2 == 0 { b.min.y } else { b.max.y },
            if i & 4 == 0 { b.min.z } else { b.max.z },
        )
    };
    // Each face's corners counter-clockwise seen from outside.
    let faces = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let soup: Vec<[Point3; 3]> =
        faces.iter().flat_map(|f| [[c(f[0]), c(f[1]), c(f[2])], [c(f[0]), c(f[2]), c(f[3])]]).collect();
    TriMesh::from_soup(&soup).unwrap().0
}

fn air(feed: f64) -> AirSettings {
    AirSettings { feed, clearance: 1.0, resolution: 0.5, axis_tolerance: 0.05 }
}

/// Tool R 5 r 1.5, 30 mm of flutes, axis +Z.
fn tool() -> Cutter {
    common::torus(30.0, 100.0)
}

/// A path at 2400 mm/min from a rapid to `start`, then the feed moves to `points`.
fn path_through(start: Point3, points: &[Point3]) -> Toolpath {
    let mut path = Toolpath::new(2400.0);
    path.push(Move::new(MoveKind::Rapid, start));
    for p in points {
        path.push(Move::new(MoveKind::Feed, *p));
    }
    path
}

/// Feed moves every 1 mm from `a` to `b`.
fn line(a: Point3, b: Point3) -> Vec<Point3> {
    let n = (b - a).norm().ceil().max(1.0) as usize;
    (1..=n).map(|k| a + (b - a) * (k as f64 / n as f64)).collect()
}

/// One straight feed move at height `z` beside or above the block, `gap` mm
/// from it (the tool's side from the block's +x face, or its tip above the
/// block's top), and one a millimetre deep into the block: the first is air
/// exactly when the gap exceeds the clearance (by more than the rays'
/// spacing), the second never is.
#[test]
fn a_move_beside_or_above_the_block_is_air_by_its_clearance() {
    let tool = tool();
    for gap in [0.25, 0.5, 1.75, 2.5, 4.0] {
        let beside = 45.0 + gap;
        let above = 20.0 + gap;
        let cases = [
            (Point3::new(beside, -10.0, 5.0), Point3::new(beside, 50.0, 5.0)),
            (Point3::new(-10.0, 20.0, above), Point3::new(50.0, 20.0, above)),
        ];
        for (a, b) in cases {
            let path = path_through(a, &[b, Point3::new(b.x, b.y, 19.0), Point3::new(20.0, 20.0, 19.0)]);
            let found = air_moves(&path, &tool, (&block(), None), &air(30_000.0)).unwrap();
            let out = &found.toolpath;
            if gap > 1.5 {
                // The long move along the block's side is one air move (its pieces joined).
                assert!(is_air_move(out, 1) && out.moves()[1].to == b, "gap {gap}: {:?}", out.moves());
            }
            // Every air move keeps the tool's cylinder (R 5 from the tip up,
            // which holds the torus) 0.5 mm (the clearance less the rays'
            // spacing) from the block, sampled every 0.25 mm.
            let to_block = |p: &Point3| {
                let dx = (0.0 - p.x).max(p.x - 40.0).max(0.0);
                let dy = (0.0 - p.y).max(p.y - 40.0).max(0.0);
                (dx.hypot(dy) - 5.0).max(0.0).hypot((p.z - 20.0).max(0.0))
            };
            for i in 1..out.moves().len() {
                if is_air_move(out, i) {
                    let (p0, p1) = (out.moves()[i - 1].to, out.moves()[i].to);
                    let n = ((p1 - p0).norm() / 0.25).ceil() as usize;
                    for k in 0..=n {
                        let p = p0 + (p1 - p0) * (k as f64 / n.max(1) as f64);
                        assert!(to_block(&p) >= 0.5, "gap {gap}: move {i} at {p:?}, {} from the block", to_block(&p));
                    }
                }
            }
            // Within the clearance the move's pieces beside the block are cut at the feed.
            if gap < 0.75 {
                assert!(out.moves().iter().enumerate().any(|(i, m)| to_block(&m.to) < 1.0 && !is_air_move(out, i)));
            }
            // The move into the block is cut where it enters: its last piece is not air.
            let last = out.moves().len() - 1;
            assert!(!is_air_move(out, last), "gap {gap}");
        }
    }
}

/// A pocket cleared by a raster at z = 10 (tool centres over [12, 28]^2,
/// the cleared floor over [7, 33]^2), then moves inside it: 2 mm over the
/// floor and 10 mm from every wall they are air, although the block was
/// there before the raster; 0.5 mm over the floor they are not.
#[test]
fn a_move_in_a_cleared_pocket_is_air_and_one_near_its_floor_is_not() {
    let tool = tool();
    let start = Point3::new(-10.0, 12.0, 10.0);
    let mut points = Vec::new();
    let mut from = start;
    for k in 0..=8 {
        let y = 12.0 + 2.0 * f64::from(k);
        let (x0, x1) = if k % 2 == 0 { (12.0, 28.0) } else { (28.0, 12.0) };
        points.extend(line(from, Point3::new(x0, y, 10.0)));
        points.extend(line(Point3::new(x0, y, 10.0), Point3::new(x1, y, 10.0)));
        from = Point3::new(x1, y, 10.0);
    }
    assert!(points.len() > 2 * AIR_CHUNK);
    let raster = points.len();
    points.extend(line(from, Point3::new(20.0, 15.0, 12.0)));
    let inside = points.len();
    points.extend(line(Point3::new(20.0, 15.0, 12.0), Point3::new(20.0, 25.0, 12.0)));
    let low = points.len();
    points.extend(line(Point3::new(20.0, 25.0, 12.0), Point3::new(20.0, 25.0, 10.5)));
    points.extend(line(Point3::new(20.0, 25.0, 10.5), Point3::new(20.0, 15.0, 10.5)));
    let path = path_through(start, &points);
    let found = air_moves(&path, &tool, (&block(), None), &air(30_000.0)).unwrap();
    let out = &found.toolpath;
    // No move was split (all 1 mm or shorter): indices are the input's.
    assert_eq!(out.moves().len(), path.moves().len());
    // The run 2 mm over the floor: air once a chunk starts after the raster
    // (a chunk sees the stock before it).
    let clear = (inside + 1..=low).filter(|&i| is_air_move(out, i)).count();
    assert!(low - inside >= 10);
    assert!(2 * clear >= low - inside, "the run over the floor: {clear} of {} moves air", low - inside);
    // 0.5 mm over the floor: within the clearance.
    assert!((low + 2..out.moves().len()).all(|i| !is_air_move(out, i)));
    assert!((1..raster).all(|i| !is_air_move(out, i) || out.moves()[i].to.x < -4.0), "the raster cuts");
    // Every air move is proven as a rapid.
    let proof = ProofSettings { resolution: 0.5, axis_tolerance: 0.05 };
    let stock = block();
    let volume = box_mesh(&stock);
    prove(out, &tool, &stock, &volume, &proof, &|_, _| {}).unwrap();
}

/// A feed move that cuts, written at the air feed, is refused by the proof
/// as a rapid into the stock.
#[test]
fn the_proof_refuses_an_air_move_that_cuts() {
    let tool = tool();
    let mut path = Toolpath::new(2400.0);
    path.push(Move::new(MoveKind::Rapid, Point3::new(-10.0, 20.0, 18.0)));
    path.set_feed_from(Some(30_000.0));
    path.push(Move::new(MoveKind::Feed, Point3::new(50.0, 20.0, 18.0)));
    path.set_feed_from(None);
    assert!(is_air_move(&path, 1));
    let stock = block();
    let proof = ProofSettings { resolution: 0.5, axis_tolerance: 0.05 };
    let err = prove(&path, &tool, &stock, &box_mesh(&stock), &proof, &|_, _| {}).unwrap_err();
    assert!(err.to_string().contains("rapid"), "{err}");
    // At the cutting feed it is a cut.
    let mut cut = Toolpath::new(2400.0);
    cut.push(Move::new(MoveKind::Rapid, Point3::new(-10.0, 20.0, 18.0)));
    cut.push(Move::new(MoveKind::Feed, Point3::new(50.0, 20.0, 18.0)));
    prove(&cut, &tool, &stock, &box_mesh(&stock), &proof, &|_, _| {}).unwrap();
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// After a slot is cut across the block, the tool comes over it from
    /// above (rapids at z = 40), plunges to a random point and feeds to
    /// another, its axis tilted up to 20 deg: up to the first piece of them
    /// that cuts, every piece classified as air has the tool (sampled every 0.25 mm along the move, on
    /// its lowest circle, its corner's equator and up its flutes) keeps at
    /// least the clearance less the rays' spacing from the block outside the
    /// slot (the slot taken as the whole box the tool's cylinder swept, less
    /// material than the true stock, whose corners the torus leaves).
    #[test]
    fn an_air_move_keeps_its_clearance_from_the_stock(
        a in (-15.0..55.0f64, -15.0..55.0f64, 8.0..30.0f64),
        b in (-15.0..55.0f64, -15.0..55.0f64, 8.0..30.0f64),
        tilt in 0.0..20f64,
        azimuth in 0.0..360f64,
    ) {
        let tool = tool();
        // The slot: tool centres along y = 20 at z = 12 across the block.
        let mut path = path_through(
            Point3::new(-10.0, 20.0, 12.0),
            &line(Point3::new(-10.0, 20.0, 12.0), Point3::new(50.0, 20.0, 12.0)),
        );
        let (t, w) = (tilt.to_radians(), azimuth.to_radians());
        let axis = Vec3::new(t.sin() * w.cos(), t.sin() * w.sin(), t.cos());
        path.push(Move::new(MoveKind::Rapid, Point3::new(50.0, 20.0, 40.0)));
        path.push_with_axis(Move::new(MoveKind::Rapid, Point3::new(a.0, a.1, 40.0)), axis);
        path.push(Move::new(MoveKind::Plunge, Point3::new(a.0, a.1, a.2)));
        path.push(Move::new(MoveKind::Feed, Point3::new(b.0, b.1, b.2)));
        let found = air_moves(&path, &tool, (&block(), None), &air(30_000.0)).unwrap();
        let out = &found.toolpath;
        let outside_box = |p: &Point3, lo: Point3, hi: Point3| {
            Vec3::new(
                (lo.x - p.x).max(p.x - hi.x).max(0.0),
                (lo.y - p.y).max(p.y - hi.y).max(0.0),
                (lo.z - p.z).max(p.z - hi.z).max(0.0),
            )
            .norm()
        };
        // The block less the slot (|y - 20| < 5, z > 12) as three boxes.
        let to_stock = |p: &Point3| {
            [
                (Point3::new(0.0, 0.0, 0.0), Point3::new(40.0, 15.0, 20.0)),
                (Point3::new(0.0, 25.0, 0.0), Point3::new(40.0, 40.0, 20.0)),
                (Point3::new(0.0, 0.0, 0.0), Point3::new(40.0, 40.0, 12.0)),
            ]
            .iter()
            .map(|(lo, hi)| outside_box(p, *lo, *hi))
            .fold(f64::INFINITY, f64::min)
        };
        // The slot's 60 moves are kept as they are (none is longer than the split length).
        prop_assert_eq!(out.moves()[60].to, Point3::new(50.0, 20.0, 12.0));
        for i in 1..out.moves().len() {
            if !is_air_move(out, i) {
                // After the slot, the first piece that cuts changes the stock: the
                // block less the slot no longer describes it.
                if i > 60 && out.moves()[i].kind != MoveKind::Rapid {
                    break;
                }
                continue;
            }
            let axis = out.axis(i);
            let (u, v) = scallop_rough5::tool_frame(&axis);
            let (p0, p1) = (out.moves()[i - 1].to, out.moves()[i].to);
            let n = ((p1 - p0).norm() / 0.25).ceil().max(1.0) as usize;
            for k in 0..=n {
                let tip = p0 + (p1 - p0) * (k as f64 / n as f64);
                for j in 0..24 {
                    let w = std::f64::consts::TAU * f64::from(j) / 24.0;
                    let radial = u * w.cos() + v * w.sin();
                    for (rho, h) in [(0.0, 0.0), (3.5, 0.0), (5.0, 1.5), (5.0, 10.0), (5.0, 20.0), (5.0, 30.0)] {
                        let p = tip + radial * rho + axis * h;
                        prop_assert!(to_stock(&p) >= 0.5, "move {} at {:?}: {} (tip {:?} from {:?} to {:?}, rho {} h {})", i, p, to_stock(&p), tip, p0, p1, rho, h);
                    }
                }
            }
        }
    }
}

/// The closed pocket with its air moves: some moves are air, the program is
/// proven (its air moves checked as rapids) and takes no longer at the
/// programmed feeds than the same program without them.
#[test]
fn the_closed_pocket_with_air_moves_is_proven_and_no_slower() {
    let part = closed_pocket(&Default::default()).unwrap();
    let (bottom, flanks, depth) = common::bottom_flanks(&part);
    let tool = common::torus(30.0, 100.0);
    let s = Rough5Settings { air: Some(air(30_000.0)), ..common::settings(depth) };
    let plan = plan_rough5(&bottom, &flanks, &part.stock, &tool, &s, &|_, _| {}).unwrap();
    let report = plan.air.unwrap();
    assert!(report.moves > 0 && report.length > 0.0, "{report:?}");
    assert!(plan.estimated_time < report.estimated_time_before, "{} {report:?}", plan.estimated_time);
    let proof_settings = ProofSettings { resolution: 1.0, axis_tolerance: 0.05 };
    let proof = prove(&plan.toolpath, &tool, &part.stock, &part.mesh, &proof_settings, &|_, _| {}).unwrap();
    assert!(proof.gouge_depth <= proof_settings.axis_tolerance, "{proof:?}");
    assert!((proof.air_move_length - report.length).abs() < 1e-6 * report.length.max(1.0), "{proof:?}");
    let without = plan_rough5(&bottom, &flanks, &part.stock, &tool, &common::settings(depth), &|_, _| {}).unwrap();
    let again = prove(&without.toolpath, &tool, &part.stock, &part.mesh, &proof_settings, &|_, _| {}).unwrap();
    assert!((again.remaining_percent - proof.remaining_percent).abs() < 1e-9, "{again:?} {proof:?}");
}
