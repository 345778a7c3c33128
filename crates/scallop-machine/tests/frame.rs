//! Tilted work planes (spec 3.13): the frame and the controllers' angles reproduce it.

use proptest::prelude::*;
use scallop_geom::Vec3;
use scallop_geom::nalgebra::Rotation3;
use scallop_machine::frame::{fanuc_g68_2, plane_spatial, tilted_plane};

proptest! {
    #[test]
    fn angles_rebuild_the_frame(x in -1.0..1.0f64, y in -1.0..1.0f64, z in 0.05..1.0f64) {
        let o = Vec3::new(x, y, z).normalize();
        let r = tilted_plane(&o);
        prop_assert!((r * Vec3::z() - o).norm() < 1e-12);
        // x_f is the projection of x_W: in the plane of x_W and O, with a positive x component.
        let xf = r * Vec3::x();
        prop_assert!(xf.dot(&o.cross(&Vec3::x())).abs() < 1e-12 && xf.x > 0.0);
        prop_assert!((r.matrix().determinant() - 1.0).abs() < 1e-12);
        let (i, j, k) = fanuc_g68_2(&r);
        let f = Rotation3::from_axis_angle(&Vec3::z_axis(), i) * Rotation3::from_axis_angle(&Vec3::x_axis(), j) * Rotation3::from_axis_angle(&Vec3::z_axis(), k);
        prop_assert!((f.matrix() - r.matrix()).norm() < 1e-9);
        prop_assert!((Vec3::new(i.sin() * j.sin(), -i.cos() * j.sin(), j.cos()) - o).norm() < 1e-9);
        let (a, b, c) = plane_spatial(&r);
        let h = Rotation3::from_axis_angle(&Vec3::z_axis(), c) * Rotation3::from_axis_angle(&Vec3::y_axis(), b) * Rotation3::from_axis_angle(&Vec3::x_axis(), a);
        prop_assert!((h.matrix() - r.matrix()).norm() < 1e-9);
    }
}

#[test]
fn axis_along_x_uses_y_for_the_frame() {
    let r = tilted_plane(&Vec3::x());
    assert!((r * Vec3::z() - Vec3::x()).norm() < 1e-15);
    assert!((r * Vec3::x() - Vec3::y()).norm() < 1e-15);
}
