//! Engagement of 2.5D pocket programs against closed forms: a full slot reads
//! 180 degrees, a straight cut at radial depth `ae` beside a slot reads
//! `arccos(1 - ae / R)`, a cut through cleared area reads 0 (a link), the
//! reachable area left uncut is the strip no pass reached, walls are gouges,
//! and the figures do not depend on the thread count.

#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

use proptest::prelude::*;
use scallop_geom::{Point2, Point3, Vec2};
use scallop_sim::{EngagementOptions, Pocket, SimError, engagement_angle, pocket_engagement};
use scallop_toolpath::{Move, MoveKind, Toolpath};

/// A rectangle pocket `[x0, x1] x [y0, y1]` with optional square islands.
fn rectangle(x0: f64, y0: f64, x1: f64, y1: f64) -> Vec<Point2> {
    vec![Point2::new(x0, y0), Point2::new(x1, y0), Point2::new(x1, y1), Point2::new(x0, y1)]
}

/// Straight passes at cutting depth z = -1, each entered by a rapid and a plunge.
fn passes(lines: &[(Point2, Point2)]) -> Toolpath {
    let mut path = Toolpath::new(1000.0);
    for &(a, b) in lines {
        path.push(Move::new(MoveKind::Rapid, Point3::new(a.x, a.y, 5.0)));
        path.push(Move::new(MoveKind::Plunge, Point3::new(a.x, a.y, -1.0)));
        path.push(Move::new(MoveKind::Feed, Point3::new(b.x, b.y, -1.0)));
        path.push(Move::new(MoveKind::Retract, Point3::new(b.x, b.y, 5.0)));
    }
    path
}

fn options(resolution: f64) -> EngagementOptions {
    EngagementOptions { resolution, ..EngagementOptions::default() }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(12))]

    /// A slot along a direction, then a pass beside it at radial depth `ae`:
    /// the slot reads 180 degrees and the pass `arccos(1 - ae / R)` away from
    /// the passes' ends, both within the raster's bound; a third pass on the
    /// second's line cuts nothing (a link).
    #[test]
    fn straight_cuts_read_the_closed_form(radius in 1.0..4.0f64, depth in 0.15..0.9f64, heading in 0.0..6.3f64) {
        let ae = depth * radius;
        let along = Vec2::new(heading.cos(), heading.sin());
        let across = Vec2::new(-along.y, along.x);
        // The pass beside the slot stays clear of the slot's rounded ends.
        let line = |offset: f64, half: f64| (Point2::origin() - along * half + across * offset, Point2::origin() + along * half + across * offset);
        let pocket = Pocket::new(vec![rectangle(-25.0, -25.0, 25.0, 25.0)]).unwrap();
        let path = passes(&[line(0.0, 15.0), line(ae, 10.0), line(ae, 10.0)]);
        let opts = options(0.1);
        let target = engagement_angle(ae, radius);
        let report = pocket_engagement(&pocket, radius, &path, target, &opts).unwrap();
        // Moves: 2 the slot's feed, 6 the pass's, 10 the link's (largest sample of each).
        let slot = report.move_phi[2];
        prop_assert!((slot - std::f64::consts::PI).abs() <= opts.angle_bound(),
            "slot {} deg", slot.to_degrees());
        prop_assert!((report.move_phi[6] - target).abs() <= opts.angle_bound(),
            "side cut {} deg, closed form {} deg", report.move_phi[6].to_degrees(), target.to_degrees());
        prop_assert!(report.move_phi[10] == 0.0);
        prop_assert!((report.link_length - 20.0).abs() < 1e-9, "link {}", report.link_length);
        prop_assert_eq!((report.entries, report.retracts), (3, 3));
    }
}

