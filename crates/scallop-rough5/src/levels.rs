//! The passes of each level (module F's curves turned into passes): the
//! bottom S_0 itself is the lowest level (the tool tangent to the bottom,
//! with the bottom allowance), then the offset levels of `build_guides`.
//! With guide curves, a level paired with the one above gets the paired path
//! and tilt curves (innermost first); a level without a pair (the top one, or
//! one whose pairing failed) and every level of the zero-tilt variant get
//! their own path curves, innermost first, then the limit curve, with the
//! tool axis +Z.

use scallop_guides::{
    Curve, GuideError, GuideSet, GuideSettings, Level, OffsetStep, Support, build_guides, limit_curves, offset_curves,
    pair_levels,
};
use scallop_mesh::TriMesh;

use crate::Rough5Error;

/// The tool-axis variant.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TiltMode {
    /// Tool axis +Z on every offset level (spec 11, baseline 4, with a
    /// vertical axis).
    Zero,
    /// Tool axis from the path curve on S_n to the tilt curve on S_{n+1}.
    Guides,
}

/// One level and its passes.
#[derive(Debug, Clone)]
pub struct LevelPasses {
    /// Distance of the level from the bottom (mm).
    pub distance: f64,
    /// The level mesh.
    pub support: Support,
    /// The passes, innermost first: the path curve and, with guide curves,
    /// its tilt curve on the level above.
    pub passes: Vec<(Curve, Option<Curve>)>,
    /// Why the level has no tilt curves, when it has none in the guide-curve
    /// variant.
    pub untilted: Option<String>,
}

/// One level's own curves: limit loops and offsets.
struct Own {
    distance: f64,
    support: Support,
    loops: Vec<Curve>,
    offsets: Vec<OffsetStep>,
}

impl Own {
    /// Innermost offsets first, then the limit loops; no tilt.
    fn passes(&self) -> Vec<(Curve, Option<Curve>)> {
        let inner = self.offsets.iter().rev().flat_map(|s| s.curves.iter().cloned());
        inner.chain(self.loops.iter().cloned()).map(|c| (c, None)).collect()
    }

    fn level(&self) -> Option<Level<'_>> {
        (self.loops.len() == 1).then(|| Level { support: &self.support, limit: &self.loops[0], offsets: &self.offsets })
    }
}

/// The bottom as level 0: its limit curves on the flank offset and their
/// offsets (none when the limit is not one closed loop).
fn bottom_level(bottom: &TriMesh, set: &GuideSet, a_e: f64) -> Result<Own, GuideError> {
    let support = Support::new(bottom.clone());
    let limit = limit_curves(&support, &set.flank_offset);
    let offsets = if limit.loops.len() == 1 && limit.open.is_empty() {
        offset_curves(&support, &limit.loops, a_e)?
    } else {
        Vec::new()
    };
    Ok(Own { distance: 0.0, support, loops: limit.loops, offsets })
}

/// The levels of the pocket with bottom `bottom` and flanks `flanks`, bottom
/// up, with their passes.
///
/// # Errors
/// Those of [`build_guides`] and of the bottom level's offsets.
pub fn level_passes(
    bottom: &TriMesh,
    flanks: &TriMesh,
    guides: &GuideSettings,
    mode: TiltMode,
) -> Result<Vec<LevelPasses>, Rough5Error> {
    let set = build_guides(bottom, flanks, guides)?;
    let mut own = vec![bottom_level(bottom, &set, guides.radial_step)?];
    for l in set.levels {
        own.push(Own { distance: l.distance, support: l.support, loops: l.limit.loops, offsets: l.offsets });
    }
    let mut out = Vec::with_capacity(own.len());
    for j in 0..own.len() {
        let paired = match (mode, own.get(j + 1)) {
            (TiltMode::Zero, _) => Err("zero-tilt variant".to_string()),
            (TiltMode::Guides, None) => Err("top level: no level above".to_string()),
            (TiltMode::Guides, Some(above)) => match (own[j].level(), above.level()) {
                (Some(a), Some(b)) => pair_levels(&a, &b, guides.radial_step).map_err(|e| e.to_string()),
                _ => Err("a level without one closed limit loop".to_string()),
            },
        };
        let (passes, untilted) = match paired {
            Ok(p) => (p.path.into_iter().zip(p.tilt.into_iter().map(Some)).collect(), None),
            Err(why) => (own[j].passes(), Some(why)),
        };
        out.push(LevelPasses { distance: own[j].distance, support: own[j].support.clone(), passes, untilted });
    }
    Ok(out)
}
