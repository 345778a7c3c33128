//! 5-axis roughing by guide curves, part 2 (Jousselin 2020, PhD thesis,
//! Université Paris-Saclay, Ch. 2 §1.2.3 and Ch. 3; docs/rough5.md): from the
//! guide curves of `scallop-guides` to a proven 5-axis roughing program.
//!
//! - [`Placer`]: the tool (flat, ball, torus) dropped along any axis to
//!   tangent contact with a level mesh (module G; C_C to C_L by Eq. 1.1);
//! - [`synchronise`], [`pitch_angle`]: SPU synchronisation of a path curve
//!   with its tilt curve (Eq. 3.10) and the pitch angle theta_t (Eq. 3.7);
//! - [`plan_rough5`]: levels top-down, passes inside-out, entries
//!   ([`EntryMode`]: a helix inside a closed pass, [`helix_entry`]; from
//!   outside the stock at the level's depth, [`side_entry`]; ramps along
//!   closed and open runs), links on the level or at a safe height, a
//!   maximum angular step; the guide-curve variant and the zero-tilt baseline
//!   (module J); [`plan_single_pass`]: one pass alone (the orientation
//!   cases of Ch. 3 §2.3);
//! - [`correct_planar`]: the collision correction that turns a colliding
//!   tool axis in its correction plane, the pitch angle kept (Ch. 3 §3,
//!   Eq. 3.31); [`correct_spatial`]: step 2, the axis turned through a
//!   point of an upper level's limit curve (Eq. 3.32);
//! - [`plan_zlevel`], [`plan_three_plus_two`]: the 3-axis baselines on the
//!   same part, tool and cutting data (z-level roughing in one setup, then
//!   rest roughing in fixed orientations chosen from the undercuts);
//! - [`air_moves`]: the cutting moves that lie in the air (outside the
//!   in-process stock by a clearance) written at an air feed, checked by the
//!   proof as rapids;
//! - [`prove`]: the program cut on a tri-dexel stock with shank and holder
//!   collisions as errors, and the metrics of spec 10.1 (module L);
//!   [`prove_with_faces`] adds those of the finished faces ([`face_metrics`]:
//!   deviation from the allowance, crest heights).
//!
//! ```
//! use scallop_cutter::{Cutter, CutterShape};
//! use scallop_geom::{Point3, Vec3};
//! use scallop_mesh::TriMesh;
//! use scallop_rough5::Placer;
//! let p = |x, y, z| Point3::new(x, y, z);
//! let (plane, _) = TriMesh::from_soup(&[[p(-50., -50., 0.), p(50., -50., 0.), p(0., 50., 0.)]]).unwrap();
//! let torus = Cutter::new(CutterShape::Bull { radius: 5.0, corner: 1.5 }, 20.0).unwrap();
//! let placer = Placer::new(&plane, &torus, 0.0).unwrap();
//! // Tilted by 10 degrees: C_L height r + (R - r) sin 10 deg (spec 12.1 item 2).
//! let t = 10f64.to_radians();
//! let placed = placer.place(&p(0., 0., 30.), &Vec3::new(t.sin(), 0.0, t.cos())).unwrap();
//! assert!((placed.cl.z - (1.5 + 3.5 * t.sin())).abs() < 1e-9);
//! ```
//!
//! # Invariants
//! - Never performs I/O; never prints; errors are [`Rough5Error`].
//! - A placed tool never penetrates the level mesh (the maximum over every
//!   triangle's contacts); results do not depend on the thread count.

mod air;
mod baseline;
mod collide;
mod correct;
mod cutting;
mod entry;
mod error;
mod faces;
mod levels;
mod orient;
pub mod place;
mod plan;
mod prove;
mod radius;
pub mod rest;
pub mod sqp;
mod sync;
pub use scallop_geom::tol::rough5 as tol;

pub use air::{AIR_CHUNK, AIR_SPLIT, AirMoves, AirSettings, air_moves, grown_flutes, is_air_move};
pub use baseline::{BaselinePlan, BaselineSettings, Pocket, SetupReport, plan_three_plus_two, plan_zlevel, setup_axes};
pub use collide::BodyCheck;
pub use correct::{CorrectionCount, correct_pairs, correct_pairs_spatial, correct_planar, correct_spatial};
pub use cutting::{CuttingData, TorusTool};
pub use entry::{
    EntryCount, EntryMode, HELIX_RADII, HELIX_STARTS, HELIX_TANGENCY, HelixSettings, PathDynamics, SIDE_DIRECTIONS,
    SIDE_REACH_RADII, helix_entry, path_time_estimate, side_entry,
};
pub use error::Rough5Error;
pub use faces::{FaceMetrics, ProofFace, face_metrics};
pub use levels::{LevelOptions, LevelPasses, TiltMode, level_passes, level_passes_with, refine_facets};
pub use orient::{
    AngleUnit, BoundsPenalty, Coverage, OrientSettings, Orientation, Reparam, Weights, constraints, objective_terms,
    optimise_pass, pitch_trace, synchronise_with,
};
pub use place::{Feature, Placement, Placer, tool_frame};
pub use plan::{
    AIR_MARGIN, AIR_STEP, AirReport, LevelReport, MoveRole, PassReport, Rough5Plan, Rough5Settings, SHUTTLE_LEGS,
    SIDE_MARGIN, SMOOTH_MIN_TILT, SMOOTH_ROUNDS, SinglePass, TRANSLATION_MAX, TRANSLATION_SLOPE,
    bottom_normal_min_slope, limit_step, plan_rough5, plan_rough5_in, plan_single_pass, round_corners, smooth_axes,
    thin_vertical,
};
pub use prove::{Proof, ProofSettings, prove, prove_from_blank, prove_with_faces};
pub use radius::{apparent_contour_radius, effective_radius, exact_scallop, scallop_height, swept_profile};
pub use sync::{SyncPoint, axis_steps, closest_vertex, interpolate_axis, limit_angular_step, pitch_angle, synchronise};