/// A slot then a pass beside it at 0.2 D: only the slot past its entry (2 R)
/// is over-engaged and a full slot, and the pass reads the closed form.
#[test]
fn a_slot_and_a_side_cut_read_their_closed_forms() {
    let (radius, ae) = (3.0, 1.2);
    let pocket = Pocket::new(vec![rectangle(0.0, 0.0, 100.0, 60.0)]).unwrap();
    let y = 30.0;
    let path =
        passes(&[(Point2::new(10.0, y), Point2::new(90.0, y)), (Point2::new(10.0, y + ae), Point2::new(84.0, y + ae))]);
    let opts = options(0.05);
    let target = engagement_angle(ae, radius);
    assert!((target.to_degrees() - 53.13).abs() < 0.01);
    let report = pocket_engagement(&pocket, radius, &path, target, &opts).unwrap();
    assert!((report.move_phi[6] - target).abs() <= opts.angle_bound(), "{}", report.move_phi[6]);
    // 80 mm of slot less its 6 mm entry, within one sample.
    assert!((report.slot_length - 74.0).abs() <= 0.1 + 1e-9, "slot {}", report.slot_length);
    assert!((report.over_length - 74.0).abs() <= 0.1 + 1e-9, "over {}", report.over_length);
    assert!((report.max - std::f64::consts::PI).abs() <= opts.angle_bound());
    assert_eq!((report.air_length, report.link_length), (0.0, 0.0));
}

/// Passes that clear the lower part of a rectangle: the reachable area left
/// uncut is the upper strip less its two corners that no disc reaches.
#[test]
fn uncut_reachable_area_is_the_strip_left() {
    let radius = 3.0;
    let pocket = Pocket::new(vec![rectangle(0.0, 0.0, 30.0, 20.0)]).unwrap();
    // Passes at y = 3 .. 10 every 1 mm, x from 3 to 27: they clear y <= 13.
    let lines: Vec<(Point2, Point2)> =
        (3..=10).map(|k| (Point2::new(3.0, f64::from(k)), Point2::new(27.0, f64::from(k)))).collect();
    let opts = options(0.05);
    let report = pocket_engagement(&pocket, radius, &passes(&lines), 1.0, &opts).unwrap();
    let corner = radius * radius * (1.0 - std::f64::consts::FRAC_PI_4);
    let strip = 30.0 * 7.0 - 2.0 * corner;
    // The strip's edges are sampled by the cells: its perimeter times a cell.
    let bound = (2.0 * 30.0 + 2.0 * 7.0) * opts.resolution + 2.0 * opts.uncut_margin * 30.0;
    assert!(
        (report.uncut_area - strip).abs() <= bound,
        "uncut {} mm2, strip {strip} mm2, reachable {}",
        report.uncut_area,
        report.reachable_area
    );
    assert!((report.pocket_area - 600.0).abs() <= 1e-6, "pocket {}", report.pocket_area);
}

/// A tool that reaches into an island, or beyond the outer wall, is a gouge.
#[test]
fn entering_an_island_or_a_wall_is_a_gouge() {
    let pocket = Pocket::new(vec![rectangle(0.0, 0.0, 50.0, 40.0), rectangle(20.0, 15.0, 30.0, 25.0)]).unwrap();
    let opts = options(0.1);
    let into_island = passes(&[(Point2::new(5.0, 20.0), Point2::new(45.0, 20.0))]);
    let err = pocket_engagement(&pocket, 3.0, &into_island, 1.0, &opts).unwrap_err();
    assert!(matches!(err, SimError::PocketGouge { depth, .. } if (depth - 8.0).abs() < 1e-9), "{err}");
    let along_wall = passes(&[(Point2::new(5.0, 2.5), Point2::new(45.0, 2.5))]);
    let err = pocket_engagement(&pocket, 3.0, &along_wall, 1.0, &opts).unwrap_err();
    assert!(matches!(err, SimError::PocketGouge { depth, .. } if (depth - 0.5).abs() < 1e-9), "{err}");
    // Beside the island, clear of it: no gouge.
    let beside = passes(&[(Point2::new(5.0, 8.0), Point2::new(45.0, 8.0))]);
    let report = pocket_engagement(&pocket, 3.0, &beside, 1.0, &opts).unwrap();
    assert!((report.max_penetration + 2.0).abs() < 1e-9, "{}", report.max_penetration);
}

