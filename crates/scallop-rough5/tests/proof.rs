//! The proof's gouge measure and its starting stock: a plunge below the floor
//! of a box-shaped volume to remove is a gouge of the plunge's depth at the
//! plunge's place; the same plunge where a blank leaves no material is none.

#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

use scallop_cutter::{Cutter, CutterShape};
use scallop_geom::{Aabb3, Point3};
use scallop_mesh::TriMesh;
use scallop_rough5::{ProofSettings, prove, prove_from_blank};
use scallop_toolpath::{Move, MoveKind, Toolpath};

fn p(x: f64, y: f64, z: f64) -> Point3 {
    Point3::new(x, y, z)
}

/// A closed box mesh with outward normals.
fn block(lo: Point3, hi: Point3) -> TriMesh {
    let c = |i: u8| {
        p(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    };
    let quads = [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]];
    let mut soup = Vec::new();
    for q in quads {
        soup.push([c(q[0]), c(q[1]), c(q[2])]);
        soup.push([c(q[0]), c(q[2]), c(q[3])]);
    }
    TriMesh::from_soup(&soup).unwrap().0
}

fn plunge(x: f64, y: f64, depth: f64) -> Toolpath {
    let mut path = Toolpath::new(1000.0);
    path.push(Move::new(MoveKind::Rapid, p(x, y, 15.0)));
    path.push(Move::new(MoveKind::Plunge, p(x, y, depth)));
    path.push(Move::new(MoveKind::Retract, p(x, y, 15.0)));
    path
}

#[test]
fn a_plunge_below_the_floor_is_a_gouge_at_its_place() {
    let stock = Aabb3 { min: p(0.0, 0.0, 0.0), max: p(40.0, 40.0, 10.0) };
    // The volume to remove: a 20 x 20 pocket 5 mm deep.
    let volume = block(p(10.0, 10.0, 5.0), p(30.0, 30.0, 10.0));
    let flat = Cutter::new(CutterShape::Flat { radius: 2.0 }, 20.0).unwrap();
    let settings = ProofSettings { resolution: 0.25, axis_tolerance: 0.05 };
    let inside = prove(&plunge(20.0, 20.0, 5.0), &flat, &stock, &volume, &settings, &|_, _| {}).unwrap();
    assert_eq!(inside.gouge_depth, 0.0);
    assert!(inside.gouge_at.is_none());
    let deep = prove(&plunge(20.0, 20.0, 3.0), &flat, &stock, &volume, &settings, &|_, _| {}).unwrap();
    assert!((deep.gouge_depth - 2.0).abs() < 1e-9, "{}", deep.gouge_depth);
    let [x, y, _] = deep.gouge_at.unwrap();
    assert!((x - 20.0).hypot(y - 20.0) <= 2.0, "({x}, {y})");
    // Outside the pocket, in the box: 8 mm removed from the part.
    let beside = prove(&plunge(5.0, 5.0, 2.0), &flat, &stock, &volume, &settings, &|_, _| {}).unwrap();
    assert!((beside.gouge_depth - 8.0).abs() < 1e-9, "{}", beside.gouge_depth);
    // A blank that stops at x = 8: the same plunge beside it cuts air, no gouge; the removed volume is 0.
    let blank = block(p(8.0, 0.0, 0.0), p(40.0, 40.0, 10.0));
    let air =
        prove_from_blank(&plunge(5.0, 5.0, 2.0), &flat, &stock, Some(&blank), &volume, &settings, &|_, _| {}).unwrap();
    assert_eq!(air.gouge_depth, 0.0);
    assert!(air.removed_volume.abs() < 1e-9, "{}", air.removed_volume);
    // An open blank is refused.
    let open = TriMesh::from_soup(&[[p(0.0, 0.0, 0.0), p(1.0, 0.0, 0.0), p(0.0, 1.0, 0.0)]]).unwrap().0;
    assert!(
        prove_from_blank(&plunge(20.0, 20.0, 5.0), &flat, &stock, Some(&open), &volume, &settings, &|_, _| {}).is_err()
    );
}
