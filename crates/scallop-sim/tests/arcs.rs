//! Circular moves (G2/G3 in the XY plane) cut exactly: a flat cutter on a
//! full circle cuts an annulus of exact inner and outer radius and the
//! annulus's volume within the grid's bound; a ball on a half circle leaves,
//! cell by cell, `z + h(d)` with `d` the distance to the arc; arcs agree with
//! fine chords; helices are simulated within their chord sagitta.

#![allow(clippy::unwrap_used, clippy::float_cmp, reason = "tests fail loudly by design; exact cases compare exactly")]

use std::f64::consts::PI;

use scallop_cutter::{Cutter, CutterShape};
use scallop_geom::{Aabb3, Point2, Point3};
use scallop_sim::ZMap;
use scallop_toolpath::{ArcXY, Move, MoveKind, Toolpath};

fn p(x: f64, y: f64, z: f64) -> Point3 {
    Point3::new(x, y, z)
}

/// Rapid above `start`, plunge to it, one arc about `center` by `sweep` to `end`, retract.
fn arc_path(start: Point3, center: Point2, sweep: f64, end: Point3) -> Toolpath {
    let mut t = Toolpath::new(1000.0);
    t.push(Move::new(MoveKind::Rapid, p(start.x, start.y, 5.0)));
    t.push(Move::new(MoveKind::Plunge, start));
    t.push_arc(Move::new(MoveKind::Feed, end), ArcXY { center, sweep });
    t.push(Move::new(MoveKind::Retract, p(end.x, end.y, 5.0)));
    t
}

/// The same arc as `chords` straight moves.
fn chord_path(start: Point3, center: Point2, sweep: f64, end: Point3, chords: u32) -> Toolpath {
    let mut t = Toolpath::new(1000.0);
    t.push(Move::new(MoveKind::Rapid, p(start.x, start.y, 5.0)));
    t.push(Move::new(MoveKind::Plunge, start));
    let r = (start.x - center.x).hypot(start.y - center.y);
    let a0 = (start.y - center.y).atan2(start.x - center.x);
    for q in 1..=chords {
        let t_ = f64::from(q) / f64::from(chords);
        let a = a0 + sweep * t_;
        let z = start.z + (end.z - start.z) * t_;
        t.push(Move::new(MoveKind::Feed, p(center.x + r * a.cos(), center.y + r * a.sin(), z)));
    }
    t.push(Move::new(MoveKind::Retract, p(end.x, end.y, 5.0)));
    t
}

fn stock() -> Aabb3 {
    Aabb3 { min: p(0.0, 0.0, -5.0), max: p(20.0, 20.0, 0.0) }
}

#[test]
fn flat_cutter_on_a_full_circle_cuts_the_exact_annulus() {
    let (rho, radius, depth) = (6.0, 1.5, 1.0);
    let c = Point2::new(10.0, 10.0);
    let flat = Cutter::new(CutterShape::Flat { radius }, 10.0).unwrap();
    let mut zmap = ZMap::new(stock(), 0.05).unwrap();
    let start = p(c.x + rho, c.y, -depth);
    let report = zmap.cut(&flat, &arc_path(start, c, -2.0 * PI, start)).unwrap();
    report.check().unwrap();
    // Cell by cell: cut to -depth exactly where the centre lies in the annulus.
    for j in 0..zmap.ny() {
        for i in 0..zmap.nx() {
            let q = zmap.cell_center(i, j);
            let a = (q.x - c.x).hypot(q.y - c.y);
            let expected = if (a - rho).abs() <= radius { -depth } else { 0.0 };
            assert_eq!(zmap.height(i, j).unwrap(), expected, "cell ({i}, {j}) at distance {a}");
        }
    }
    // Volume: pi ((rho + R)^2 - (rho - R)^2) depth = 4 pi rho R depth; cells
    // decide by their centres, so the error is at most the depth times the
    // area within half a cell diagonal of the two boundary circles.
    let exact = 4.0 * PI * rho * radius * depth;
    let (cx, cy) = zmap.cell_size();
    let half_diagonal = 0.5 * cx.hypot(cy);
    let bound = depth * 2.0 * PI * 2.0 * rho * 2.0 * half_diagonal;
    assert!((report.removed_volume - exact).abs() <= bound, "{} vs {exact} (bound {bound})", report.removed_volume);
    // And far tighter in practice (the errors cancel around the circles).
    assert!((report.removed_volume - exact).abs() <= 0.01 * exact, "{} vs {exact}", report.removed_volume);
}

