//! Isoparametric finishing on random bicubic Bezier patches: the scallop measured
//! independently between every pair of adjacent passes stays <= sh, no cutter
//! location lies below the drop-cutter height (no gouge of the mesh), and the
//! passes cover the patch from one iso edge to the other.

mod common;

use common::{ball, bull, params};
use proptest::prelude::*;
use scallop_cutter::{Cutter, CutterShape, drop_cutter};
use scallop_geom::{Point2, Point3, Tolerances};
use scallop_mesh::MeshIndex;
use scallop_strategy::{
    IsoDirection, IsoSurface, Pattern, StrategyError, iso_fitted_passes, iso_scallop, plan_isoparametric,
};
use scallop_surface::Patch;
use scallop_toolpath::MoveKind;

fn patch(heights: &[f64]) -> Patch {
    let control: Vec<Vec<Point3>> = (0..4)
        .map(|i| {
            (0..4)
                .map(|j| Point3::new(10.0 * f64::from(i), 10.0 * f64::from(j), heights[4 * i as usize + j as usize]))
                .collect()
        })
        .collect();
    Patch::bezier("random", [3, 3], &control, None).expect("valid")
}

fn check(patch: &Patch, cutter: &Cutter, direction: IsoDirection, sh: f64) {
    let tol = Tolerances { path: 0.01, gouge: 0.0 };
    let t = patch.tessellate(tol.tessellation()).expect("tessellates");
    let index = MeshIndex::build(&t.mesh);
    let p = params(0.0, Pattern::Zigzag, sh, 1.0);
    let planned = match plan_isoparametric(
        &IsoSurface { patch, index: &index, chordal_error: t.chordal_bound },
        cutter,
        &p,
        direction,
        &tol,
    ) {
        Ok(planned) => planned,
        // The planner's documented refusal for a bull-nose, never an unsafe plan. Known
        // defect (issue 3): in a hollow tighter than the bull-nose the measured height
        // can grow as the gap shrinks (see `known_defect_iso_bull_in_a_tight_hollow`).
        Err(StrategyError::Unreachable { .. }) if matches!(cutter.shape(), CutterShape::Bull { .. }) => return,
        Err(e) => panic!("plans: {e}"),
    };
    assert!(planned.max_scallop_mm <= sh * (1.0 + 1e-6), "{} > {sh}", planned.max_scallop_mm);
    // Independent re-measurement of every adjacent pair.
    for w in planned.passes.windows(2) {
        let h = iso_scallop(patch, &index, cutter, direction, &w[0], &w[1]);
        let worst = h.iter().copied().fold(0.0, f64::max);
        assert!(worst + t.chordal_bound <= sh * (1.0 + 1e-6), "pair at {}: {worst}", w[0].iso);
    }
    // Coverage: from one iso edge to the other.
    let d = patch.domain();
    let across = if direction == IsoDirection::U { d.v } else { d.u };
    assert_eq!(planned.passes.first().map(|p| p.iso), Some(across[0]));
    assert_eq!(planned.passes.last().map(|p| p.iso), Some(across[1]));
    // No gouge: every cutting vertex is at or above the drop-cutter height.
    for m in planned.toolpath.moves().iter().filter(|m| m.kind == MoveKind::Feed) {
        let cl = drop_cutter(cutter, &index, Point2::new(m.to.x, m.to.y), -100.0);
        assert!(m.to.z >= cl.tip.z - 1e-9, "{} below {}", m.to, cl.tip);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(6))]
    #[test]
    fn random_bezier_patches_keep_the_scallop(
        heights in prop::collection::vec(-3.0..3.0f64, 16),
        along_u in any::<bool>(),
        use_ball in any::<bool>(),
    ) {
        let cutter = if use_ball { ball(3.0) } else { bull(4.0, 1.5) };
        let direction = if along_u { IsoDirection::U } else { IsoDirection::V };
        check(&patch(&heights), &cutter, direction, 0.01);
    }
}

