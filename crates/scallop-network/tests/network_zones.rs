//! Zones of the network planner (finishing.md 6.3, 7.4): clipping to the cells
//! of a label, several passes per plane on non-convex zones, the zones' passes
//! add up to the unlabelled passes, transitions, and the errors.
#![allow(clippy::unwrap_used)]

mod network_common;

use std::f64::consts::FRAC_PI_2;

use network_common::{inclined_plane, params, rel};
use proptest::prelude::*;
use scallop_analysis::{Cutter, MachineLimits};
use scallop_network::{
    CellLabels, Network, Pass, TransitionModel, Transitions, Zoning, plan_zone, plan_zones, plane_passes, surface_time,
};
use scallop_strategy::StrategyError;

const TORUS: Cutter = Cutter::Toroidal { radius: 5.0, corner: 2.0 };
const BALL: Cutter = Cutter::Ball { radius: 5.0 };

/// Label 1 on a U-shaped set of cells (open towards +v), 0 elsewhere.
fn u_shape(n: usize) -> CellLabels {
    let mut labels = Vec::with_capacity(n * n);
    for a in 0..n {
        for b in 0..n {
            let (u, v) = ((a as f64 + 0.5) / n as f64, (b as f64 + 0.5) / n as f64);
            let outer = (0.2..0.8).contains(&u) && (0.2..0.8).contains(&v);
            let notch = (0.4..0.6).contains(&u) && v >= 0.4;
            labels.push(u32::from(outer && !notch));
        }
    }
    CellLabels { cells_u: n, cells_v: n, labels }
}

fn length(passes: &[Pass]) -> f64 {
    passes.iter().map(|p| p.length).sum()
}

#[test]
fn a_non_convex_zone_gives_several_passes_per_plane() {
    let network = Network::new(&inclined_plane(56.0, 28.0, 0.5), 0.5).unwrap();
    let labels = u_shape(80);
    let zoning = Zoning::new(&network, &labels).unwrap();
    assert_eq!(zoning.zones(), &[0, 1]);
    // Feed along Y (u): planes of constant x cross both arms of the U.
    let plan = plan_zone(&network, Some(&zoning), 1, &params(FRAC_PI_2, BALL, 0.01)).unwrap();
    assert!(plan.planes.iter().any(|p| p.passes.len() == 2));
    assert!(plan.planes.iter().all(|p| p.passes.len() <= 2));
    // Every pass segment lies in a cell of the zone.
    for plane in &plan.planes {
        for pass in &plane.passes {
            for w in pass.params.windows(2) {
                let mid = [0.5 * (w[0][0] + w[1][0]), 0.5 * (w[0][1] + w[1][1])];
                assert_eq!(labels.label_at(mid[0], mid[1]), 1, "{mid:?}");
            }
        }
    }
    assert_eq!(plan.connections.len(), plan.passes - 1);
    // Both zones in label order, joined by one transition.
    let machine = MachineLimits::default();
    let plans = plan_zones(&network, &zoning, &[0.0, FRAC_PI_2], &params(0.0, BALL, 0.01)).unwrap();
    assert_eq!(plans.iter().map(|p| p.zone).collect::<Vec<_>>(), vec![0, 1]);
    assert_eq!(plans[1], plan);
    let total = surface_time(&plans, &Transitions::default(), &machine);
    let (t, l) = Transitions::default().time(&plans[0].end, &plans[1].start, &machine);
    assert!(l >= 10.0 && t > 0.0);
    assert!(rel(total.total_s, plans[0].time_s + plans[1].time_s + t) < 1e-12);
    assert!(rel(total.transition_length_mm, l) < 1e-12);
    // A linear transition is never longer than retract-traverse-plunge.
    let linear = Transitions { model: TransitionModel::Linear, reorientation_s: 0.0 };
    assert!(surface_time(&plans, &linear, &machine).transition_length_mm < l);
}

#[test]
fn zone_plans_add_up_to_the_whole_surface_with_a_ball_on_a_plane() {
    // Constant spacing: each zone's planes cover its own extent; the cut
    // lengths add up to the whole plan's up to the half-step margins.
    let network = Network::new(&inclined_plane(56.0, 40.0, 0.6), 0.5).unwrap();
    let labels = u_shape(80);
    let zoning = Zoning::new(&network, &labels).unwrap();
    let whole = plan_zone(&network, None, 0, &params(0.2, BALL, 0.01)).unwrap();
    let plans = plan_zones(&network, &zoning, &[0.2, 0.2], &params(0.2, BALL, 0.01)).unwrap();
    let sum: f64 = plans.iter().map(|p| p.cut_length_mm).sum();
    assert!(rel(sum, whole.cut_length_mm) < 0.02, "{sum} vs {}", whole.cut_length_mm);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// On any plane offset, the passes of all zones of a random labelling add
    /// up to the unlabelled passes (up to dropped pieces shorter than 1 um).
    #[test]
    fn zones_partition_every_plane(
        cells in (1usize..9, 1usize..9),
        seed in prop::collection::vec(0u32..4, 81),
        theta in 0.0f64..std::f64::consts::PI,
        fraction in 0.02f64..0.98,
        step in 0.4f64..3.0,
    ) {
        let set = scallop_surface::builtin("choi").unwrap();
        let network = Network::new(&set.patches()[0], step).unwrap();
        let labels = CellLabels { cells_u: cells.0, cells_v: cells.1, labels: seed[..cells.0 * cells.1].to_vec() };
        let zoning = Zoning::new(&network, &labels).unwrap();
        let p = params(theta, TORUS, 0.01);
        let m = [-theta.sin(), theta.cos()];
        let g: Vec<f64> = network.points().iter().map(|q| m[0] * q.x + m[1] * q.y).collect();
        let (lo, hi) = g.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, &x| (a.0.min(x), a.1.max(x)));
        let offset = lo + fraction * (hi - lo);
        let whole = plane_passes(&network, None, 0, &p, offset).unwrap();
        let mut sum = 0.0;
        let mut spacing = f64::INFINITY;
        for &zone in zoning.zones() {
            let part = plane_passes(&network, Some(&zoning), zone, &p, offset).unwrap();
            sum += length(&part.passes);
            spacing = spacing.min(part.spacing);
            for pass in &part.passes {
                for w in pass.params.windows(2) {
                    let mid = [0.5 * (w[0][0] + w[1][0]), 0.5 * (w[0][1] + w[1][1])];
                    prop_assert_eq!(labels.label_at(mid[0], mid[1]), zone);
                }
            }
        }
        let total = length(&whole.passes);
        prop_assert!((sum - total).abs() <= 1e-9 * total + 2e-3 * labels.labels.len() as f64, "{} vs {}", sum, total);
        // The vertices of the zones include the plane's: the spacing cannot grow.
        prop_assert!(spacing <= whole.spacing * (1.0 + 1e-12));
    }
}

