//! Surface analysis and tool choice for finishing, without machining simulation
//! (finishing.md chapter 2, sections 5, 7-10, 12.7 and annexes A-E):
//!
//! - **sampling** ([`sample_patch`], [`sample_mesh`]): cell-centre grids on
//!   parametric patches, one area-weighted sample per triangle on meshes; per sample
//!   the point, unit normal, tilt `s`, steepest-slope direction `theta` and the
//!   feature vector [`FeatureVector`] `(u, v, s, theta)` shared with partitioning;
//! - **PCA** ([`Moments`], [`Pca`]): population covariance (1/n), batch or
//!   incremental (stable add/remove), best-fit plane, principal direction, shape
//!   factor `mu`, size `chi`, slope `s~ = arccos(|S_III . Z|)`;
//! - **analytic models**: effective radius and step-over ([`Cutter`]), the
//!   jerk-limited stop-to-stop time ([`MachineLimits::segment_time`]), times and
//!   lengths of rectangle planes ([`plane_time`]), critical slope
//!   [`critical_slope`] and shape factor [`critical_shape_factor`], the Annex E time
//!   of a PCA rectangle in any feed direction ([`annex_e_time`]), the cross-shaped
//!   plane ([`CrossPlane`]);
//! - **advisor** ([`analyze`]): a serde-serialisable [`AnalysisReport`] with the
//!   recommended cutter and direction, and [`plot_svg`], the `(mu, s)` decision plane.
//!
//! ```
//! use scallop_analysis::{analyze, plot_svg, sample_patch, GridOptions, MachineLimits, Recommendation, ToolOptions};
//!
//! let set = scallop_surface::builtin("choi").unwrap();
//! let samples = sample_patch(&set.patches()[0], &GridOptions::default()).unwrap(); // 80 x 80
//! let report = analyze(&samples, &ToolOptions::default(), &MachineLimits::default(), 0.01).unwrap();
//! assert_eq!(report.recommendation, Recommendation::ToroidalAlongSlope);
//! assert!((report.plane.eigenvalues[0] - 312.07).abs() < 0.02);
//! assert!(report.critical_slope_deg > report.slope_deg);
//! let svg = plot_svg(&report);
//! assert!(svg.contains("<polyline"));
//! ```
//!
//! # Units
//! Lengths mm, areas mm^2, angles rad, times s, feed mm/s, acceleration mm/s^2, jerk
//! mm/s^3 ([`MachineLimits::from_thesis_units`] converts m/min, m/s^2, m/s^3). Every
//! formula is dimensionally homogeneous, so times equal the specification's SI
//! values. [`AnalysisReport`] fields are in mm, mm^2, s and degrees (`_deg`).
//!
//! # Invariants
//! - Never performs I/O, never prints, never reads the environment.
//! - Deterministic: results depend only on the inputs, bit for bit for any number of
//!   rayon threads (parallel sampling collects by index; sums are reduced per fixed
//!   chunk of [`tol::REDUCTION_CHUNK`] samples, then in chunk order).
//! - No NaN: degenerate inputs (horizontal or vertical planes, all normals
//!   horizontal, a single triangle) give the documented finite answers; samples on
//!   a line or a point are an [`AnalysisError::DegenerateSamples`]. Infinite values
//!   appear only where documented (`R_eff` of a horizontal plane, Annex E time of a
//!   vertical plane, `mu_c` of a horizontal plane) and never in an [`AnalysisReport`].
//! - Statistics are population statistics (divide by the total weight, 1/n).
//! - Every numeric threshold lives in [`tol`].

mod advisor;
mod cutter;
mod error;
mod kinematics;
mod moments;
mod pca;
mod plane;
mod plot;
mod sample;
pub use scallop_geom::tol::analysis as tol;

pub use advisor::{AnalysisReport, Note, PcaPlane, Recommendation, ToolOption, analyze};
pub use cutter::{Cutter, effective_radius_for_step_over, fold_direction_angle, step_over};
pub use error::AnalysisError;
pub use kinematics::{KinematicModel, MachineLimits};
pub use moments::Moments;
pub use pca::{Pca, direction_angle_xy};
pub use plane::{
    CrossPlane, CrossTimes, FeedDirection, LengthTime, PlaneTime, Rectangle, ToolOptions, annex_e_time,
    critical_shape_factor, critical_slope, plane_time, rectangle_time_at_angle, strip_time,
};
pub use plot::plot_svg;
pub use sample::{
    FeatureVector, GridOptions, PcaWeighting, Sample, Samples, sample_mesh, sample_patch, sample_patch_masked,
    sample_surface_set, slope_and_direction,
};
