//! The guide-curve builder (Jousselin 2020, Ch. 2 §1.2 and §3, Fig. 2.14;
//! module F of docs/guides-curves.md): axial levels offset from the pocket
//! bottom (a voxel distance field, `scallop-field`), the flank offset at the
//! tool radius plus the flank allowance, on each level the limit curve C_n
//! where it meets the flank offset, the path curves (its offsets by a_e), and
//! for each pair of neighbouring levels the paired path and tilt curves.

use scallop_field::{FieldError, LevelOptions, Side, Surface, offset_levels};
use scallop_mesh::TriMesh;

use crate::{
    GuideError, GuidePairs, Level, LimitCurves, OffsetStep, Support, limit_curves, offset_curves, pair_levels,
};

/// Settings of [`build_guides`] (mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GuideSettings {
    /// Tool radius R.
    pub tool_radius: f64,
    /// Material left on the flanks s_f.
    pub flank_allowance: f64,
    /// Axial depth of cut a_p: the levels lie a_p, 2 a_p, ... above the bottom.
    pub axial_step: f64,
    /// Radial engagement a_e between path curves.
    pub radial_step: f64,
    /// Voxel size of the distance fields.
    pub voxel: f64,
    /// Height of the pocket above its bottom: no level at or above it.
    pub depth: f64,
}

/// One axial level and its curves.
#[derive(Debug, Clone)]
pub struct GuideLevel {
    /// Its distance from the bottom (mm).
    pub distance: f64,
    /// The level mesh S_n.
    pub support: Support,
    /// Its limit curves C_n.
    pub limit: LimitCurves,
    /// The offsets of C_n (path curves), outermost first; empty when the
    /// level has no single closed limit loop.
    pub offsets: Vec<OffsetStep>,
}

/// The guide curves of a pocket.
#[derive(Debug, Clone)]
pub struct GuideSet {
    /// The flank offset at R + s_f (the pocket-side sheet).
    pub flank_offset: TriMesh,
    /// The levels, bottom up.
    pub levels: Vec<GuideLevel>,
    /// For each pair of neighbouring levels with one limit loop each (lower
    /// level index), the paired path and tilt curves, or why they could not
    /// be paired.
    pub pairs: Vec<(usize, Result<GuidePairs, GuideError>)>,
}

fn field_error(what: &'static str, e: &FieldError) -> GuideError {
    GuideError::Field { what, reason: e.to_string() }
}

/// Builds the guide curves of the pocket with bottom faces `bottom` and flank
/// faces `flanks` (both with the volume to remove's outward normals, i.e.
/// pointing into the part).
///
/// # Errors
/// [`GuideError::BadLength`] for a bad setting, [`GuideError::Field`] when a
/// level or the flank offset cannot be extracted, and the errors of
/// [`offset_curves`].
pub fn build_guides(bottom: &TriMesh, flanks: &TriMesh, settings: &GuideSettings) -> Result<GuideSet, GuideError> {
    for (name, value) in [
        ("tool_radius", settings.tool_radius),
        ("axial_step", settings.axial_step),
        ("radial_step", settings.radial_step),
        ("voxel", settings.voxel),
        ("depth", settings.depth),
    ] {
        if !(value.is_finite() && value > 0.0) {
            return Err(GuideError::BadLength { name, value });
        }
    }
    if !(settings.flank_allowance.is_finite() && settings.flank_allowance >= 0.0) {
        return Err(GuideError::BadLength { name: "flank_allowance", value: settings.flank_allowance });
    }
    // The volume's normals point into the part: the pocket lies behind them.
    let options = LevelOptions { voxel: settings.voxel, side: Side::Against, ..LevelOptions::default() };
    let mut distances = Vec::new();
    let mut d = settings.axial_step;
    while d < settings.depth - 0.5 * settings.voxel && distances.len() < crate::tol::MAX_LEVELS {
        distances.push(d);
        d += settings.axial_step;
    }
    let levels = offset_levels(&Surface::new(bottom), &distances, &options).map_err(|e| field_error("levels", &e))?;
    let flank_offset =
        offset_levels(&Surface::new(flanks), &[settings.tool_radius + settings.flank_allowance], &options)
            .map_err(|e| field_error("flank offset", &e))?
            .pop()
            .ok_or(GuideError::Field { what: "flank offset", reason: "no sheet".into() })?;
    let mut out = Vec::with_capacity(levels.len());
    for (mesh, &distance) in levels.into_iter().zip(&distances) {
        let support = Support::new(mesh);
        let limit = limit_curves(&support, &flank_offset);
        let offsets = if limit.loops.len() == 1 && limit.open.is_empty() {
            offset_curves(&support, &limit.loops, settings.radial_step)?
        } else {
            Vec::new()
        };
        out.push(GuideLevel { distance, support, limit, offsets });
    }
    let pairs = (0..out.len().saturating_sub(1))
        .filter(|&k| out[k].limit.loops.len() == 1 && out[k + 1].limit.loops.len() == 1)
        .map(|k| (k, pair_levels(&level_of(&out[k]), &level_of(&out[k + 1]), settings.radial_step)))
        .collect();
    Ok(GuideSet { flank_offset, levels: out, pairs })
}

/// The curves of a level with one limit loop, for [`pair_levels`].
fn level_of(g: &GuideLevel) -> Level<'_> {
    Level { support: &g.support, limit: &g.limit.loops[0], offsets: &g.offsets }
}
