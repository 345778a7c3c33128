//! Closed-form cases: scallop between two ball passes, a flat slot, the
//! swept volume of one straight move per cutter shape, rapids and shank
//! collisions.

#![allow(clippy::unwrap_used, clippy::float_cmp, reason = "tests fail loudly by design; exact cases compare exactly")]

use std::f64::consts::PI;

use scallop_cutter::{Cutter, CutterShape, HolderSegment};
use scallop_geom::{Aabb3, Point2, Point3, assert_near};
use scallop_mesh::{MeshIndex, TriMesh};
use scallop_sim::{SimError, ToolPart, VerifyOptions, ZMap, simulate, verify};
use scallop_toolpath::{Move, MoveKind, Toolpath};

fn p(x: f64, y: f64, z: f64) -> Point3 {
    Point3::new(x, y, z)
}

fn stock(x: f64, y: f64, bottom: f64, top: f64) -> Aabb3 {
    Aabb3 { min: p(0.0, 0.0, bottom), max: p(x, y, top) }
}

/// A path: rapid above `points[0]`, plunge to it, feed through the rest, retract.
fn path(points: &[Point3], clearance: f64) -> Toolpath {
    let mut t = Toolpath::new(1000.0);
    let first = points[0];
    t.push(Move::new(MoveKind::Rapid, p(first.x, first.y, clearance)));
    t.push(Move::new(MoveKind::Plunge, first));
    for q in &points[1..] {
        t.push(Move::new(MoveKind::Feed, *q));
    }
    let last = points[points.len() - 1];
    t.push(Move::new(MoveKind::Retract, p(last.x, last.y, clearance)));
    t
}

fn plane(x0: f64, y0: f64, x1: f64, y1: f64, z: f64) -> MeshIndex {
    let (mesh, _) =
        TriMesh::from_soup(&[[p(x0, y0, z), p(x1, y0, z), p(x1, y1, z)], [p(x0, y0, z), p(x1, y1, z), p(x0, y1, z)]])
            .unwrap();
    MeshIndex::build(&mesh)
}

#[test]
fn ball_leaves_the_theoretical_scallop_between_two_passes() {
    let (radius, step) = (2.0, 1.2);
    let ball = Cutter::new(CutterShape::Ball { radius }, 10.0).unwrap();
    let (y0, y1) = (5.0, 5.0 + step);
    let mut zmap = ZMap::new(stock(20.0, 12.0, -2.0, 1.0), 0.05).unwrap();
    let mut t = path(&[p(-3.0, y0, 0.0), p(23.0, y0, 0.0), p(23.0, y1, 0.0), p(-3.0, y1, 0.0)], 5.0);
    // The link at x = 23 is outside the stock; keep it.
    t.push(Move::new(MoveKind::Rapid, p(-3.0, y1, 5.0)));
    let report = zmap.cut(&ball, &t).unwrap();
    report.check().unwrap();

    // Exact at every cell centre between the passes: the lower of the two circles.
    let theory = radius - (radius * radius - (0.5 * step) * (0.5 * step)).sqrt();
    let (_, cell_y) = zmap.cell_size();
    let mut measured = f64::NEG_INFINITY;
    for j in 0..zmap.ny() {
        let y = zmap.cell_center(0, j).y;
        if !(y0..=y1).contains(&y) {
            continue;
        }
        let expected = [y0, y1].map(|c| radius - (radius * radius - (y - c) * (y - c)).sqrt());
        for i in 20..380 {
            assert_near!(zmap.height(i, j).unwrap(), expected[0].min(expected[1]), 1e-12);
        }
        measured = measured.max(zmap.height(200, j).unwrap());
    }
    // The grid's resolution bound: the cusp's slope times half a cell.
    let half = 0.5 * step;
    let slope = half / (radius * radius - half * half).sqrt();
    assert!(measured <= theory + 1e-12 && measured >= theory - slope * 0.5 * cell_y, "{measured} vs {theory}");

    // The same through `verify` with a part between the passes.
    let part = plane(5.0, y0, 15.0, y1, 0.0);
    let v = verify(&zmap, &part, &VerifyOptions::default()).unwrap();
    assert_near!(v.max_scallop, measured, 1e-12);
    assert!(v.min_deviation >= -1e-12);
    assert!(v.part_cells > 0);
}

