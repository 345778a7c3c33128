//! Triangle meshes for scallop: one validated f64 indexed mesh ([`TriMesh`]),
//! vertex welding scaled to the model, degenerate-triangle removal with
//! diagnostics, and an XY bounding-volume hierarchy ([`MeshIndex`]) for
//! drop-cutter queries; a 3D hierarchy ([`Bvh`]) for closest points and rays
//! ([`MeshQuery`]), polylines and the distance to them ([`PolylineQuery`]),
//! and mesh-mesh intersection chained into polylines ([`intersect_meshes`]).
//!
//! ```
//! use scallop_geom::Point3;
//! use scallop_mesh::TriMesh;
//! let p = |x, y, z| Point3::new(x, y, z);
//! let soup = [[p(0., 0., 0.), p(1., 0., 0.), p(0., 1., 0.)],
//!             [p(1., 0., 0.), p(1., 1., 0.), p(0., 1., 0.)],
//!             [p(0., 0., 0.), p(1., 0., 0.), p(2., 0., 0.)]]; // collinear: dropped
//! let (mesh, diag) = TriMesh::from_soup(&soup).unwrap();
//! assert_eq!(mesh.triangles().len(), 2);
//! assert_eq!(mesh.vertices().len(), 4);
//! assert_eq!(diag.degenerate_dropped, 1);
//! ```
//!
//! # Invariants
//! - A [`TriMesh`] is never empty, has only finite coordinates, in-range
//!   indices and no degenerate (exactly collinear) triangle. Nothing re-validates it.
//! - Never performs I/O.

mod bvh;
mod hash;
mod index;
mod intersect;
mod polyline;
mod query;
pub mod tol;
mod trimesh;

pub use bvh::Bvh;
pub use hash::{FastMap, WordHasher};
pub use index::MeshIndex;
pub use intersect::{KeyChain, MeshIntersection, chain_keys, intersect_meshes};
pub use polyline::{Polyline3, PolylineFoot, PolylineQuery, segment_parameter};
pub use query::{ClosestPoint, MeshQuery, RayHit, closest_on_triangle, ray_triangle, triangle_box};
pub use trimesh::{MeshDiagnostics, MeshError, TriMesh};
