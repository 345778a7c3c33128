//! Cutters for scallop and the exact drop-cutter.
//!
//! A [`Cutter`] is an axisymmetric profile (flat, ball, bull-nose, cone) with
//! its flute length, shank and holder. [`drop_cutter`] finds the lowest tool-tip
//! height at an (x, y) where the cutter touches a mesh without penetrating it.
//!
//! ```
//! use scallop_cutter::{Cutter, CutterShape, drop_cutter, Contact};
//! use scallop_geom::{Point2, Point3};
//! use scallop_mesh::{MeshIndex, TriMesh};
//! let p = |x, y, z| Point3::new(x, y, z);
//! let (plane, _) = TriMesh::from_soup(&[[p(-10., -10., 1.), p(10., -10., 1.), p(0., 10., 1.)]]).unwrap();
//! let index = MeshIndex::build(&plane);
//! let ball = Cutter::new(CutterShape::Ball { radius: 3.0 }, 20.0).unwrap();
//! let cl = drop_cutter(&ball, &index, Point2::new(0.0, 0.0), -100.0);
//! assert_eq!(cl.tip.z, 1.0);
//! assert!(matches!(cl.contact, Contact::Facet { .. }));
//! ```
//!
//! # Invariants
//! - The drop-cutter height is the maximum over every triangle's vertex, edge
//!   and facet contacts; the index only skips triangles that cannot raise it, so
//!   the indexed result equals the brute-force one bit for bit.
//! - Batch calls are parallel and deterministic: the output does not depend on
//!   the number of threads.
//! - Never performs I/O; never prints.

mod drop;
mod shape;
pub use scallop_geom::tol::cutter as tol;

pub use drop::{
    BoxDrop, ClPoint, Contact, drop_cutter, drop_cutter_brute_force, drop_grid, drop_patch, drop_path, drop_points,
    drop_triangle,
};
pub use shape::{Cutter, CutterError, CutterShape, HolderSegment};
