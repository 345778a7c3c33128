//! The scallop guarantee of the network planner on random Bezier patches, for
//! ball, flat and toroidal cutters: between every pair of adjacent planes, every
//! pass vertex of both planes sees the gap within its own step-over, i.e. the
//! circle-model scallop (finishing.md 5.2) at that vertex, with its effective
//! radius from the **exact** surface normal at its `(u, v)` and the local
//! cross-feed distance `gap / |c . m|`, is at most `sh`.
#![allow(clippy::unwrap_used)]

mod network_common;

use network_common::{params, step_over_and_factor, vertices};
use proptest::prelude::*;
use scallop_analysis::{Cutter, effective_radius_for_step_over};
use scallop_geom::Point3;
use scallop_network::{Network, plan_zone};
use scallop_surface::Patch;

/// Relative slack of the check: rounding (the planner evaluates the same exact
/// normals from per-row tables, the check through `Patch::normal`) and the
/// sweep's acceptance of a gap up to `tol::LOOKAHEAD_REL` over a spacing.
const ROUNDING_SLACK: f64 = 1e-8;

fn patch(z: &[f64], size: [f64; 2]) -> Patch {
    let rows: Vec<Vec<Point3>> = (0..4)
        .map(|i| {
            (0..4).map(|j| Point3::new(size[0] * i as f64 / 3.0, size[1] * j as f64 / 3.0, z[i * 4 + j])).collect()
        })
        .collect();
    Patch::bezier("random", [3, 3], &rows, None).unwrap()
}

fn tool(kind: u8) -> (Cutter, f64) {
    match kind {
        0 => (Cutter::Ball { radius: 5.0 }, 0.01),
        1 => (Cutter::Toroidal { radius: 5.0, corner: 2.0 }, 0.01),
        _ => (Cutter::Toroidal { radius: 4.0, corner: 0.0 }, 0.05), // flat end
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, ..ProptestConfig::default() })]

    #[test]
    fn adjacent_planes_keep_the_scallop_below_sh(
        z in prop::collection::vec(-8.0f64..8.0, 16),
        size in (30.0f64..70.0, 30.0f64..70.0),
        theta in 0.0f64..std::f64::consts::PI,
        kind in 0u8..3,
    ) {
        let surface = patch(&z, [size.0, size.1]);
        let network = Network::new(&surface, 1.0).unwrap();
        let (cutter, sh) = tool(kind);
        let plan = plan_zone(&network, None, 0, &params(theta, cutter, sh)).unwrap();
        prop_assert!(plan.planes.len() >= 2);
        let points = vertices(&plan);
        let mut worst: f64 = 0.0;
        for (k, w) in plan.planes.windows(2).enumerate() {
            let gap = w[1].offset - w[0].offset;
            prop_assert!(gap > 0.0);
            for (_, p, uv) in points.iter().filter(|(i, _, _)| *i == k || *i == k + 1) {
                let n = surface.normal(uv[0], uv[1]);
                let (sod, factor) = step_over_and_factor(&n, theta, &cutter, sh);
                if factor <= 0.0 {
                    continue; // a vertical tangent across the feed: no cusp in this section
                }
                let across = gap / factor;
                let radius = effective_radius_for_step_over(sh, sod);
                let half = across * across / 4.0;
                let scallop = half / (radius + (radius * radius - half).max(0.0).sqrt());
                prop_assert!(
                    scallop <= sh * (1.0 + ROUNDING_SLACK),
                    "scallop {} > sh {} at {:?} (planes {}, {}; gap {}, vertex spacing {}, plane spacings {} {})",
                    scallop, sh, p, k, k + 1, gap, sod * factor, w[0].spacing, w[1].spacing
                );
                worst = worst.max(scallop / sh);
            }
        }
        // The rule is tight: some vertex sees (nearly) the full scallop.
        prop_assert!(worst > 0.9, "worst ratio {}", worst);
    }
}
