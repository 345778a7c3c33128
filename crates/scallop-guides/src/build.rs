//! The guide-curve builder (Jousselin 2020, Ch. 2 §1.2 and §3, Fig. 2.14;
//! module F of docs/guides-curves.md): axial levels offset from the pocket
//! bottom (a voxel distance field, `scallop-field`), the flank offset at the
//! tool radius plus the flank allowance, on each level the limit curve C_n
//! where it meets the flank offset, the path curves (its offsets by a_e), and
//! for each pair of neighbouring levels the paired path and tilt curves.

use scallop_field::{FieldError, LevelOptions, Side, Surface, offset_levels};
use scallop_geom::num::first_not_positive;
use scallop_mesh::TriMesh;

use crate::open::{OpenPocket, extended_bottom, open_limit};
use crate::zones::{Zone, degeneracy_zones, pair_zones};
use crate::{GuideError, GuidePairs, LimitCurves, OffsetStep, Support, limit_curves, offset_curves};

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
    /// The degeneracy zones of the offsets (Jousselin 2020, Ch. 2 §3.3):
    /// zone 0 from C_n to the last unsplit offset, then one per branch;
    /// empty when the level has no single closed limit loop.
    pub zones: Vec<Zone>,
    /// Why the level's open limit chains could not be closed by virtual
    /// flanks, if they could not (Jousselin 2020, Ch. 4 §1.3.1).
    pub closing: Option<GuideError>,
}

/// The guide curves of a pocket.
#[derive(Debug, Clone)]
pub struct GuideSet {
    /// The flank offset at R + s_f (the pocket-side sheet).
    pub flank_offset: TriMesh,
    /// The levels, bottom up.
    pub levels: Vec<GuideLevel>,
    /// For each pair of neighbouring levels with one limit loop each (lower
    /// level index), the paired path and tilt curves of each pair of matched
    /// degeneracy zones (zone 0 first), or why they could not be paired; a
    /// zone without a partner gets an entry of its own
    /// ([`GuideError::Unpaired`]).
    pub pairs: Vec<(usize, Result<GuidePairs, GuideError>)>,
    /// For each entry of [`GuideSet::pairs`], the zone on the lower level and
    /// the zone on the upper one (`None`: no partner).
    pub pair_zones: Vec<[Option<usize>; 2]>,
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
    if let Some((name, value)) = first_not_positive(&[
        ("tool_radius", settings.tool_radius),
        ("axial_step", settings.axial_step),
        ("radial_step", settings.radial_step),
        ("voxel", settings.voxel),
        ("depth", settings.depth),
    ]) {
        return Err(GuideError::BadLength { name, value });
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
    let open = OpenPocket::new(bottom, flanks, settings.tool_radius + settings.flank_allowance);
    let out = levels
        .into_iter()
        .zip(&distances)
        .map(|(mesh, &distance)| guide_level(Support::new(mesh), distance, &flank_offset, &open, settings))
        .collect::<Result<Vec<_>, _>>()?;
    let mut pairs = Vec::new();
    let mut pair_zones = Vec::new();
    for k in 0..out.len().saturating_sub(1) {
        let (a, b) = (&out[k], &out[k + 1]);
        for z in pair_zones_of(a, b, settings.radial_step) {
            pairs.push((k, z.pairs));
            pair_zones.push([z.lower, z.upper]);
        }
    }
    Ok(GuideSet { flank_offset, levels: out, pairs, pair_zones })
}

/// The bottom S_0 itself as the lowest level of the pocket with bottom faces
/// `bottom` and flank faces `flanks`: its limit curves where it meets
/// `flank_offset` (the [`GuideSet::flank_offset`] of the same settings), and
/// their offsets. Where those are open chains (an open pocket), the bottom is
/// extended across its open edge by a strip R + s_f wide and the chains are
/// closed by the virtual flanks there, as on the offset levels (Jousselin
/// 2020, Ch. 4 §1.3.1): the level's support is then the extended bottom.
///
/// # Errors
/// Those of [`offset_curves`].
pub fn bottom_level(
    bottom: &TriMesh,
    flanks: &TriMesh,
    flank_offset: &TriMesh,
    settings: &GuideSettings,
) -> Result<GuideLevel, GuideError> {
    let clearance = settings.tool_radius + settings.flank_allowance;
    let open = OpenPocket::new(bottom, flanks, clearance);
    let support = Support::new(bottom.clone());
    let own = limit_curves(&support, flank_offset);
    let support = match extended_bottom(bottom, flanks, clearance, settings.voxel) {
        Some(mesh) if !own.open.is_empty() => Support::new(mesh),
        _ => support,
    };
    guide_level(support, 0.0, flank_offset, &open, settings)
}

/// One level: its limit curves (an open pocket's closed by virtual flanks,
/// [`crate::open`]), the offsets of a single limit loop and their degeneracy
/// zones.
fn guide_level(
    support: Support,
    distance: f64,
    flank_offset: &TriMesh,
    open: &OpenPocket,
    settings: &GuideSettings,
) -> Result<GuideLevel, GuideError> {
    let mut limit = limit_curves(&support, flank_offset);
    let mut closing = None;
    if !limit.open.is_empty() {
        let (loops, chains) = open_limit(&support, open);
        if chains.is_empty() {
            limit.closed_by_virtual_flanks = loops.len();
            limit.loops = loops;
            limit.nested = 0;
        } else {
            closing = Some(GuideError::OpenPocket { distance, reason: "the pocket region reaches the level's edge" });
        }
    }
    let single = limit.loops.len() == 1 && closing.is_none();
    let offsets = if single { offset_curves(&support, &limit.loops, settings.radial_step)? } else { Vec::new() };
    let zones = if single { degeneracy_zones(&limit.loops[0], &offsets) } else { Vec::new() };
    Ok(GuideLevel { distance, support, limit, offsets, zones, closing })
}

/// The zone pairs of two neighbouring levels (none unless both have zones).
fn pair_zones_of(a: &GuideLevel, b: &GuideLevel, a_e: f64) -> Vec<crate::zones::ZonePair> {
    pair_zones(&a.support, &a.zones, &b.support, &b.zones, a_e)
}
