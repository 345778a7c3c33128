//! Criterion benchmark of the fast network planner (finishing.md 6.3-6.5, 7,
//! 12.2; issues 3 and 8) on the Choi and Rubio surfaces at the specification's
//! settings: 0.5 mm machining mesh, bull-nose R = 5, r = 2 mm, sh = 0.01 mm,
//! V = 5 m/min, A = 6 m/s^2, J = 40 m/s^3. Single-threaded (the planner uses no
//! threads). Run: `cargo bench -p scallop-strategy --bench network`.
//!
//! - `network_build/<surface>`: the 0.5 mm network (once per surface, or per
//!   3+2 orientation for the rotation only);
//! - `whole_surface/<surface>`: one zone, feed along the PCA steepest-slope
//!   direction, plus the surface time (issue 3's "planning one finishing");
//! - `whole_surface_toolpath/<surface>`: the same plan turned into a toolpath
//!   (`network_toolpath`: drop-cutter locations on the part tessellated at the
//!   default tolerances, links, retracts), on one rayon thread: what
//!   `finishing.strategy = "network"` plans before the post and the simulation;
//! - `black_box_80x80_k<K>/<surface>`: one black-box evaluation (12.2) after the
//!   clustering: a K-zone 80 x 80 labelling prepared ([`Zoning::new`]), zone `i`
//!   planned along `theta + 0.37 i` (directions all around, as an optimiser
//!   explores them), surface time with the default transitions (issue 8's "one
//!   black-box evaluation at 80 x 80"); `_slope`: every zone along the surface's
//!   steepest-slope direction (the spec's start point, fewer planes).

use std::f64::consts::PI;

use criterion::{Criterion, criterion_group, criterion_main};
use scallop_analysis::{Cutter, GridOptions, MachineLimits, ToolOptions, analyze, sample_patch};
use scallop_cutter::CutterShape;
use scallop_geom::Tolerances;
use scallop_mesh::MeshIndex;
use scallop_network::{
    CellLabels, Margins, Network, Transitions, ZoneParams, Zoning, network_toolpath, plan_zone, plan_zones,
    surface_time,
};
use scallop_strategy::{Boundary, FinishingParams, Pattern};

/// A deterministic K-zone labelling of an 80 x 80 grid: K angular sectors
/// around an off-centre point, with wavy borders (non-convex zones).
fn sectors(k: u32) -> CellLabels {
    let n = 80;
    let mut labels = Vec::with_capacity(n * n);
    for a in 0..n {
        for b in 0..n {
            let (u, v) = ((a as f64 + 0.5) / n as f64 - 0.43, (b as f64 + 0.5) / n as f64 - 0.57);
            let angle = v.atan2(u) + PI + 0.3 * (9.0 * (u * u + v * v).sqrt()).sin();
            let sector = ((angle.rem_euclid(2.0 * PI)) / (2.0 * PI) * f64::from(k)).floor();
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
            labels.push((sector as u32).min(k - 1));
        }
    }
    CellLabels { cells_u: n, cells_v: n, labels }
}

fn bench(c: &mut Criterion) {
    let machine = MachineLimits::from_thesis_units(5.0, 6.0, 40.0);
    let params = |direction: f64| ZoneParams {
        direction,
        tool: Cutter::Toroidal { radius: 5.0, corner: 2.0 },
        scallop_height: 0.01,
        margins: Margins::HalfStep,
        sharp_corner: 30f64.to_radians(),
        machine,
    };
    let transitions = Transitions::default();
    for name in ["choi", "rubio"] {
        let set = scallop_surface::builtin(name).expect("built-in surface");
        let patch = &set.patches()[0];
        let samples = sample_patch(patch, &GridOptions::default()).expect("samples");
        let analysis = analyze(&samples, &ToolOptions::default(), &machine, 0.01).expect("analysis");
        let theta = analysis.slope_direction_deg.to_radians();
        let mut group = c.benchmark_group("network");
        group.sample_size(20);
        group.bench_function(format!("network_build/{name}"), |b| {
            b.iter(|| Network::new(patch, 0.5).expect("network"));
        });
        let network = Network::new(patch, 0.5).expect("network");
        group.bench_function(format!("whole_surface/{name}"), |b| {
            b.iter(|| {
                let plan = plan_zone(&network, None, 0, &params(theta)).expect("plan");
                surface_time(std::slice::from_ref(&plan), &transitions, &machine).total_s
            });
        });
        // Issue 3's finishing with cutter locations: the plan above, then the
        // drop-cutter locations of its passes on the tessellated part (the
        // engine's default tolerances), links and retracts: a whole toolpath.
        let tolerances = Tolerances { path: 0.01, gouge: 0.0 }; // the demo job's
        let mesh = set.tessellate(tolerances.tessellation()).expect("tessellation").mesh;
        let index = MeshIndex::build(&mesh);
        let cutter = scallop_cutter::Cutter::new(CutterShape::Bull { radius: 5.0, corner: 2.0 }, 30.0).expect("cutter");
        let finishing = FinishingParams {
            direction: theta,
            pattern: Pattern::Zigzag,
            scallop_height: 0.01,
            boundary: Boundary::ContactInside,
            max_step: 0.5,
            clearance: 5.0,
            machine,
            plunge_feed: machine.feed / 4.0,
            rapid_rate: 1000.0,
            sharp_corner: 30f64.to_radians(),
            blend_tolerance: tolerances.path,
        };
        let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("pool");
        group.bench_function(format!("whole_surface_toolpath/{name}"), |b| {
            b.iter(|| {
                one.install(|| {
                    let plan = plan_zone(&network, None, 0, &params(theta)).expect("plan");
                    network_toolpath(&network, std::slice::from_ref(&plan), &index, &cutter, &finishing, &tolerances)
                        .expect("toolpath")
                        .toolpath
                        .moves()
                        .len()
                })
            });
        });
        for (k, spread) in [(3u32, 0.37), (6, 0.37), (10, 0.37), (10, 0.0)] {
            let labels = sectors(k);
            let id = if spread > 0.0 { format!("black_box_80x80_k{k}") } else { format!("black_box_80x80_k{k}_slope") };
            group.bench_function(format!("{id}/{name}"), |b| {
                b.iter(|| {
                    let zoning = Zoning::new(&network, &labels).expect("zoning");
                    let directions: Vec<f64> = (0..zoning.zones().len()).map(|i| theta + spread * i as f64).collect();
                    let plans = plan_zones(&network, &zoning, &directions, &params(theta)).expect("plans");
                    surface_time(&plans, &transitions, &machine).total_s
                });
            });
        }
        group.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
