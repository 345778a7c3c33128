//! The one error type of the crate.

/// What went wrong, where, and how to fix it.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum GuideError {
    /// A length parameter is not a finite positive number.
    #[error("{name} = {value} mm must be finite and > 0: give a positive step in mm")]
    BadLength {
        /// Parameter name.
        name: &'static str,
        /// The value given.
        value: f64,
    },
    /// A curve has too few points or a non-finite coordinate.
    #[error("curve {curve} is unusable ({reason}): give at least 2 finite points on the mesh")]
    BadCurve {
        /// Index of the curve in its set.
        curve: usize,
        /// What is wrong.
        reason: &'static str,
    },
    /// Exact normals given for a support do not match its vertices.
    #[error("{given} normals for {vertices} vertices (or a non-finite/zero normal): give one unit normal per vertex")]
    BadNormals {
        /// Normals given.
        given: usize,
        /// Vertices of the mesh.
        vertices: usize,
    },
    /// The offsets did not vanish within the step guard.
    #[error("offsets did not vanish after {steps} steps: check that the curve bounds a finite region of the mesh")]
    NotVanishing {
        /// Steps done.
        steps: usize,
    },
    /// A morph level or a family split into several loops, which the pairing
    /// of one path family with one tilt family cannot follow.
    #[error(
        "{what} has {loops} loops at step {step}: split the pocket into degeneracy zones (Jousselin 2020, Ch. 2 §3.3)"
    )]
    Split {
        /// Which family or morph.
        what: &'static str,
        /// Step index.
        step: usize,
        /// Number of loops found.
        loops: usize,
    },
    /// A level or the flank offset could not be extracted from its field.
    #[error("{what}: {reason}")]
    Field {
        /// Which surface.
        what: &'static str,
        /// The field engine's message.
        reason: String,
    },
    /// A degeneracy zone of one level has no partner on the neighbouring
    /// level (Jousselin 2020, Fig. 4.7a: the two levels degenerate
    /// differently).
    #[error(
        "zone {zone} of the {what} level has no partner on the other level: its offsets split differently; \
         change a_p or a_e, or machine that zone separately"
    )]
    Unpaired {
        /// `"lower"` or `"upper"`.
        what: &'static str,
        /// The zone index on that level.
        zone: usize,
    },
    /// The open limit chains of a level could not be closed by virtual
    /// flanks over the bottom's open edge.
    #[error(
        "level at {distance} mm: {reason}; the open pocket cannot be closed by virtual flanks over the bottom's open edge"
    )]
    OpenPocket {
        /// Distance of the level from the bottom (mm).
        distance: f64,
        /// What failed.
        reason: &'static str,
    },
    /// The projection of the innermost curve onto the next level failed.
    #[error("the innermost curve could not be projected onto the next level: {reason}")]
    Projection {
        /// Why.
        reason: &'static str,
    },
}