/// A spiral-like program evaluated on one and on two threads: identical figures.
#[test]
fn figures_do_not_depend_on_the_thread_count() {
    let pocket = Pocket::new(vec![rectangle(0.0, 0.0, 40.0, 30.0)]).unwrap();
    let mut path = Toolpath::new(1000.0);
    path.push(Move::new(MoveKind::Rapid, Point3::new(20.0, 15.0, 5.0)));
    path.push(Move::new(MoveKind::Plunge, Point3::new(20.0, 15.0, -1.0)));
    for k in 1..2000 {
        let t = f64::from(k) * 0.01;
        let r = 0.55 * t;
        path.push(Move::new(MoveKind::Feed, Point3::new(20.0 + r * (t * 6.0).cos(), 15.0 + r * (t * 6.0).sin(), -1.0)));
    }
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| pocket_engagement(&pocket, 3.0, &path, 1.0, &options(0.1)).unwrap())
    };
    let (one, two) = (run(1), run(2));
    assert!(one.samples > 1000);
    assert_eq!(one, two);
}

/// Bad pockets and options are errors naming the problem.
#[test]
fn bad_input_is_an_error() {
    assert!(matches!(Pocket::new(vec![]), Err(SimError::BadPocket { ring: 0, .. })));
    let two = vec![Point2::new(0.0, 0.0), Point2::new(1.0, 0.0), Point2::new(0.0, 0.0)];
    assert!(matches!(Pocket::new(vec![rectangle(0.0, 0.0, 1.0, 1.0), two]), Err(SimError::BadPocket { ring: 1, .. })));
    let pocket = Pocket::new(vec![rectangle(0.0, 0.0, 10.0, 10.0)]).unwrap();
    let opts = EngagementOptions { sample_step: 0.0, ..EngagementOptions::default() };
    assert!(matches!(
        pocket_engagement(&pocket, 1.0, &Toolpath::new(1.0), 1.0, &opts),
        Err(SimError::BadEngagement { .. })
    ));
}

/// The largest engagement of each move of `path` by brute force: every probe
/// against the pocket and every earlier move at cutting depth, no raster.
fn brute_force_move_phi(pocket: &Pocket, radius: f64, path: &Toolpath, opts: &EngagementOptions) -> Vec<f64> {
    let moves = path.moves();
    let xy = |i: usize| Point2::new(moves[i].to.x, moves[i].to.y);
    let mut done: Vec<(Point2, Point2)> = Vec::new();
    let mut out = vec![0.0; moves.len()];
    let half = opts.angle_samples / 2;
    let step = std::f64::consts::PI / half as f64;
    for i in 1..moves.len() {
        if matches!(moves[i].kind, MoveKind::Rapid | MoveKind::Retract) {
            continue;
        }
        let (a, b) = (xy(i - 1), xy(i));
        let uncut_at = |q: Point2, at: Point2| {
            let d = |p: Point2, s: Point2, e: Point2| {
                let t = ((p - s).dot(&(e - s)) / (e - s).norm_squared()).clamp(0.0, 1.0);
                if (e - s).norm_squared() > 0.0 { (p - (s + (e - s) * t)).norm() } else { (p - s).norm() }
            };
            pocket.contains(q) && d(q, a, at) >= radius - 1e-6 && done.iter().all(|&(s, e)| d(q, s, e) > radius + 1e-6)
        };
        if a == b && moves[i].to.z < moves[i - 1].to.z {
            // A vertical plunge: the half circle (of any direction) with most material.
            let probes: Vec<bool> = (0..2 * half)
                .map(|j| {
                    let theta = (j as f64 + 0.5) * step;
                    uncut_at(a + Vec2::new(theta.cos(), theta.sin()) * radius, a)
                })
                .collect();
            let best = (0..2 * half).map(|j| (0..half).filter(|&k| probes[(j + k) % (2 * half)]).count()).max();
            out[i] = best.unwrap_or(0) as f64 * step;
            done.push((a, b));
            continue;
        }
        let n = ((b - a).norm() / opts.sample_step).ceil() as usize;
        for k in 1..=n {
            let at = a + (b - a) * (k as f64 / n as f64);
            let heading = (at.y - a.y).atan2(at.x - a.x);
            let uncut = (0..half)
                .filter(|&j| {
                    let theta = heading - std::f64::consts::FRAC_PI_2 + (j as f64 + 0.5) * step;
                    uncut_at(at + Vec2::new(theta.cos(), theta.sin()) * radius, at)
                })
                .count();
            out[i] = f64::max(out[i], uncut as f64 * step);
        }
        done.push((a, b));
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(8))]

    /// A random walk in a pocket with an island: the largest engagement of
    /// every move equals the brute force's (no raster) within one probe step.
    #[test]
    fn engagement_matches_the_brute_force(radius in 1.0..3.0f64, seed in 0u64..1000) {
        let pocket = Pocket::new(vec![rectangle(0.0, 0.0, 30.0, 24.0), rectangle(13.0, 10.0, 17.0, 14.0)]).unwrap();
        let mut path = Toolpath::new(1000.0);
        let mut state = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut at = Point2::new(radius + 1.0, radius + 1.0);
        path.push(Move::new(MoveKind::Rapid, Point3::new(at.x, at.y, 5.0)));
        path.push(Move::new(MoveKind::Plunge, Point3::new(at.x, at.y, -1.0)));
        for _ in 0..60 {
            let heading = next() * std::f64::consts::TAU;
            let to = at + Vec2::new(heading.cos(), heading.sin()) * (0.3 + 3.0 * next());
            if pocket.penetration(to, radius) < -0.05 && pocket.penetration(at + (to - at) * 0.5, radius) < -0.05 {
                path.push(Move::new(MoveKind::Feed, Point3::new(to.x, to.y, -1.0)));
                at = to;
            }
        }
        let opts = options(0.1);
        let report = pocket_engagement(&pocket, radius, &path, 1.0, &opts).unwrap();
        // A walk that hardly moved (boxed in by the island) says nothing: draw another.
        prop_assume!(path.moves().len() > 20 && report.max > 0.5);
        let brute = brute_force_move_phi(&pocket, radius, &path, &opts);
        let step = std::f64::consts::TAU / opts.angle_samples as f64;
        for (i, (got, want)) in report.move_phi.iter().zip(&brute).enumerate() {
            prop_assert!((got - want).abs() <= step + 1e-12, "move {}: {} deg, brute force {} deg", i, got.to_degrees(), want.to_degrees());
        }
    }
}

