//! The one error type of the crate.

use scallop_guides::GuideError;

/// What went wrong, where, and how to fix it.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum Rough5Error {
    /// A length or angle setting is not a finite positive number.
    #[error("{name} = {value} must be finite and > 0 (mm or rad): give a positive value")]
    BadSetting {
        /// Setting name.
        name: &'static str,
        /// The value given.
        value: f64,
    },
    /// The cutter shape cannot be placed (cones are not supported).
    #[error("the {what} cannot be placed along its axis: use a flat, ball or bull-nose (torus) cutter")]
    UnsupportedCutter {
        /// The shape.
        what: &'static str,
    },
    /// The cutter grown by the allowance is not a valid cutter.
    #[error("the cutter grown by the allowance {allowance} mm is invalid ({reason}): lower the allowance")]
    BadAllowance {
        /// The allowance (mm).
        allowance: f64,
        /// Why.
        reason: String,
    },
    /// The guide curves could not be built.
    #[error("guide curves: {0}")]
    Guides(#[from] GuideError),
    /// A level yields no pass.
    #[error("no level of the pocket yields a pass ({reason}): check the tool radius, a_p and a_e against the pocket")]
    NoPass {
        /// Why.
        reason: String,
    },
    /// The 3-axis roughing of a baseline failed.
    #[error("3-axis roughing: {0}")]
    Rough(String),
    /// The stock simulation refused the program or found it unsafe.
    #[error("stock simulation: {0}")]
    Simulation(String),
}
