//! Parametric surfaces for scallop (f64, mm): rational Bezier and NURBS patches
//! ([`Patch`]) validated on construction, exact evaluation of the point and its
//! derivatives up to order 2, unit normals, closest points, tight bounding boxes,
//! areas, tessellation into a [`scallop_mesh::TriMesh`] within a proven chordal
//! tolerance, named sets of patches ([`SurfaceSet`]), the built-in test surfaces of
//! the finishing specification ([`builtin`]) and a TOML description format
//! ([`toml_format`]).
//!
//! ```
//! use scallop_surface::{builtin, toml_format};
//!
//! let set = builtin("choi").unwrap();
//! let choi = &set.patches()[0];
//! let d = choi.derivatives(0.25, 0.5);            // S, Su, Sv, Suu, Suv, Svv
//! let n = choi.normal(0.25, 0.5);                 // unit Su x Sv
//! let above = d.point + n * 1.5;
//! let c = choi.closest_point(&above);             // (u, v, point, distance)
//! assert!((c.u - 0.25).abs() < 1e-9 && (c.distance - 1.5).abs() < 1e-9);
//!
//! let t = set.tessellate(0.01).unwrap();          // chordal deviation <= 0.01 mm
//! assert!(t.guaranteed && t.chordal_bound <= 0.01);
//!
//! let text = toml_format::to_toml(&set);
//! assert_eq!(toml_format::parse_surfaces(&text).unwrap(), set);
//! ```
//!
//! # Invariants
//! - Never performs I/O and never prints: parsing takes text, writing returns text.
//! - Deterministic: every result depends only on the inputs (no hashing order, no
//!   threads, no randomness), bit for bit on a given platform.
//! - A [`Patch`] is valid once built (degrees >= 1, consistent net, knots and
//!   weights, finite numbers); evaluation is then infallible and clamps `(u, v)` into
//!   the domain.
//! - Index `i` of the control net goes with `u`, index `j` with `v` (finishing.md 4.1).
//! - Tessellations of polynomial patches are within the requested chordal tolerance
//!   by proof (see [`tessellate`] for the bound and its derivation); for rational patches the bound is a
//!   sampled estimate with a safety factor, flagged by [`Tessellation::guaranteed`].
//! - Numeric thresholds and algorithm constants live in [`tol`].
//!
//! # TOML format
//!
//! ```toml
//! units = "mm"                # required: "mm" or "in" (inches are converted to mm)
//!
//! [[patch]]                   # one table per patch, at least one; names are unique
//! name = "choi"
//! kind = "bezier"             # or "nurbs"
//! degree = [3, 3]             # [p, q] >= 1
//! # control points row by row: control[i][j] = [x, y, z], i along u, j along v;
//! # (p + 1) rows of (q + 1) points for a Bezier patch
//! control = [
//!     [[7.92, 0.0, 37.26], [6.33, 20.4, 29.81], [6.33, 40.8, 29.81], [7.92, 61.2, 37.26]],
//!     # ... three more rows
//! ]
//! weights = [[1.0, 1.0, 1.0, 1.0], ...]   # optional, same shape as control, each > 0
//! # nurbs only, non-decreasing, len = rows + p + 1 and columns + q + 1
//! # (need not be clamped; the domain is [knots[p], knots[rows]]):
//! knots_u = [0, 0, 0, 0, 1, 1, 1, 1]
//! knots_v = [0, 0, 0, 0, 1, 1, 1, 1]
//! ```
//!
//! Unknown keys are errors (a misspelt `weight` is not silently ignored). Integers
//! are accepted wherever floats are; `nan` and `inf` parse but are rejected with the
//! place. Every error names the patch (index from 0 and name), the line of its
//! `[[patch]]` header and the place (knot index, control point `(i, j)`); syntax
//! errors keep the TOML parser's line and column. [`toml_format::to_toml`] writes
//! the same format and round-trips exactly. Example files: `examples/surfaces/`.

mod basis;
mod builtin;
pub mod closest;
mod error;
mod patch;
mod set;
pub mod tessellate;
pub use scallop_geom::tol::surface as tol;
pub mod toml_format;

pub use builtin::{BUILTIN_NAMES, builtin};
pub use closest::{ClosestPoint, ClosestPointOptions};
pub use error::{Direction, PatchLabel, SurfaceError};
pub use patch::{Domain, Patch, SurfaceDerivatives};
pub use set::SurfaceSet;
pub use tessellate::{SecondDerivativeBounds, Tessellation};
pub use toml_format::SurfaceFormatError;