#[test]
fn ball_on_a_half_circle_leaves_the_profile_at_the_distance_to_the_arc() {
    let radius = 2.0;
    let c = Point2::new(10.0, 10.0);
    let ball = Cutter::new(CutterShape::Ball { radius }, 10.0).unwrap();
    // Clockwise half circle from (14, 10) over the bottom to (6, 10), 1 mm deep.
    let (start, end) = (p(14.0, 10.0, -1.0), p(6.0, 10.0, -1.0));
    let mut zmap = ZMap::new(stock(), 0.1).unwrap();
    zmap.cut(&ball, &arc_path(start, c, -PI, end)).unwrap().check().unwrap();
    for j in 0..zmap.ny() {
        for i in 0..zmap.nx() {
            let q = zmap.cell_center(i, j);
            let (qx, qy) = (q.x - c.x, q.y - c.y);
            // The arc is the lower half (y <= 10); elsewhere the nearer end.
            let d = if qy <= 0.0 {
                (qx.hypot(qy) - 4.0).abs()
            } else {
                (q.x - 14.0).hypot(q.y - 10.0).min((q.x - 6.0).hypot(q.y - 10.0))
            };
            // Also the plunge at the start and the retract at the end (vertical moves).
            let expected = if d <= radius { (-1.0 + radius - (radius * radius - d * d).sqrt()).min(0.0) } else { 0.0 };
            let got = zmap.height(i, j).unwrap();
            assert!((got - expected).abs() <= 1e-9, "cell ({i}, {j}): {got} vs {expected}");
        }
    }
}

#[test]
fn arcs_agree_with_fine_chords_and_helices_with_their_chords() {
    let c = Point2::new(10.0, 10.0);
    let bull = Cutter::new(CutterShape::Bull { radius: 2.0, corner: 0.5 }, 10.0).unwrap();
    // A planar three-quarter turn counter-clockwise, and a helix down 1 mm.
    for (start, end, sweep) in
        [(p(15.0, 10.0, -1.0), p(10.0, 5.0, -1.0), 1.5 * PI), (p(15.0, 10.0, -0.5), p(10.0, 5.0, -1.5), 1.5 * PI)]
    {
        let mut exact = ZMap::new(stock(), 0.1).unwrap();
        exact.cut(&bull, &arc_path(start, c, sweep, end)).unwrap().check().unwrap();
        // 4000 chords of a 5 mm circle: sagitta 5 (1 - cos(3 pi / 16000)) < 1e-6 mm.
        let mut chords = ZMap::new(stock(), 0.1).unwrap();
        chords.cut(&bull, &chord_path(start, c, sweep, end, 4000)).unwrap().check().unwrap();
        let worst = exact.heights().iter().zip(chords.heights()).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        // Chords lie inside the circle by at most their sagitta delta (the
        // test's 8.7e-7 mm, plus the simulator's own 1e-4 mm for a helix).
        // Moving a profile sideways by delta moves its floor by at most
        // sqrt(2 r delta) where it is steepest (the corner's vertical rim,
        // r = 0.5 mm), and by nothing on its flat bottom.
        let helix = start.z != end.z;
        let delta = 5.0 * (1.0 - (1.5 * PI / 4000.0 / 2.0).cos()) + if helix { 1e-4 } else { 0.0 };
        let bound = (2.0 * 0.5 * delta).sqrt();
        assert!(worst <= bound, "{worst} > {bound}");
        assert!(exact.heights().iter().any(|&h| h < -0.4));
    }
}

#[test]
fn gcode_arcs_are_read_as_arcs_and_cut_exactly() {
    use scallop_io::gcode::{GcodeOptions, read_gcode, read_gcode_arcs};
    // A flat 3 mm cutter, 1 mm deep, a full clockwise circle of radius 6 about
    // (10, 10) in incremental I J, then a counter-clockwise half circle by R.
    let text = "G21 G90 G17\nG0 X16 Y10 Z5\nG1 Z-1 F300\nG2 X16 Y10 I-6 J0\nG3 X4 Y10 R6\nG0 Z5\n";
    let arcs = read_gcode_arcs(text, &GcodeOptions::default()).unwrap();
    assert_eq!(arcs.arc_count(), 2);
    let chords = read_gcode(text, &GcodeOptions::default()).unwrap();
    assert_eq!(chords.arc_count(), 0);
    assert!(chords.moves().len() > 100);
    let flat = Cutter::new(CutterShape::Flat { radius: 1.5 }, 10.0).unwrap();
    let mut exact = ZMap::new(stock(), 0.05).unwrap();
    let report = exact.cut(&flat, &arcs).unwrap();
    report.check().unwrap();
    // The half circle retraces half of the annulus: the annulus alone.
    let annulus = 4.0 * PI * 6.0 * 1.5 * 1.0;
    assert!((report.removed_volume - annulus).abs() <= 0.01 * annulus, "{} vs {annulus}", report.removed_volume);
    let mut linear = ZMap::new(stock(), 0.05).unwrap();
    linear.cut(&flat, &chords).unwrap().check().unwrap();
    // The chords (0.001 mm sagitta) move the walls by at most 0.001 mm: only
    // cells whose centres lie that close to a wall can differ.
    let differ = exact.heights().iter().zip(linear.heights()).filter(|(a, b)| a != b).count();
    assert!(differ <= exact.heights().len() / 100, "{differ}");
}
