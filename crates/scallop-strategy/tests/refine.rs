//! Refinement (`Refinement`): planes and levels that a verification asks for
//! are added to those the planners place, in order, once each.

mod common;

use common::{ball, inclined_plane, params};
use scallop_geom::{Point3, Tolerances};
use scallop_mesh::{MeshIndex, TriMesh};
use scallop_strategy::{Pattern, Refinement, SteepShallow, plan_finishing, plan_finishing_refined, plan_steep_shallow};

fn tolerances() -> Tolerances {
    Tolerances { path: 0.01, gouge: 0.0 }
}

#[test]
fn a_plane_between_two_planes_is_added_in_order_and_an_existing_or_outside_one_is_not() {
    let index = inclined_plane(30.0, 20.0, 20.0);
    let cutter = ball(3.0);
    let p = params(0.0, Pattern::Zigzag, 0.05, 0.5);
    let tol = tolerances();
    let base = plan_finishing(&index, &cutter, &p, &tol).unwrap();
    let offsets: Vec<f64> = base.planes.iter().map(|q| q.offset).collect();
    assert!(offsets.len() >= 3, "{offsets:?}");
    let mid = 0.5 * (offsets[1] + offsets[2]);
    let refine = Refinement { planes: vec![mid, offsets[0], 1e3], levels: vec![] };
    let refined = plan_finishing_refined(&index, &cutter, &p, &tol, &refine).unwrap();
    let after: Vec<f64> = refined.planes.iter().map(|q| q.offset).collect();
    assert_eq!(after.len(), offsets.len() + 1, "{after:?}");
    assert!(after.windows(2).all(|w| w[0] < w[1]), "increasing: {after:?}");
    assert!(after.iter().any(|&d| (d - mid).abs() < 1e-9));
    assert!(refined.report.passes > base.report.passes);
    // The added plane's passes lie on it: every CL point at offset `mid` (m = +Y).
    let added = refined.planes.iter().find(|q| (q.offset - mid).abs() < 1e-9).unwrap();
    assert!(added.passes.iter().flatten().all(|q| (q.y - mid).abs() < 1e-9));
}

/// A mesa: a 20 mm square top at z = 10 on 60-degree-ish walls (10 mm high,
/// 5 mm wide at the foot) standing on a 60 mm square floor at z = 0.
fn mesa() -> (TriMesh, MeshIndex) {
    let sq =
        |h: f64, z: f64| [Point3::new(-h, -h, z), Point3::new(h, -h, z), Point3::new(h, h, z), Point3::new(-h, h, z)];
    let (top, foot, floor) = (sq(10.0, 10.0), sq(15.0, 0.0), sq(30.0, 0.0));
    let mut soup = vec![[top[0], top[1], top[2]], [top[0], top[2], top[3]]];
    for i in 0..4 {
        let j = (i + 1) % 4;
        soup.push([foot[i], foot[j], top[j]]);
        soup.push([foot[i], top[j], top[i]]);
        soup.push([floor[i], floor[j], foot[j]]);
        soup.push([floor[i], foot[j], foot[i]]);
    }
    let (mesh, _) = TriMesh::from_soup(&soup).unwrap();
    let index = MeshIndex::build(&mesh);
    (mesh, index)
}

#[test]
fn a_level_between_two_levels_is_added_and_planned() {
    let (mesh, index) = mesa();
    let cutter = ball(2.0);
    let p = params(0.0, Pattern::Zigzag, 0.05, 0.5);
    let tol = tolerances();
    let split = SteepShallow::default_for(&cutter, 0.05);
    let base = plan_steep_shallow(&mesh, &index, &cutter, &p, &tol, &split, &Refinement::default()).unwrap();
    let z = &base.level_heights;
    assert!(z.len() >= 3, "{z:?}");
    assert!(z.windows(2).all(|w| w[0] > w[1]), "from the top down: {z:?}");
    let mid = 0.5 * (z[1] + z[2]);
    let refine = Refinement { planes: vec![], levels: vec![mid, z[0]] };
    let refined = plan_steep_shallow(&mesh, &index, &cutter, &p, &tol, &split, &refine).unwrap();
    assert_eq!(refined.level_heights.len(), z.len() + 1, "{:?}", refined.level_heights);
    assert!(refined.level_heights.windows(2).all(|w| w[0] > w[1]));
    assert!(refined.level_heights.iter().any(|&h| (h - mid).abs() < 1e-12));
    assert!(refined.steep_passes > base.steep_passes);
}
