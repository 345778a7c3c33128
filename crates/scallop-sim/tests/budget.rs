//! Issue 21: a z-map over the cell budget is refused before it is allocated, with its size.

use scallop_geom::{Aabb3, Point3};
use scallop_sim::{MAX_CELLS, SimError, ZMap};

#[test]
fn a_zmap_over_the_budget_is_refused_with_its_size() {
    let stock = Aabb3 { min: Point3::new(0.0, 0.0, -10.0), max: Point3::new(80.0, 60.0, 10.0) };
    // The case: 0.0085 mm cells on a Choi-sized stock, about 66 million cells.
    match ZMap::new(stock, 0.0085) {
        Err(e @ SimError::TooManyCells { nx, ny, limit }) => {
            assert_eq!((nx, ny, limit), (9412, 7059, MAX_CELLS));
            assert!(e.to_string().contains("budget"), "{e}");
        }
        other => panic!("{:?}", other.map(|z| (z.nx(), z.ny()))),
    }
    // A fine grid within the budget is accepted: 2000 x 2000 cells.
    assert!(ZMap::new(Aabb3 { min: Point3::new(0.0, 0.0, 0.0), max: Point3::new(20.0, 20.0, 1.0) }, 0.01).is_ok());
}