#[test]
fn flat_slot_has_the_exact_width_and_depth() {
    let radius = 1.5;
    let flat = Cutter::new(CutterShape::Flat { radius }, 10.0).unwrap();
    let mut zmap = ZMap::new(stock(20.0, 10.0, -3.0, 0.0), 0.04).unwrap();
    // Starts inside the stock (a round end at x = 4) and leaves it at x = 25.
    let (a, b) = (Point2::new(4.0, 5.1), Point2::new(25.0, 5.1));
    let t = path(&[p(a.x, a.y, -0.7), p(b.x, b.y, -0.7)], 5.0);
    let report = zmap.cut(&flat, &t).unwrap();
    // The plunge is a feed-rate move; the rapid and retract touch nothing.
    report.check().unwrap();
    let mut rows_cut = std::collections::BTreeSet::new();
    for j in 0..zmap.ny() {
        for i in 0..zmap.nx() {
            let c = zmap.cell_center(i, j);
            let d = if c.x < a.x { (c - a).norm() } else { (c.y - a.y).abs() };
            let h = zmap.height(i, j).unwrap();
            if (d - radius).abs() < 1e-9 {
                continue; // on the boundary within rounding
            }
            if d < radius {
                assert_eq!(h.to_bits(), (-0.7f64).to_bits(), "cell {i} {j}");
                rows_cut.insert(j);
            } else {
                assert_eq!(h.to_bits(), 0.0f64.to_bits(), "cell {i} {j}");
            }
        }
    }
    // Width: the cut rows span 2R to within one cell.
    let (_, cell_y) = zmap.cell_size();
    let width = rows_cut.len() as f64 * cell_y;
    assert!((width - 2.0 * radius).abs() <= cell_y, "{width}");
}

/// Half the area of the circular segment of depth `d` of a circle of radius `r`:
/// the integral of sqrt(r^2 - (r - z)^2) for z in [0, d].
fn half_segment(r: f64, d: f64) -> f64 {
    0.5 * (r * r * ((r - d) / r).acos() - (r - d) * (2.0 * r * d - d * d).sqrt())
}

/// (cross-section area, volume of revolution) of the cutter below depth `d`
/// above its tip: A = 2 int rho(z) dz, V = pi int rho(z)^2 dz over [0, d].
fn profile_integrals(shape: &CutterShape, d: f64) -> (f64, f64) {
    match *shape {
        CutterShape::Flat { radius } => (2.0 * radius * d, PI * radius * radius * d),
        CutterShape::Ball { radius } => (2.0 * half_segment(radius, d), PI * (radius * d * d - d * d * d / 3.0)),
        CutterShape::Bull { radius, corner } => {
            let flat = radius - corner;
            let s = half_segment(corner, d);
            (2.0 * (flat * d + s), PI * (flat * flat * d + 2.0 * flat * s + corner * d * d - d * d * d / 3.0))
        }
        CutterShape::Cone { half_angle, .. } => {
            let tan = half_angle.tan();
            (d * d * tan, PI * tan * tan * d * d * d / 3.0)
        }
    }
}