/// A pass around the inner corner of an L by an arc of radius R about the
/// corner touches the corner and never reaches beyond it; the same move read
/// as its chord would cut R (1 - cos 45 deg) into the corner. So the
/// evaluation follows the arc: no gouge, and the move's figures are those of
/// the arc.
#[test]
fn an_arc_around_an_inner_corner_is_followed_not_its_chord() {
    use scallop_toolpath::ArcXY;
    // The L: [0, 20]^2 without [10, 20]^2; its inner corner is (10, 10).
    let l = vec![
        Point2::new(0.0, 0.0),
        Point2::new(20.0, 0.0),
        Point2::new(20.0, 10.0),
        Point2::new(10.0, 10.0),
        Point2::new(10.0, 20.0),
        Point2::new(0.0, 20.0),
    ];
    let pocket = Pocket::new(vec![l]).unwrap();
    let radius = 2.0;
    let corner_pass = |arc: bool| {
        let mut path = Toolpath::new(1000.0);
        path.push(Move::new(MoveKind::Rapid, Point3::new(8.0, 18.0, 5.0)));
        path.push(Move::new(MoveKind::Plunge, Point3::new(8.0, 18.0, -1.0)));
        path.push(Move::new(MoveKind::Feed, Point3::new(8.0, 10.0, -1.0)));
        let end = Move::new(MoveKind::Feed, Point3::new(10.0, 8.0, -1.0));
        if arc {
            path.push_arc(end, ArcXY { center: Point2::new(10.0, 10.0), sweep: std::f64::consts::FRAC_PI_2 });
        } else {
            path.push(end);
        }
        path.push(Move::new(MoveKind::Feed, Point3::new(18.0, 8.0, -1.0)));
        path.push(Move::new(MoveKind::Retract, Point3::new(18.0, 8.0, 5.0)));
        path
    };
    let opts = options(0.1);
    let target = engagement_angle(1.0, radius);
    let report = pocket_engagement(&pocket, radius, &corner_pass(true), target, &opts).unwrap();
    assert_eq!(report.move_phi.len(), 6);
    assert!(report.move_phi[3] > 0.0, "the arc cuts the corner's material");
    match pocket_engagement(&pocket, radius, &corner_pass(false), target, &opts) {
        Err(SimError::PocketGouge { depth, index, .. }) => {
            assert_eq!(index, 3);
            // The chord's middle is R (1 - cos 45 deg) inside the corner; the
            // samples come within a sample step of it.
            let chord = radius * (1.0 - std::f64::consts::FRAC_1_SQRT_2);
            assert!(depth <= chord + 1e-9 && depth > 0.9 * chord, "depth {depth}, chord {chord}");
        }
        other => panic!("the chord should gouge the corner: {other:?}"),
    }
}

