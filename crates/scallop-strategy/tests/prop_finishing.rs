//! Property tests of parallel-planes finishing on random Bezier patches:
//! verified scallop within `sh` for ball, flat and bull-nose cutters, no CL
//! point off the drop-cutter surface, coverage of the region, and thread
//! independence.
#![allow(clippy::unwrap_used)]

mod common;

use common::{ball, bull, flat, params};
use proptest::prelude::*;
use scallop_cutter::{Contact, Cutter, drop_cutter};
use scallop_geom::{Point2, Point3, Tolerances};
use scallop_mesh::MeshIndex;
use scallop_strategy::{Pattern, Planned, StrategyError, plan_finishing};
use scallop_surface::{Patch, SurfaceSet};
use scallop_toolpath::MoveKind;

const TOL: Tolerances = Tolerances { path: 0.05, gouge: 0.0 };

/// A bicubic Bezier patch over 24 x 24 mm with control heights `z`.
fn patch(z: &[f64; 16]) -> SurfaceSet {
    let control: Vec<Vec<Point3>> =
        (0..4).map(|i| (0..4).map(|j| Point3::new(8.0 * i as f64, 8.0 * j as f64, z[4 * i + j])).collect()).collect();
    SurfaceSet::new(vec![Patch::bezier("random", [3, 3], &control, None).unwrap()]).unwrap()
}

fn index_of(set: &SurfaceSet) -> MeshIndex {
    MeshIndex::build(&set.tessellate(TOL.tessellation()).unwrap().mesh)
}

/// Every CL point of the toolpath is its own drop-cutter point, and the
/// midpoint of every cutting move is within the path budget of the drop-cutter
/// surface (never deeper).
fn check_no_gouge(planned: &Planned, index: &MeshIndex, cutter: &Cutter) {
    let floor = index.bounds().min.z - 100.0;
    let moves = planned.toolpath.moves();
    for w in moves.windows(2) {
        if !matches!(w[1].kind, MoveKind::Feed | MoveKind::Link) {
            continue;
        }
        let p = w[1].to;
        let cl = drop_cutter(cutter, index, Point2::new(p.x, p.y), floor);
        assert!((cl.tip.z - p.z).abs() <= 1e-9, "CL point {p:?} is not on the drop-cutter surface ({})", cl.tip.z);
        let mid = nalgebra_mid(&w[0].to, &p);
        let cl = drop_cutter(cutter, index, Point2::new(mid.x, mid.y), floor);
        assert!(
            cl.tip.z - mid.z <= 0.75 * TOL.path + 1e-9,
            "move midpoint {mid:?} is {} below the CL surface",
            cl.tip.z - mid.z
        );
    }
}

fn nalgebra_mid(a: &Point3, b: &Point3) -> Point3 {
    Point3::from((a.coords + b.coords) * 0.5)
}

/// Every surface sample lies within one step-over of a contact point of a pass.
fn check_coverage(planned: &Planned, set: &SurfaceSet, index: &MeshIndex, cutter: &Cutter, step_over: f64) {
    let floor = index.bounds().min.z - 100.0;
    let mut contacts = Vec::new();
    for plane in &planned.planes {
        for pass in &plane.passes {
            for w in pass.windows(2) {
                let n = ((w[1] - w[0]).xy().norm() / 0.25).ceil().max(1.0) as usize;
                for k in 0..=n {
                    let p = w[0] + (w[1] - w[0]) * (k as f64 / n as f64);
                    match drop_cutter(cutter, index, Point2::new(p.x, p.y), floor).contact {
                        Contact::Vertex { point, .. } | Contact::Edge { point, .. } | Contact::Facet { point, .. } => {
                            contacts.push(point);
                        }
                        Contact::Floor => {}
                    }
                }
            }
        }
    }
    let surface = &set.patches()[0];
    for i in 0..12 {
        for j in 0..12 {
            let (u, v) = ((i as f64 + 0.5) / 12.0, (j as f64 + 0.5) / 12.0);
            let p = surface.point(u, v);
            let d = contacts.iter().map(|c| (c - p).norm()).fold(f64::INFINITY, f64::min);
            assert!(d <= step_over + 0.25, "surface point {p:?} is {d} mm from every contact (step-over {step_over})");
        }
    }
}

fn run(z: &[f64; 16], cutter: &Cutter, model: scallop_analysis::Cutter, sh: f64, direction: f64, pattern: Pattern) {
    let set = patch(z);
    let index = index_of(&set);
    let p = params(direction, pattern, sh, 1.5);
    let planned = match plan_finishing(&index, cutter, &p, &TOL) {
        Ok(planned) => planned,
        Err(StrategyError::Unreachable { .. }) => {
            // A flat end across a slope, or a bull-nose's flat bottom over a hollow,
            // cannot hold sh: the planner's documented refusal (never a gouge). A
            // ball can be refused too, falsely (`ball_false_refusal_is_safe`): safe,
            // and a known defect of the scallop measure.
            return;
        }
        Err(e) => panic!("{e}"),
    };
    assert!(planned.scallop.max_mm <= sh * (1.0 + 1e-6), "{} > {sh}", planned.scallop.max_mm);
    assert!(planned.scallop.samples > 0);
    check_no_gouge(&planned, &index, cutter);
    check_coverage(&planned, &set, &index, cutter, model.max_step_over(sh));
}