#[test]
fn one_straight_move_removes_the_swept_volume_for_each_shape() {
    let shapes = [
        (CutterShape::Flat { radius: 2.0 }, 1.0),
        (CutterShape::Ball { radius: 2.0 }, 1.3),
        (CutterShape::Bull { radius: 2.0, corner: 0.6 }, 0.45),
        (CutterShape::Cone { radius: 2.0, half_angle: PI / 6.0 }, 1.5),
    ];
    let length = 10.0;
    for (shape, depth) in shapes {
        let cutter = Cutter::new(shape, 10.0).unwrap();
        let mut zmap = ZMap::new(stock(20.0, 12.0, -5.0, 0.0), 0.02).unwrap();
        let mut t = Toolpath::new(1000.0);
        t.push(Move::new(MoveKind::Rapid, p(5.0, 6.0, 3.0)));
        t.push(Move::new(MoveKind::Plunge, p(5.0, 6.0, -depth)));
        t.push(Move::new(MoveKind::Feed, p(5.0 + length, 6.0, -depth)));
        t.push(Move::new(MoveKind::Retract, p(5.0 + length, 6.0, 3.0)));
        let report = zmap.cut(&cutter, &t).unwrap();
        report.check().unwrap();
        let (area, revolution) = profile_integrals(&shape, depth);
        let exact = area * length + revolution;
        // Resolution bound: cells within half a diagonal of the cut's outline
        // (perimeter 2 L + 2 pi rho_top) may be misclassified, each by at most
        // its area times the depth.
        let (cx, cy) = zmap.cell_size();
        let rho_top = shape.radius_at(depth);
        let bound = (2.0 * length + 2.0 * PI * rho_top) * cx.hypot(cy) * depth;
        let removed = zmap.initial_volume() - zmap.volume();
        assert_near!(report.removed_volume, removed, 1e-6 * exact);
        assert!((removed - exact).abs() <= bound, "{shape:?}: removed {removed}, exact {exact}, bound {bound}");
        // Misclassified boundary cells mostly cancel: the error observed is ~1e-4 of
        // the volume; a wrong end cap or cross-section would be far above this guard.
        assert!((removed - exact).abs() <= 1e-3 * exact, "{shape:?}: removed {removed}, exact {exact}");
        // The plunge's own removal is the revolution volume (vertical move).
        assert!((report.removed_by_move[1] - revolution).abs() <= 2.0 * PI * rho_top * cx.hypot(cy) * depth);
        assert_eq!(report.air_feed_moves, 0);
    }
}

#[test]
fn rapid_into_stock_is_an_error_and_above_it_is_not() {
    let flat = Cutter::new(CutterShape::Flat { radius: 1.0 }, 10.0).unwrap();
    let part = plane(-1.0, -1.0, 11.0, 11.0, -1.0);
    let s = stock(10.0, 10.0, -2.0, 0.0);
    let mut t = Toolpath::new(1000.0);
    t.push(Move::new(MoveKind::Rapid, p(-3.0, 5.0, 0.0))); // skims the top: no material removed
    t.push(Move::new(MoveKind::Rapid, p(13.0, 5.0, 0.0)));
    let sim = simulate(s, 0.1, &flat, &t, &part, &VerifyOptions::default()).unwrap();
    assert_eq!(sim.cut.removed_volume, 0.0);

    t.push(Move::new(MoveKind::Rapid, p(13.0, 2.0, -0.5)));
    t.push(Move::new(MoveKind::Rapid, p(-3.0, 2.0, -0.5))); // through the stock
    t.push(Move::new(MoveKind::Retract, p(-3.0, 2.0, 5.0)));
    match simulate(s, 0.1, &flat, &t, &part, &VerifyOptions::default()) {
        Err(SimError::RapidIntoStock { count, hits }) => {
            assert_eq!(count, 1);
            assert_eq!(hits[0].id.index, 3);
            assert_near!(hits[0].depth, 0.5, 1e-12);
            let e = SimError::RapidIntoStock { count, hits };
            assert!(e.to_string().contains("move 3 of operation 0"), "{e}");
        }
        other => panic!("expected a rapid hit, got {other:?}"),
    }
}

