//! Guide curves on triangle meshes for 5-axis roughing by guide curves
//! (Jousselin 2020, PhD thesis, Université Paris-Saclay, Ch. 2 §3.2 and
//! Annex A; docs/guides-curves.md):
//!
//! - [`Support`] and [`Curve`]: a level mesh with vertex normals and a
//!   polyline on it with its normals (Ch. 4 §1.2);
//! - [`CurveField`]: the signed distance to curves (inside on their left);
//! - [`offset_curves`]: path curves by Marching Facets, iterated offsets of a
//!   curve in steps of a_e until they vanish, with split detection and
//!   medial-axis repair (Ch. 2 §3.2.1);
//! - [`limit_curves`]: C_n, a level meets the flank offset (Ch. 2 §3.2.1);
//! - [`morph_level`], [`pair_levels`]: tilt curves by scalar morphing on the
//!   next level, the swap rule and the count rule (Ch. 2 §3.2.2);
//! - [`build_guides`]: levels, flank offset, limit, path and tilt curves of
//!   a pocket (module F), with the degeneracy zones of non-convex limit
//!   curves ([`degeneracy_zones`], [`pair_zones`], Ch. 2 §3.3) and open
//!   pockets closed by virtual flanks along the level's edge (Ch. 4 §1.3.1);
//! - [`vectorial_offset`]: the vectorial method (Eq. 2.8-2.10, Alg. 1-3), the
//!   reference for the scalar one.
//!
//! ```
//! use scallop_geom::Point3;
//! use scallop_guides::{Support, offset_curves};
//! use scallop_mesh::{Polyline3, TriMesh, grid_triangles};
//! // A 40 mm square plane in 1 mm cells, and a square loop of side 30 on it.
//! let n = 40;
//! let v: Vec<Point3> = (0..=n).flat_map(|j| (0..=n).map(move |i| Point3::new(i as f64 - 20.0, j as f64 - 20.0, 0.0))).collect();
//! let support = Support::new(TriMesh::from_indexed(&v, &grid_triangles(n, n)).unwrap().0);
//! let p = |x, y| Point3::new(x, y, 0.0);
//! let square = Polyline3::new(vec![p(-15., -15.), p(15., -15.), p(15., 15.), p(-15., 15.)], true);
//! let limit = support.curve(square).unwrap().inside_left();
//! let offsets = offset_curves(&support, &[limit], 4.5).unwrap();
//! assert_eq!(offsets.len(), 3); // at 4.5, 9 and 13.5 mm from the side
//! ```
//!
//! # Invariants
//! - Never performs I/O; never prints; errors are [`GuideError`].
//! - Results do not depend on the thread count (rayon with indexed collection).

mod build;
mod error;
mod facets;
mod field;
mod limit;
mod morph;
mod offset;
mod open;
pub use open::extended_bottom;
mod support;
pub use scallop_geom::tol::guides as tol;
mod vectorial;
mod zones;

pub use build::{GuideLevel, GuideSet, GuideSettings, bottom_level, build_guides};
pub use error::GuideError;
pub use facets::Isolines;
pub use field::CurveField;
pub use limit::{LimitCurves, limit_curves};
pub use morph::{GuidePairs, Level, morph_level, morph_vectorial, pair_levels, project_curve};
pub use offset::{OffsetStep, offset_curve, offset_curves};
pub use support::{Curve, Support};
pub use vectorial::{VectorialOffset, VectorialOptions, vectorial_offset};
pub use zones::{Zone, ZonePair, degeneracy_zones, pair_zones};
