//! Trochoidal slot (kinematics.md section 5): the derived test values of the spec's slot
//! (D = 20, W = 28, p = 1.5 mm), measured on the generated polyline.

use scallop_geom::Point3;
use scallop_strategy::trochoid::{TrochoidParams, trochoid_slot};
use scallop_toolpath::MoveKind;

fn params(tolerance: f64) -> TrochoidParams {
    TrochoidParams {
        diameter: 20.0,
        width: 28.0,
        step: 1.5,
        tolerance,
        depth: -3.0,
        clearance: 5.0,
        feed: 2400.0,
        clockwise: false,
    }
}

fn slot(tolerance: f64) -> Vec<Point3> {
    let guide = [Point3::new(0.0, 0.0, 0.0), Point3::new(120.0, 0.0, 0.0)];
    let path = trochoid_slot(&guide, &params(tolerance)).expect("valid slot");
    path.moves().iter().filter(|m| matches!(m.kind, MoveKind::Plunge | MoveKind::Feed)).map(|m| m.to).collect()
}

/// Radius of the circle through three points.
fn circumradius(a: &Point3, b: &Point3, c: &Point3) -> f64 {
    let (ab, bc, ca) = ((b - a).norm(), (c - b).norm(), (a - c).norm());
    let area2 = (b - a).cross(&(c - a)).norm();
    ab * bc * ca / (2.0 * area2)
}

#[test]
fn derived_values_of_the_spec_slot() {
    let p = params(0.02);
    assert!((p.loop_radius() - 4.0).abs() < 1e-12);
    assert!((p.advance_per_radian() - 0.238732).abs() < 1e-6);
    // The spec's dt = 0.2 is the step of a 0.019983 mm chordal tolerance, R (1 - cos(dt/2)).
    assert!((params(4.0 * (1.0 - 0.1f64.cos())).parameter_step() - 0.2).abs() < 1e-12);

    // A fine polyline (chordal 1e-6 mm) so the measured values are the curve's, to 1e-4.
    let pts = slot(1e-6);
    // Envelope width 2R + D = 28 mm.
    let (lo, hi) = pts.iter().fold((f64::MAX, f64::MIN), |(lo, hi), p| (lo.min(p.y), hi.max(p.y)));
    assert!((hi - lo + 20.0 - 28.0).abs() < 1e-4, "{lo} {hi}");
    // 80 loops over 120 mm of centre travel: the angle turned is 80 turns.
    let turns = (pts.len() - 1) as f64 * params(1e-6).parameter_step() / std::f64::consts::TAU;
    assert!((turns - 80.0).abs() < 0.01, "{turns}");
    // One period's length, 25.155127 mm, from the middle of the slot.
    // (Averaged over the middle 40 loops: a loop is not a whole number of steps.)
    let per_loop_exact = (pts.len() - 1) as f64 / 80.0;
    let per_loop = per_loop_exact.round() as usize;
    let (mid, span) = (pts.len() / 4, (40.0 * per_loop_exact).round() as usize);
    let length: f64 = pts[mid..=mid + span].windows(2).map(|w| (w[1] - w[0]).norm()).sum::<f64>()
        * (40.0 * per_loop_exact / span as f64)
        / 40.0;
    assert!((length - 25.155127).abs() < 1e-3, "{length}");
    let mid = pts.len() / 2;
    // Radius of curvature between R (1 -+ V / (R omega))^2 = 3.536783 and 4.491713 mm.
    let radii: Vec<f64> = pts[mid..mid + per_loop + 2].windows(3).map(|w| circumradius(&w[0], &w[1], &w[2])).collect();
    let (rmin, rmax) = radii.iter().fold((f64::MAX, f64::MIN), |(a, b), r| (a.min(*r), b.max(*r)));
    assert!((rmin - 3.536783).abs() < 1e-4, "{rmin}");
    assert!((rmax - 4.491713).abs() < 1e-4, "{rmax}");
}

#[test]
fn the_polyline_stays_within_the_chordal_tolerance() {
    // Dense samples of the exact curve between two points never leave the chord by more
    // than the tolerance.
    let p = params(0.02);
    let pts = slot(0.02);
    let (r, v, dt) = (p.loop_radius(), p.advance_per_radian(), 120.0 / p.advance_per_radian() / (pts.len() - 1) as f64);
    let exact = |t: f64| Point3::new(v * t + r * t.cos(), r * t.sin(), -3.0);
    let mut worst = 0.0f64;
    for k in (0..pts.len() - 1).step_by(7) {
        let (a, b) = (pts[k], pts[k + 1]);
        let d = (b - a).normalize();
        for s in 1..16 {
            let q = exact((k as f64 + f64::from(s) / 16.0) * dt);
            let off = q - a;
            worst = worst.max((off - d * off.dot(&d)).norm());
        }
    }
    assert!(worst <= 0.02 + 1e-12, "{worst}");
    assert!(worst > 0.015, "the step should use most of the tolerance: {worst}");
}

#[test]
fn guides_with_corners_give_a_continuous_path_and_bad_slots_are_rejected() {
    let guide = [Point3::new(0.0, 0.0, 0.0), Point3::new(30.0, 0.0, 0.0), Point3::new(30.0, 30.0, 0.0)];
    let path = trochoid_slot(&guide, &params(0.01)).expect("valid");
    let feeds: Vec<Point3> = path.moves().iter().filter(|m| m.kind == MoveKind::Feed).map(|m| m.to).collect();
    let longest = feeds.windows(2).map(|w| (w[1] - w[0]).norm()).fold(0.0, f64::max);
    assert!(longest < 1.0, "a jump at the corner: {longest}");
    let last = feeds[feeds.len() - 1];
    assert!((last - Point3::new(34.0, 30.0, -3.0)).norm() < 1e-9, "{last:?}");

    let bad = |p: TrochoidParams| trochoid_slot(&guide, &p).expect_err("rejected").to_string();
    assert!(bad(TrochoidParams { width: 20.0, ..params(0.01) }).contains("`width`"));
    assert!(bad(TrochoidParams { step: 30.0, ..params(0.01) }).contains("`step`"));
    assert!(bad(TrochoidParams { tolerance: 0.0, ..params(0.01) }).contains("`tolerance`"));
    assert!(bad(TrochoidParams { feed: f64::NAN, ..params(0.01) }).contains("`feed`"));
    assert!(trochoid_slot(&guide[..1], &params(0.01)).expect_err("one point").to_string().contains("`guide`"));
}