/// A slot along the x axis from outside a stock box to (2.7, 0) at depth,
/// then a circle of radius 2.7 about the origin (tighter than the 3 mm
/// radius tool, as a helical entry's) as four quarter arcs, or (`arcs`
/// false) the same arcs as the chords the engagement follows them by.
fn tight_circle(arcs: bool) -> Toolpath {
    let rho = 2.7;
    let at = |a: f64| Point3::new(rho * a.cos(), rho * a.sin(), -1.0);
    let mut path = Toolpath::new(1000.0);
    path.push(Move::new(MoveKind::Rapid, Point3::new(25.0, 0.0, 5.0)));
    path.push(Move::new(MoveKind::Plunge, Point3::new(25.0, 0.0, -1.0)));
    path.push(Move::new(MoveKind::Feed, at(0.0)));
    for q in 1..=4 {
        let (from, to) =
            (at(std::f64::consts::FRAC_PI_2 * f64::from(q - 1)), at(std::f64::consts::FRAC_PI_2 * f64::from(q)));
        let arc = scallop_toolpath::ArcXY { center: Point2::origin(), sweep: std::f64::consts::FRAC_PI_2 };
        if arcs {
            path.push_arc(Move::new(MoveKind::Feed, to), arc);
        } else {
            for p in arc.chords(&from, &to, scallop_geom::tol::sim::ENGAGEMENT_ARC_SAGITTA) {
                path.push(Move::new(MoveKind::Feed, p));
            }
        }
    }
    path.push(Move::new(MoveKind::Retract, Point3::new(rho, 0.0, 5.0)));
    path
}

/// On the in-process stock an arc move reads as the same path written as
/// the chords the measure follows it by, even where it turns tighter than
/// the tool: there the earlier part of the arc sweeps the front half of the
/// tool's periphery at its later points, and probing the stock as it was
/// before the arc began would count material the arc had already removed.
#[test]
fn an_arc_reads_as_its_chords_on_the_stock() {
    use scallop_cutter::{Cutter, CutterShape};
    use scallop_geom::Aabb3;
    use scallop_sim::{ZMap, stock_engagement};
    let stock =
        ZMap::new(Aabb3 { min: Point3::new(-20.0, -20.0, -5.0), max: Point3::new(20.0, 20.0, 0.0) }, 0.05).unwrap();
    let flat = Cutter::new(CutterShape::Flat { radius: 3.0 }, 20.0).unwrap();
    let target = engagement_angle(1.2, 3.0);
    let read = |path: &Toolpath| stock_engagement(&stock, &flat, path, target, &EngagementOptions::default()).unwrap();
    let (arcs, chords) = (read(&tight_circle(true)), read(&tight_circle(false)));
    for (what, a, c) in [("p50", arcs.p50, chords.p50), ("p95", arcs.p95, chords.p95), ("max", arcs.max, chords.max)] {
        assert!(
            (a - c).abs() <= 1e-9,
            "{what}: {:.2} deg as arcs, {:.2} deg as chords",
            a.to_degrees(),
            c.to_degrees()
        );
    }
    assert!((arcs.slot_length - chords.slot_length).abs() <= 1e-9, "{} / {}", arcs.slot_length, chords.slot_length);
    assert!(arcs.cutting_length > 0.0 && arcs.max > 0.0);
}