#[test]
fn bad_inputs_are_errors_naming_the_fix() {
    let network = Network::new(&inclined_plane(20.0, 10.0, 0.3), 1.0).unwrap();
    let flat = Cutter::Flat { radius: 5.0, inclination: 0.2 };
    assert!(matches!(plan_zone(&network, None, 0, &params(0.0, flat, 0.01)), Err(StrategyError::Unsupported { .. })));
    assert!(matches!(
        plan_zone(&network, None, 0, &params(0.0, TORUS, 2.5)),
        Err(StrategyError::ScallopTooLarge { .. })
    ));
    assert!(matches!(
        plan_zone(&network, None, 0, &params(f64::NAN, TORUS, 0.01)),
        Err(StrategyError::BadParameter { name: "direction", .. })
    ));
    let short = CellLabels { cells_u: 4, cells_v: 4, labels: vec![0; 15] };
    assert!(matches!(Zoning::new(&network, &short), Err(StrategyError::BadLabels { .. })));
    let labels = CellLabels { cells_u: 2, cells_v: 2, labels: vec![0, 0, 3, 3] };
    let zoning = Zoning::new(&network, &labels).unwrap();
    let err = plan_zone(&network, Some(&zoning), 1, &params(0.0, TORUS, 0.01)).unwrap_err();
    assert!(matches!(err, StrategyError::EmptyZone { zone: 1 }));
    assert!(err.to_string().contains("Zoning::zones"));
    assert!(matches!(
        plan_zones(&network, &zoning, &[0.0], &params(0.0, TORUS, 0.01)),
        Err(StrategyError::BadParameter { name: "directions", .. })
    ));
    let other = Network::new(&inclined_plane(20.0, 10.0, 0.3), 0.5).unwrap();
    assert!(matches!(
        plan_zone(&other, Some(&zoning), 0, &params(0.0, TORUS, 0.01)),
        Err(StrategyError::BadLabels { .. })
    ));
    assert!(matches!(Network::new(&inclined_plane(20.0, 10.0, 0.3), 0.0), Err(StrategyError::BadParameter { .. })));
}

/// `oriented_for` rotates the nodes of the given zones exactly as `oriented`
/// does, leaves the others NaN, and a zone plans the same on both, with one
/// reused workspace or a fresh one.
#[test]
fn a_zone_plans_the_same_on_a_partly_oriented_network() {
    use scallop_network::{Orientation, ZoneWorkspace, plan_zone_with};
    let set = scallop_surface::builtin("rubio").unwrap();
    let network = Network::new(&set.patches()[0], 1.0).unwrap();
    let zoning = Zoning::new(&network, &u_shape(40)).unwrap();
    let o = Orientation::new(0.4, 2.1, scallop_geom::Point3::new(3.0, -2.0, 1.0));
    let full = network.oriented(&o);
    let part = network.oriented_for(&o, &zoning, &[1]);
    let (rotated, untouched) = full.points().iter().zip(part.points()).fold((0, 0), |(r, u), (a, b)| {
        if b.x.is_nan() {
            (r, u + 1)
        } else {
            assert_eq!(a.coords.map(f64::to_bits), b.coords.map(f64::to_bits));
            (r + 1, u)
        }
    });
    assert!(rotated > 0 && untouched > 0, "{rotated} rotated, {untouched} left");
    assert!(!part.is_accessible());
    let mut workspace = ZoneWorkspace::default();
    for cutter in [TORUS, BALL] {
        let p = params(0.7, cutter, 0.01);
        let on_full = plan_zone(&full, Some(&zoning), 1, &p).unwrap();
        let on_part = plan_zone_with(&part, Some(&zoning), 1, &p, &mut workspace).unwrap();
        assert_eq!(on_full, on_part);
        // The workspace also serves another zone on another network.
        let other = plan_zone_with(&network, Some(&zoning), 0, &p, &mut workspace).unwrap();
        assert_eq!(other, plan_zone(&network, Some(&zoning), 0, &p).unwrap());
    }
}