#[test]
fn a_plane_patch_gets_the_analytic_step_over() {
    // A flat 30 x 30 patch with a ball R3 at sh 0.01: sod = 2 sqrt(2 sh R - sh^2) = 0.4894 mm,
    // so ceil(30 / 0.4894) + 1 = 63 passes at most (the measured fit may only shrink it).
    let flat = patch(&[0.0; 16]);
    let tol = Tolerances { path: 0.01, gouge: 0.0 };
    let t = flat.tessellate(tol.tessellation()).expect("tessellates");
    let index = MeshIndex::build(&t.mesh);
    let p = params(0.0, Pattern::Zigzag, 0.01, 1.0);
    let planned = plan_isoparametric(
        &IsoSurface { patch: &flat, index: &index, chordal_error: t.chordal_bound },
        &ball(3.0),
        &p,
        IsoDirection::U,
        &tol,
    )
    .expect("plans");
    let sod = 2.0 * (2.0f64 * 0.01 * 3.0 - 0.0001).sqrt();
    let analytic = (30.0 / sod).ceil() as usize + 1;
    assert!(
        planned.passes.len() >= analytic - 1 && planned.passes.len() <= analytic + 2,
        "{} passes for {analytic}",
        planned.passes.len()
    );
    check(&flat, &ball(3.0), IsoDirection::U, 0.01);
}

/// A case the property test found (2026-11-25): a bull-nose R4 r1.5 along u on this
/// patch. In a hollow near (12.0, 7.2) mm the cutter is held up (the tip touching the
/// surface there, dropped, stays 0.018 mm away) and the measured height between two
/// passes grows from 0.0086 mm to 0.0164 mm as the step shrinks from 0.017 to 0.005:
/// the rest-material estimate of `iso_scallop` (one placement per surface point) does
/// not match what the passes' own held-up placements leave, so the planner refuses
/// (`Unreachable`) though a plan exists: an open defect of issue 3. Whatever it does,
/// it must never give an unverified plan: a plan is checked like every other one, a
/// refusal must be `Unreachable`.
#[test]
fn iso_bull_in_a_tight_hollow_is_verified_or_refused() {
    let heights = [
        -1.667707237410849,
        0.0,
        -1.04742715362713,
        0.0,
        1.7558682456584243,
        -1.237923468992292,
        1.2853436048567337,
        0.0,
        0.0,
        -1.5079348879120646,
        2.877544688255003,
        -1.4057805416228413,
        -2.4316493078139154,
        0.0,
        0.0,
        2.266273662811149,
    ];
    let patch = patch(&heights);
    let tol = Tolerances { path: 0.01, gouge: 0.0 };
    let t = patch.tessellate(tol.tessellation()).expect("tessellates");
    let index = MeshIndex::build(&t.mesh);
    let p = params(0.0, Pattern::Zigzag, 0.01, 1.0);
    match plan_isoparametric(
        &IsoSurface { patch: &patch, index: &index, chordal_error: t.chordal_bound },
        &bull(4.0, 1.5),
        &p,
        IsoDirection::U,
        &tol,
    ) {
        Ok(_) => check(&patch, &bull(4.0, 1.5), IsoDirection::U, 0.01),
        Err(e) => assert!(matches!(e, StrategyError::Unreachable { .. }), "{e}"),
    }
}

/// The estimate of `scallop run --plan-only` (the planner's step fit at 8
/// isolines, the cross range walked with those steps) counts the planner's
/// passes within 10 % on a plane, a dome and a saddle, both directions.
#[test]
fn the_fitted_estimate_counts_the_planners_passes() {
    let tol = Tolerances { path: 0.01, gouge: 0.0 };
    let dome = [0.0, 0.0, 0.0, 0.0, 0.0, 4.0, 4.0, 0.0, 0.0, 4.0, 4.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    let saddle = [3.0, 0.0, 0.0, -3.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -3.0, 0.0, 0.0, 3.0];
    for heights in [[0.0; 16], dome, saddle] {
        let part = patch(&heights);
        let t = part.tessellate(tol.tessellation()).expect("tessellates");
        let index = MeshIndex::build(&t.mesh);
        let surface = IsoSurface { patch: &part, index: &index, chordal_error: t.chordal_bound };
        let p = params(0.0, Pattern::Zigzag, 0.01, 1.0);
        for direction in [IsoDirection::U, IsoDirection::V] {
            let planned = plan_isoparametric(&surface, &ball(3.0), &p, direction, &tol).expect("plans").passes.len();
            let estimated = iso_fitted_passes(&surface, &ball(3.0), &p, direction, &tol, 8).expect("estimates");
            #[allow(clippy::cast_precision_loss, reason = "pass counts")]
            let error = (estimated as f64 - planned as f64).abs() / planned as f64;
            assert!(error <= 0.1, "{heights:?} {direction:?}: estimated {estimated}, planned {planned}");
        }
    }
}
