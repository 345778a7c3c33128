//! A raster finishing path from the exact drop-cutter on a generated wavy
//! surface simulates without gouge; the same path with one pass lowered by
//! 0.05 mm is reported as gouges under that pass, cut by its moves; the result
//! is identical on 1 and 2 threads.

#![allow(clippy::unwrap_used, clippy::float_cmp, reason = "tests fail loudly by design; exact cases compare exactly")]

mod common;

use scallop_cutter::{Cutter, CutterShape, drop_grid};
use scallop_geom::{Aabb3, Point3};
use scallop_mesh::{MeshIndex, TriMesh};
use scallop_sim::{SimError, VerifyOptions, ZMap, simulate};
use scallop_toolpath::{Move, MoveKind, Toolpath};

const SIZE: f64 = 30.0;
const CLEARANCE: f64 = 5.0;

fn surface(x: f64, y: f64) -> f64 {
    1.5 * (0.35 * x).sin() * (0.25 * y).cos() + 0.5 * (0.2 * (x + y)).sin()
}

fn wavy() -> MeshIndex {
    let soup = common::height_field(SIZE, 60, surface);
    MeshIndex::build(&TriMesh::from_soup(&soup).unwrap().0)
}

/// Zig-zag raster along x, passes 1 mm apart, CL points every 0.25 mm; the
/// pass `lowered` (if any) goes `drop` mm deeper. Returns the path and, per
/// pass, the range of its move indices.
fn raster(cutter: &Cutter, part: &MeshIndex, lowered: Option<(usize, f64)>) -> (Toolpath, Vec<(usize, usize)>) {
    let xs: Vec<f64> = (0..=120).map(|i| SIZE * f64::from(i) / 120.0).collect();
    let ys: Vec<f64> = (0..=30).map(f64::from).collect();
    let cl = drop_grid(cutter, part, &xs, &ys, -10.0, &|_| {});
    let mut t = Toolpath::new(1000.0);
    let mut passes = Vec::new();
    for (j, _) in ys.iter().enumerate() {
        let mut row: Vec<Point3> = cl[j * xs.len()..(j + 1) * xs.len()].iter().map(|c| c.tip).collect();
        if j % 2 == 1 {
            row.reverse();
        }
        if let Some((pass, drop)) = lowered
            && pass == j
        {
            for q in &mut row {
                q.z -= drop;
            }
        }
        let first = t.moves().len();
        t.push(Move::new(MoveKind::Rapid, Point3::new(row[0].x, row[0].y, CLEARANCE)));
        t.push(Move::new(MoveKind::Plunge, row[0]));
        for q in &row[1..] {
            t.push(Move::new(MoveKind::Feed, *q));
        }
        t.push(Move::new(MoveKind::Retract, Point3::new(row[row.len() - 1].x, row[row.len() - 1].y, CLEARANCE)));
        passes.push((first, t.moves().len()));
    }
    (t, passes)
}

fn setup() -> (Cutter, MeshIndex, Aabb3) {
    let ball = Cutter::new(CutterShape::Ball { radius: 2.0 }, 15.0).unwrap();
    let stock = Aabb3 { min: Point3::new(0.0, 0.0, -4.0), max: Point3::new(SIZE, SIZE, 3.0) };
    (ball, wavy(), stock)
}

/// Chordal error allowed to the straight moves between CL points 0.25 mm
/// apart: the sag of the CL surface (curvature <= 1/R = 0.5/mm here) is at most
/// 0.25^2 / 8 / 2 = 0.002 mm.
const CHORDAL: f64 = 0.004;

#[test]
fn drop_cutter_raster_has_no_gouge_and_a_lowered_pass_gouges_under_it() {
    let (ball, part, stock) = setup();
    let options = VerifyOptions { gouge_tolerance: CHORDAL, worst_reported: 1_000_000, ..VerifyOptions::default() };
    let (path, _) = raster(&ball, &part, None);
    let sim = simulate(stock, 0.1, &ball, &path, &part, &options).unwrap();
    let v = sim.verification;
    assert!(v.min_deviation >= -CHORDAL, "{v:?}");
    assert_eq!(v.part_cells, 300 * 300);
    // 1 mm passes of a 2 mm ball: cusps up to R - sqrt(R^2 - 0.5^2) = 0.064 mm
    // on a flat; more on slopes, far less than the 3 mm of stock above.
    assert!(v.max_scallop > 0.0 && v.max_scallop < 0.5, "{v:?}");
    assert!(v.excess_volume > 0.0 && v.removed_volume > 0.0);
    assert_eq!(sim.cut.air_feed_moves, 0);

    let pass = 15;
    let (lowered, passes) = raster(&ball, &part, Some((pass, 0.05)));
    let (first, end) = passes[pass];
    match simulate(stock, 0.1, &ball, &lowered, &part, &options) {
        Err(e @ SimError::Gouge { .. }) => {
            let message = e.to_string();
            assert!(message.contains("cut by move") && message.contains("of operation 0"), "{message}");
            let SimError::Gouge { count, worst, .. } = e else { unreachable!() };
            assert_eq!(count, worst.len());
            assert!(count > 100, "{count}");
            // The deepest gouge is the lowering (plus the chordal error of the
            // straight moves), sampled by the grid.
            assert!(worst[0].depth <= 0.05 + CHORDAL && worst[0].depth >= 0.045, "{:?}", worst[0]);
            for g in &worst {
                let id = g.cut_by.unwrap();
                let index = id.index as usize;
                assert!((first..end).contains(&index), "{g:?} not cut by pass {pass}");
                // Under the pass: within the cutter radius of its line y = 15.
                assert!((g.at.y - 15.0).abs() <= 2.0, "{g:?}");
            }
        }
        other => panic!("expected gouges, got {other:?}"),
    }
}

#[test]
fn results_are_identical_on_one_and_two_threads() {
    let (ball, part, stock) = setup();
    let (path, _) = raster(&ball, &part, Some((7, 0.05)));
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let mut zmap = ZMap::new(stock, 0.1).unwrap();
            let report = zmap.cut(&ball, &path).unwrap();
            let verdict = scallop_sim::verify(&zmap, &part, &VerifyOptions::default());
            (zmap, report, verdict)
        })
    };
    let (z1, r1, v1) = run(1);
    let (z2, r2, v2) = run(2);
    let bits = |z: &ZMap| z.heights().iter().map(|h| h.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&z1), bits(&z2));
    assert_eq!(z1, z2);
    assert_eq!(r1, r2);
    assert_eq!(r1.removed_volume.to_bits(), r2.removed_volume.to_bits());
    assert_eq!(v1, v2);
    assert!(v1.is_err());
}
