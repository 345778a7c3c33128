//! `stock_engagement`: the engagement of a 3-axis program read on the
//! in-process stock, against the closed form of a straight side cut.

use proptest::prelude::*;
use scallop_cutter::{Cutter, CutterShape};
use scallop_geom::{Aabb3, Point3};
use scallop_sim::{EngagementOptions, ZMap, engagement_angle, stock_engagement};
use scallop_toolpath::{Move, MoveKind, Toolpath};

const R: f64 = 3.0;
const CELL: f64 = 0.05;

fn p(x: f64, y: f64, z: f64) -> Point3 {
    Point3::new(x, y, z)
}

fn stock() -> ZMap {
    ZMap::new(Aabb3 { min: p(0.0, 0.0, -5.0), max: p(60.0, 40.0, 0.0) }, CELL).expect("stock")
}

/// Straight passes at depth `z` along x from 10 to `x1` at each `y`, each
/// entered by a plunge from above and left by a retract.
fn passes(rows: &[(f64, f64)], z: f64) -> Toolpath {
    let mut path = Toolpath::new(1000.0);
    for &(y, x1) in rows {
        path.push(Move::new(MoveKind::Rapid, p(10.0, y, 5.0)));
        path.push(Move::new(MoveKind::Plunge, p(10.0, y, z)));
        path.push(Move::new(MoveKind::Feed, p(x1, y, z)));
        path.push(Move::new(MoveKind::Retract, p(x1, y, 5.0)));
    }
    path
}

/// How far the measured angle of a side cut may be from the closed form: the
/// probed circle lies half a cell diagonal inside the periphery and a cell's
/// edge half a diagonal from its centre, so the material's edge is read within
/// one cell diagonal, which moves the arc's end by that over `R sin(phi)`;
/// plus the probes' spacing.
fn bound(phi: f64, options: &EngagementOptions) -> f64 {
    let diagonal = CELL * std::f64::consts::SQRT_2;
    diagonal / (R * phi.sin()) + options.angle_bound()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// A slot, then a pass `ae` beside it: the slot reads 180 degrees, the
    /// side cut `arccos(1 - ae / R)`, for a flat end mill and a bull-nose
    /// (probed where its profile reaches R), at any depth.
    #[test]
    fn a_side_cut_reads_its_radial_depth(ae in 0.6f64..5.4, depth in 1.0f64..4.0, bull in any::<bool>()) {
        let shape = if bull { CutterShape::Bull { radius: R, corner: 0.8 } } else { CutterShape::Flat { radius: R } };
        let cutter = Cutter::new(shape, 20.0).expect("cutter");
        let path = passes(&[(20.0, 50.0), (20.0 + ae, 44.0)], -depth);
        let options = EngagementOptions::default();
        let target = engagement_angle(ae, R);
        let r = stock_engagement(&stock(), &cutter, &path, target, &options).expect("engagement");
        prop_assert!((r.move_phi[2] - std::f64::consts::PI).abs() <= options.angle_bound(), "slot {}", r.move_phi[2]);
        let tolerance = bound(target, &options);
        prop_assert!(
            (r.move_phi[6] - target).abs() <= tolerance,
            "ae {ae}: {} deg against {} (bound {})",
            r.move_phi[6].to_degrees(),
            target.to_degrees(),
            tolerance.to_degrees()
        );
        prop_assert_eq!((r.entries, r.retracts), (2, 2));
    }
}

/// A pass whose tool only touches material standing beside it (the stock
/// beyond R, which it does not cut, as a finishing contour at the allowance
/// touches the wall) reads no engagement, on a stock cleared by an earlier
/// program; the same pass 0.5 mm into that material reads its radial depth.
#[test]
fn running_along_standing_material_reads_no_engagement() {
    let cutter = Cutter::new(CutterShape::Flat { radius: R }, 20.0).expect("cutter");
    // Slots at y = 5 to 20 clear y < 23 between x = 7 and 53 (the first
    // pass's own slot is only the stock's).
    let mut clearing = passes(&[(5.0, 50.0), (10.0, 50.0), (15.0, 50.0), (20.0, 50.0)], -2.0);
    let mut stock = stock();
    stock.cut(&cutter, &clearing).expect("clearing");
    let options = EngagementOptions::default();
    for (y, expected) in [(20.0, 0.0), (20.5, engagement_angle(0.5, R))] {
        clearing = passes(&[(y, 45.0)], -2.0);
        let r = stock_engagement(&stock, &cutter, &clearing, 1.0, &options).expect("engagement");
        let phi = r.move_phi[2];
        let tolerance = if expected > 0.0 { bound(expected, &options) } else { options.angle_bound() };
        assert!(
            (phi - expected).abs() <= tolerance,
            "y {y}: {} deg, expected {}",
            phi.to_degrees(),
            expected.to_degrees()
        );
    }
}

/// Bad options and a stock too coarse for the tool are errors, not figures.
#[test]
fn a_stock_coarser_than_the_tool_is_refused() {
    let cutter = Cutter::new(CutterShape::Flat { radius: 0.05 }, 5.0).expect("cutter");
    let coarse = ZMap::new(Aabb3 { min: p(0.0, 0.0, -1.0), max: p(10.0, 10.0, 0.0) }, 0.2).expect("stock");
    let path = passes(&[(5.0, 9.0)], -0.5);
    assert!(stock_engagement(&coarse, &cutter, &path, 1.0, &EngagementOptions::default()).is_err());
    let options = EngagementOptions { sample_step: f64::NAN, ..EngagementOptions::default() };
    assert!(stock_engagement(&stock(), &cutter, &path, 1.0, &options).is_err());
}

/// A descent at cutting depth is an entry, however the tool came there: a
/// slot at z = -1, a plunge to z = -2 at its end (a tool-down link to the
/// next level) and the slot back. The plunge is the second entry, its bottom
/// reads the material all round it (180 degrees for the fuller half), and the
/// slot back is reported apart within 2 R of it, outside from there on
/// (before, the plunge was no entry and read nothing).
#[test]
fn a_plunge_at_depth_is_an_entry() {
    let cutter = Cutter::new(CutterShape::Flat { radius: R }, 20.0).expect("cutter");
    let mut path = Toolpath::new(1000.0);
    path.push(Move::new(MoveKind::Rapid, p(10.0, 20.0, 5.0)));
    path.push(Move::new(MoveKind::Plunge, p(10.0, 20.0, -1.0)));
    path.push(Move::new(MoveKind::Feed, p(50.0, 20.0, -1.0)));
    path.push(Move::new(MoveKind::Plunge, p(50.0, 20.0, -2.0)));
    path.push(Move::new(MoveKind::Feed, p(10.0, 20.0, -2.0)));
    path.push(Move::new(MoveKind::Retract, p(10.0, 20.0, 5.0)));
    let options = EngagementOptions::default();
    let target = engagement_angle(1.2, R);
    let r = stock_engagement(&stock(), &cutter, &path, target, &options).expect("engagement");
    assert_eq!((r.entries, r.retracts), (2, 1), "{r:?}");
    assert!((r.move_phi[3] - std::f64::consts::PI).abs() <= options.angle_bound(), "plunge {}", r.move_phi[3]);
    assert!((r.entry_max - std::f64::consts::PI).abs() <= options.angle_bound(), "{r:?}");
    // Both slots outside their entries' 2 R: 40 - 6 mm each.
    assert!((r.slot_length - 68.0).abs() <= 2.0 * options.sample_step, "{r:?}");
}
