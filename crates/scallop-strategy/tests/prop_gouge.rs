//! No gouge between cutter locations (issue 15, item 5): along every feed and
//! link move of a planned toolpath, the straight move between two cutter
//! locations never lies below the exact drop-cutter (CL) surface by more than
//! the sampling share of the path tolerance. Parts with steep descents are
//! generated here: terrains with a cliff, a hemisphere on a plate and steps,
//! finished in random directions; each move is checked at 16 points by
//! `scallop_cutter::drop_cutter`.
#![allow(clippy::unwrap_used)]

mod common;

use common::{ball, bull, params};
use proptest::prelude::*;
use scallop_cutter::{Cutter, drop_cutter};
use scallop_geom::{Point2, Point3, Tolerances};
use scallop_mesh::{MeshIndex, TriMesh};
use scallop_strategy::{Pattern, Planned, plan_finishing, tol};
use scallop_toolpath::MoveKind;

const TOL: Tolerances = Tolerances { path: 0.02, gouge: 0.0 };

/// Points checked per move (the move's ends are its own cutter locations).
const CHECKS_PER_MOVE: usize = 16;

/// A height field `z(x, y)` on the grid `xs` x `ys`, two triangles a cell.
fn height_field(xs: &[f64], ys: &[f64], z: impl Fn(f64, f64) -> f64) -> MeshIndex {
    let mut soup = Vec::new();
    for i in 0..xs.len() - 1 {
        for j in 0..ys.len() - 1 {
            let p = |a: usize, b: usize| Point3::new(xs[a], ys[b], z(xs[a], ys[b]));
            soup.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
            soup.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
        }
    }
    MeshIndex::build(&TriMesh::from_soup(&soup).unwrap().0)
}

/// `0, step, .., size` with the extra abscissae `extra` (sorted, deduplicated).
fn grid(size: f64, step: f64, extra: &[f64]) -> Vec<f64> {
    let n = (size / step).round() as usize;
    let mut xs: Vec<f64> = (0..=n).map(|k| size * k as f64 / n as f64).collect();
    xs.extend(extra.iter().copied().filter(|&x| x > 0.0 && x < size));
    xs.sort_by(f64::total_cmp);
    xs.dedup_by(|a, b| (*a - *b).abs() < 1e-6);
    xs
}

/// The parts: 0 a terrain of random bumps with a cliff of height `h` across X
/// (wall width `w`), 1 a hemisphere of radius `0.7 h` on a plate, 2 steps up and down.
fn part(kind: u8, bumps: &[f64; 16], h: f64, w: f64, x_cliff: f64) -> MeshIndex {
    let size = 16.0;
    match kind {
        0 => {
            let xs = grid(size, 1.0, &[x_cliff, x_cliff + w]);
            let ys = grid(size, 1.0, &[]);
            height_field(&xs, &ys, |x, y| {
                let (u, v) = (x / size * 3.0, y / size * 3.0);
                let (i, j) = ((u as usize).min(2), (v as usize).min(2));
                let (fu, fv) = (u - i as f64, v - j as f64);
                let b = |a: usize, c: usize| bumps[4 * a + c];
                let bump = b(i, j) * (1.0 - fu) * (1.0 - fv)
                    + b(i + 1, j) * fu * (1.0 - fv)
                    + b(i, j + 1) * (1.0 - fu) * fv
                    + b(i + 1, j + 1) * fu * fv;
                let cliff = ((x - x_cliff) / w).clamp(0.0, 1.0);
                bump + h * (1.0 - cliff)
            })
        }
        1 => {
            let xs = grid(size, 0.5, &[]);
            height_field(&xs, &xs, |x, y| {
                let r2 = (x - 8.0).powi(2) + (y - 8.0).powi(2);
                let radius = 0.7 * h;
                (radius * radius - r2).max(0.0).sqrt()
            })
        }
        _ => {
            let edges: Vec<f64> = (1..4).flat_map(|k| [4.0 * k as f64, 4.0 * k as f64 + w]).collect();
            let xs = grid(size, 1.0, &edges);
            let ys = grid(size, 2.0, &[]);
            height_field(&xs, &ys, |x, _| {
                let mut z = 0.0;
                for k in 1..4 {
                    let x0 = 4.0 * k as f64;
                    z += bumps[k] * h * ((x - x0) / w).clamp(0.0, 1.0);
                }
                z
            })
        }
    }
}

/// The largest depth of a feed or link move below the CL surface (mm) and where.
fn worst_gouge(planned: &Planned, index: &MeshIndex, cutter: &Cutter) -> (f64, Point3) {
    let floor = index.bounds().min.z - 100.0;
    let mut worst = (f64::NEG_INFINITY, Point3::origin());
    for w in planned.toolpath.moves().windows(2) {
        if !matches!(w[1].kind, MoveKind::Feed | MoveKind::Link) {
            continue;
        }
        for k in 0..=CHECKS_PER_MOVE {
            let p = w[0].to + (w[1].to - w[0].to) * (k as f64 / CHECKS_PER_MOVE as f64);
            let cl = drop_cutter(cutter, index, Point2::new(p.x, p.y), floor);
            if cl.tip.z - p.z > worst.0 {
                worst = (cl.tip.z - p.z, p);
            }
        }
    }
    worst
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, ..ProptestConfig::default() })]

    /// Along every cutting move the chord stays above the CL surface less the
    /// sampling share of the path tolerance.
    #[test]
    fn no_gouge_between_cutter_locations(
        kind in 0u8..3,
        bumps in prop::array::uniform16(-1.0f64..1.0),
        h in 3.0f64..8.0,
        w in 0.01f64..1.5,
        x_cliff in 4.0f64..10.0,
        direction in 0.0f64..std::f64::consts::PI,
        bull_nose in any::<bool>(),
        sh in 0.1f64..0.3,
    ) {
        let index = part(kind, &bumps, h, w, x_cliff);
        let cutter = if bull_nose { bull(3.0, 1.0) } else { ball(3.0) };
        let p = params(direction, Pattern::Zigzag, sh.min(0.9), 0.5);
        // A part no strategy can finish in this direction (a wall across the
        // feed) is refused with an error: nothing to check.
        let planned = plan_finishing(&index, &cutter, &p, &TOL);
        let Ok(planned) = planned else { return Ok(()) };
        let allowed = tol::SAMPLING_SHARE * TOL.path;
        let (depth, at) = worst_gouge(&planned, &index, &cutter);
        prop_assert!(depth <= allowed + 1e-9, "a move lies {depth} mm below the CL surface at {at:?} (allowed {allowed})");
    }
}

/// The demo's job (the Choi surface, bull-nose R 5, r 2, sh 0.01 mm along the
/// PCA steepest slope, path 0.01 mm): no move below the CL surface beyond the
/// sampling share.
#[test]
fn choi_demo_moves_stay_above_the_cl_surface() {
    let tolerances = Tolerances { path: 0.01, gouge: 0.0 };
    let (index, analysis) = common::choi_analysed(&tolerances);
    let p = params(analysis.slope_direction_deg.to_radians(), Pattern::Zigzag, 0.01, 0.5);
    let cutter = bull(5.0, 2.0);
    let planned = plan_finishing(&index, &cutter, &p, &tolerances).unwrap();
    let (depth, at) = worst_gouge(&planned, &index, &cutter);
    let allowed = tol::SAMPLING_SHARE * tolerances.path;
    eprintln!("choi: {} moves, deepest {depth} mm below the CL surface at {at:?}", planned.toolpath.moves().len());
    assert!(depth <= allowed + 1e-9, "a move lies {depth} mm below the CL surface at {at:?} (allowed {allowed})");
}