#[test]
fn shank_above_short_flutes_collides() {
    let part = plane(-1.0, -1.0, 21.0, 11.0, -9.0);
    let s = stock(20.0, 10.0, -10.0, 0.0);
    let short = Cutter::new(CutterShape::Flat { radius: 2.0 }, 3.0).unwrap().with_shank(1.5, 20.0).unwrap();
    let slot = |depth: f64| path(&[p(-3.0, 5.0, -depth), p(23.0, 5.0, -depth)], 5.0);
    // 2.5 mm deep: within the 3 mm flutes.
    simulate(s, 0.1, &short, &slot(2.5), &part, &VerifyOptions::default()).unwrap();
    // 5 mm deep in one pass: 2 mm of stock above the flutes.
    match simulate(s, 0.1, &short, &slot(5.0), &part, &VerifyOptions::default()) {
        Err(SimError::HolderCollision { collisions, .. }) => {
            assert_eq!(collisions[0].part, ToolPart::Shank);
            assert_near!(collisions[0].depth, 2.0, 1e-9);
        }
        other => panic!("expected a shank collision, got {other:?}"),
    }
}

#[test]
fn part_above_the_stock_is_an_error() {
    let part = plane(2.0, 2.0, 8.0, 8.0, 0.5);
    let flat = Cutter::new(CutterShape::Flat { radius: 1.0 }, 10.0).unwrap();
    let zmap = ZMap::new(stock(10.0, 10.0, -2.0, 0.0), 0.1).unwrap();
    assert!(matches!(verify(&zmap, &part, &VerifyOptions::default()), Err(SimError::PartOutsideStock { .. })));
    let _ = flat;
}

#[test]
fn bad_stock_is_rejected() {
    assert!(matches!(ZMap::new(stock(10.0, 0.0, -1.0, 0.0), 0.1), Err(SimError::BadStock { .. })));
    assert!(matches!(ZMap::new(stock(10.0, 10.0, -1.0, 0.0), f64::NAN), Err(SimError::BadResolution { .. })));
    assert!(matches!(ZMap::new(stock(1e4, 1e4, -1.0, 0.0), 0.001), Err(SimError::TooManyCells { .. })));
    // 60 / 0.05 is 1200 cells despite rounding.
    let z = ZMap::new(stock(60.0, 60.0, -1.0, 0.0), 0.05).unwrap();
    assert_eq!((z.nx(), z.ny()), (1200, 1200));
}

#[test]
fn holder_collides_with_a_pocket_wall_cut_by_an_earlier_operation() {
    let mut zmap = ZMap::new(stock(40.0, 40.0, -30.0, 0.0), 0.2).unwrap();
    // Operation 0: a 20 mm wide pocket, 20 mm deep, plunged at the centre.
    let big = Cutter::new(CutterShape::Flat { radius: 10.0 }, 30.0).unwrap();
    let first = zmap.cut(&big, &path(&[p(20.0, 20.0, -20.0)], 5.0)).unwrap();
    first.check().unwrap();
    // Operation 1: a 4 mm cutter whose holder (radius 8) starts 15 mm above its tip.
    let holder = HolderSegment { length: 20.0, bottom_radius: 8.0, top_radius: 8.0 };
    let small = Cutter::new(CutterShape::Flat { radius: 2.0 }, 10.0)
        .unwrap()
        .with_shank(2.0, 5.0)
        .unwrap()
        .with_holder(vec![holder])
        .unwrap();
    // At the centre the holder stays inside the pocket.
    let report = zmap.cut(&small, &path(&[p(20.0, 20.0, -19.0)], 5.0)).unwrap();
    report.check().unwrap();
    // 5 mm off centre the holder reaches 13 mm out, over the uncut top at z = 0,
    // 4 mm above its bottom face (tip -19 + 15); cutter and shank stay in the pocket.
    let report = zmap.cut(&small, &path(&[p(25.0, 20.0, -19.0)], 5.0)).unwrap();
    assert_eq!(report.operation, 2);
    match report.check() {
        Err(SimError::HolderCollision { collisions, .. }) => {
            assert!(collisions.iter().all(|c| c.part == ToolPart::Holder(0)), "{collisions:?}");
            assert!(collisions.iter().all(|c| c.id.operation == 2));
            assert_near!(collisions.iter().map(|c| c.depth).fold(0.0, f64::max), 4.0, 1e-9);
        }
        other => panic!("expected a holder collision, got {other:?}"),
    }
}