fn heights(amplitude: f64) -> impl Strategy<Value = [f64; 16]> {
    prop::array::uniform16(-amplitude..amplitude)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 4, ..ProptestConfig::default() })]

    #[test]
    fn ball_scallop_within_sh(z in heights(2.5), r in 2.0..6.0f64, sh in 0.02..0.06f64, dir in 0.0..3.1f64, zigzag in any::<bool>()) {
        let pattern = if zigzag { Pattern::Zigzag } else { Pattern::OneWay };
        run(&z, &ball(r), scallop_analysis::Cutter::Ball { radius: r }, sh, dir, pattern);
    }

    #[test]
    fn bull_scallop_within_sh(z in heights(1.5), r in 3.0..6.0f64, corner_frac in 0.3..0.8f64, sh in 0.02..0.06f64, dir in 0.0..3.1f64, zigzag in any::<bool>()) {
        let pattern = if zigzag { Pattern::Zigzag } else { Pattern::OneWay };
        let corner = r * corner_frac;
        run(&z, &bull(r, corner), scallop_analysis::Cutter::Toroidal { radius: r, corner }, sh, dir, pattern);
    }

    #[test]
    fn flat_scallop_within_sh(z in heights(0.5), r in 2.0..5.0f64, sh in 0.03..0.06f64, dir in 0.0..3.1f64) {
        run(&z, &flat(r), scallop_analysis::Cutter::Toroidal { radius: r, corner: 0.0 }, sh, dir, Pattern::Zigzag);
    }
}

#[test]
fn output_is_identical_on_one_and_two_threads() {
    let z = [0.0, 1.0, -0.5, 0.5, 1.0, 1.5, 1.2, -1.0, -0.7, 0.0, 2.0, 0.5, 0.5, -1.5, 0.5, 1.0];
    let set = patch(&z);
    let index = index_of(&set);
    let cutter = bull(5.0, 2.0);
    let p = params(0.3, Pattern::Zigzag, 0.03, 1.5);
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    let two = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    let a = one.install(|| plan_finishing(&index, &cutter, &p, &TOL).unwrap());
    let b = two.install(|| plan_finishing(&index, &cutter, &p, &TOL).unwrap());
    assert_eq!(a, b);
}

/// A case the bull-nose property test found (2026-11-23): near the corner at
/// (0, 24) the planes between offsets 15.9 and 21.7 have no interior contact (the
/// cutter rides on the patch's raised edge), so the sweep makes two ranges, and the
/// surface between the last plane of the first range and the first of the second
/// stood 0.068 mm > sh above the cutter. The sweep now bridges such gaps with
/// planes that accept boundary contacts (`Planner::bridge`), and the final check
/// holds. Before the fix planning failed with its own safety error.
#[test]
fn bull_gap_between_ranges_is_bridged() {
    let z = [
        -1.1328400216447208,
        -0.5500051951164447,
        0.9879181724244479,
        0.3515186804546003,
        -0.35831540904342096,
        -1.1981258397392003,
        -0.2648774657980002,
        0.47875760033956377,
        -0.0408368926426085,
        -0.6057342324724233,
        0.4429685856563578,
        1.0918096604605243,
        -0.3987714769638035,
        0.7105566507573391,
        -0.9228318724130498,
        -0.6943006927241776,
    ];
    let (r, corner) = (5.112451450197818, 5.112451450197818 * 0.32719208614781);
    run(
        &z,
        &bull(r, corner),
        scallop_analysis::Cutter::Toroidal { radius: r, corner },
        0.05316420986032395,
        0.576614066567737,
        Pattern::Zigzag,
    );
}

/// A ball case the property test found (2026-11-25): the measured planner
/// refuses it (`Unreachable` near (5.49, 16.39), "spacing would be 0.035 mm")
/// although the surface there is reachable: drop-cutter balls placed every
/// r / 100 around that place leave at most 0.0005 mm of material (checked once
/// by hand; the check is too slow for every run). A false refusal, on the safe
/// side: the planner's scallop measure sees a cusp over sh that no spacing
/// removes (the defect documented in docs/validation.md, "Known defects"). The
/// test pins the contract that holds: a verified plan or a refusal, never an
/// unverified plan, a gouge or a panic.
#[test]
fn ball_false_refusal_is_safe() {
    let z = [
        0.0,
        0.0,
        -2.3359518833421062,
        0.9973709134668522,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        1.4239842666821885,
        0.0,
        0.0,
        0.0,
        2.0979484936410806,
        -1.5963516938647917,
        -1.4502344916091872,
    ];
    let (r, sh, dir) = (2.6330323012022143, 0.022968544537423724, 1.987678246352003);
    run(&z, &ball(r), scallop_analysis::Cutter::Ball { radius: r }, sh, dir, Pattern::Zigzag);
}
