//! The machine layer of scallop: machine descriptions, exact 5-axis kinematics and the
//! choice of one joint vector per tool pose.
//!
//! Toolpaths live in the part frame (tool tip and tool axis); machines move joints.
//! This crate reads a machine description (`scallop.machine/1` TOML, `docs/machine.md`),
//! computes forward kinematics (joints -> tip and tool axis in the part frame), the
//! closed-form inverse of the standard table-table, head-head and head-table families
//! with both branches (plus a generic two-rotary solver and a numeric fallback for any
//! chain), the analytic Jacobian, and plans a path: branch selection by continuity,
//! pole handling, rotary unwrapping within the strokes and axis-limit checks that name
//! the block and the axis. It also builds joint-space programs (subdivision, G93 feeds,
//! forward-kinematics replay) and predicts their time with per-axis velocity,
//! acceleration and jerk limits. Specification: `kinematics.md` sections 2, 3 and 8.
//!
//! Modules: [`desc`] (descriptions), [`chain`] (forward kinematics, Jacobian), [`ik`]
//! (inverse), [`plan`] (selection, unwrapping, limits), [`feed`] (subdivision, G93),
//! [`program`] (CL records to a joint-space program), [`time`] (time model), [`mill`]
//! (3-axis mills and [`Described`], a machine of either kind as a job names it), [`tol`].
//!
//! ```
//! use scallop_geom::{Point3, Vec3};
//! use scallop_machine::{Kinematics, Machine, Pose, plan};
//!
//! let machine = Machine::builtin("mx330")?;              // or Machine::from_toml_str(&text)?
//! let kin = Kinematics::new(&machine, 100.0);             // tool length l = 100 mm, baked
//! let pose = Pose::new(Point3::new(-51.0867, -68.4847, 6.5685), Vec3::new(-0.353553, -0.612372, 0.707107));
//! let path = plan::solve_path(&kin, &[pose], None)?;
//! let words: Vec<f64> = machine.axes().iter().zip(path.joints[0].iter()).map(|(a, q)| a.to_nc_word(*q)).collect();
//! assert!((words[3] + 45.0).abs() < 1e-3 && (words[4] - 30.0).abs() < 1e-3); // A -45, C 30
//! assert!((kin.fk(&path.joints[0]).tip - pose.tip).norm() < 1e-9);
//! # Ok::<(), scallop_machine::MachineError>(())
//! ```
//!
//! # Invariants
//! - Never performs I/O (descriptions are parsed from `&str`) and never prints.
//! - Internal units are mm and radians; files, NC words and error messages use mm and
//!   degrees ([`Axis::to_nc_word`]).
//! - A [`Machine`] is valid once built; kinematics queries are infallible except the
//!   inverse, which returns `Err` for unreachable poses, never NaN.
//! - `fk(ik(pose))` reproduces the pose to 1e-9 for every reachable pose off the pole
//!   (on the pole, `rho < pole_eps`, the tool axis is reproduced to `pole_eps`).
//! - Deterministic: same input, same bits; no hashing, no threads.
//! - Every numeric threshold lives in [`tol`].

#[cfg(feature = "ann-baseline")]
pub mod ann;
pub mod chain;
pub mod desc;
pub mod error;
pub mod feed;
pub mod frame;
pub mod ik;
pub mod mill;
pub mod plan;
pub mod program;
pub mod time;
pub mod tol;

pub use chain::{Class, Family, Jacobian6, Joints, Kinematics, Pose, Solver};
pub use desc::{
    Axis, AxisKind, ChainSide, ControlledPoint, Decimals, Dialect, Dynamics, FamilyChoice, FeedNorm, Iso841, Machine,
    Nc, PreferredBranch, SCHEMA, Tcp, ToolLengthMode, Wrap,
};
pub use error::MachineError;
pub use ik::{Branch, IkSolution, IkSolutions};
pub use mill::{Described, Mill};