/// A floor at z = 0 with a wall 10 mm tall at y >= 6 (top and side faces).
fn floor_and_wall() -> MeshIndex {
    let soup = [
        [p(-5.0, -5.0, 0.0), p(25.0, -5.0, 0.0), p(25.0, 6.0, 0.0)],
        [p(-5.0, -5.0, 0.0), p(25.0, 6.0, 0.0), p(-5.0, 6.0, 0.0)],
        [p(-5.0, 6.0, 0.0), p(25.0, 6.0, 0.0), p(25.0, 6.0, 10.0)],
        [p(-5.0, 6.0, 0.0), p(25.0, 6.0, 10.0), p(-5.0, 6.0, 10.0)],
        [p(-5.0, 6.0, 10.0), p(25.0, 6.0, 10.0), p(25.0, 15.0, 10.0)],
        [p(-5.0, 6.0, 10.0), p(25.0, 15.0, 10.0), p(-5.0, 15.0, 10.0)],
    ];
    MeshIndex::build(&TriMesh::from_soup(&soup).unwrap().0)
}

#[test]
fn shank_hitting_a_wall_of_the_part_names_the_move_and_the_place() {
    let part = floor_and_wall();
    let s = stock(20.0, 10.0, -1.0, 10.0);
    // A 1 mm ball on a 3 mm shank: the pass at y = 4.5 keeps the ball 0.5 mm
    // from the wall, but the shank (from the flute length up) reaches y = 7.5.
    let pass = path(&[p(-2.0, 4.5, 0.0), p(22.0, 4.5, 0.0)], 25.0);
    let short = Cutter::new(CutterShape::Ball { radius: 1.0 }, 3.0).unwrap().with_shank(3.0, 20.0).unwrap();
    match simulate(s, 0.1, &short, &pass, &part, &VerifyOptions::default()) {
        Err(e @ SimError::PartCollision { .. }) => {
            let message = e.to_string();
            assert!(message.contains("shank into the part") && message.contains("move 1 of operation 0"), "{message}");
            let SimError::PartCollision { collisions, .. } = e else { unreachable!() };
            // The plunge, the feed move and the retract (each starts or ends
            // at z = 0 beside the stock's ends), each deepest on the wall's top
            // within the shank's 3 mm of the path: 10 mm of wall above z = 3.
            let moves: Vec<u32> = collisions.iter().map(|c| c.id.index).collect();
            assert_eq!(moves, vec![1, 2, 3]);
            for c in &collisions {
                assert_eq!(c.part, ToolPart::Shank);
                assert!(c.at.y > 6.0 && c.at.y <= 7.5, "{c:?}");
                assert_near!(c.depth, 7.0, 1e-9);
            }
        }
        other => panic!("expected a shank collision with the part, got {other:?}"),
    }
    // The same check alone, on a stock already cut: the part is what it sees.
    let zmap = ZMap::new(s, 0.1).unwrap();
    assert_eq!(zmap.part_collisions(&part, &short, &pass, 0).unwrap().len(), 3);
    // Flutes longer than the wall: no collision with the part or the stock.
    let long = Cutter::new(CutterShape::Ball { radius: 1.0 }, 12.0).unwrap().with_shank(3.0, 20.0).unwrap();
    let sim = simulate(s, 0.1, &long, &pass, &part, &VerifyOptions::default()).unwrap();
    assert!(sim.verification.min_deviation >= -1e-9);
    assert!(zmap.part_collisions(&part, &long, &pass, 0).unwrap().is_empty());
}
