//! The passes of each level (module F's curves turned into passes): the
//! bottom S_0 itself is the lowest level (the tool tangent to the bottom,
//! with the bottom allowance), then the offset levels of `build_guides`.
//! With guide curves, a level paired with the one above gets the paired path
//! and tilt curves (innermost first); a level without a pair (the top one, or
//! one whose pairing failed) and every level of the zero-tilt variant get
//! their own path curves, innermost first, then the limit curve, with the
//! tool axis +Z.
//!
//! [`level_passes_with`] adds two repairs ([`LevelOptions`]): the bottom's
//! innermost offsets that `offset_curves` drops as slivers of its coarse
//! facets, and, where `pair_levels` fails (the bottom of the closed pocket),
//! a pairing of the level's own curves with the own curves of the level above
//! by rank from the limit (limit with limit, first offset with first offset,
//! ...), so that the outer passes of such a level lean along the flanks too.

use scallop_guides::{
    Curve, GuideError, GuideSet, GuideSettings, Level, OffsetStep, Support, build_guides, limit_curves, offset_curve,
    offset_curves, pair_levels,
};
use std::collections::{BinaryHeap, HashMap};

use scallop_geom::Point3;
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
    /// How many of the last passes follow the level's limit curves (the
    /// outermost passes, along the flanks).
    pub outer: usize,
    /// Why `pair_levels` failed when the passes were paired by rank instead.
    pub paired_by_rank: Option<String>,
}

/// Options of [`level_passes_with`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct LevelOptions {
    /// Keep the bottom's offsets that `offset_curves` drops as slivers of
    /// the bottom's coarse facets (its sliver width is relative to the
    /// longest facet edge): a closed pocket's bottom is refined to facets
    /// no longer than the voxel ([`refine_facets`]), and while the innermost
    /// closed loop has a closed offset at a_e inside it, that offset is a
    /// pass too.
    pub centre_offsets: bool,
    /// Where `pair_levels` fails, pair the level's own curves with the own
    /// curves of the level above by rank from the limit.
    pub pair_by_rank: bool,
    /// Where the bottom's limit curves are open chains (an open pocket),
    /// extend the bottom across its open edge and close them by the virtual
    /// flanks there, so that the bottom is cut too
    /// ([`scallop_guides::bottom_level`]); the offset levels are then the
    /// offsets of that extended bottom, so they reach a steep open end.
    pub open_bottom: bool,
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
/// offsets (none when the limit is not one closed loop); with `open`, an open
/// pocket's bottom extended across its open edge and its limit chains closed
/// by the virtual flanks there ([`scallop_guides::bottom_level`]); with
/// `centre`, the inner offsets dropped as slivers added back
/// ([`LevelOptions`]).
fn bottom_level(
    (bottom, flanks): (&TriMesh, &TriMesh),
    set: &GuideSet,
    guides: &GuideSettings,
    options: &LevelOptions,
) -> Result<Own, Rough5Error> {
    // The part's own bottom faces can be long slivers (an ear-clipped flat
    // floor): refined to the level fields' voxel, its offsets are not
    // dropped as slivers of its facets. An open pocket's bottom (the
    // impeller's hub) is extended across its open edge instead.
    let refined;
    let closed = || limit_curves(&Support::new(bottom.clone()), &set.flank_offset).open.is_empty();
    let bottom = if options.centre_offsets && closed() {
        refined = refine_facets(bottom, guides.voxel)?;
        &refined
    } else {
        bottom
    };
    let (support, loops, mut offsets) = if options.open_bottom {
        let level = scallop_guides::bottom_level(bottom, flanks, &set.flank_offset, guides)?;
        (level.support, level.limit.loops, level.offsets)
    } else {
        let support = Support::new(bottom.clone());
        let limit = limit_curves(&support, &set.flank_offset);
        let offsets = if limit.loops.len() == 1 && limit.open.is_empty() {
            offset_curves(&support, &limit.loops, guides.radial_step)?
        } else {
            Vec::new()
        };
        (support, limit.loops, offsets)
    };
    if options.centre_offsets && !offsets.is_empty() {
        centre_offsets(&support, &mut offsets, guides.radial_step)?;
    }
    Ok(Own { distance: 0.0, support, loops, offsets })
}

/// Appends the closed offsets at `a_e` inside the innermost offset while it
/// is one closed loop with one closed loop inside it, at most
/// [`CENTRE_OFFSETS`] of them.
fn centre_offsets(support: &Support, offsets: &mut Vec<OffsetStep>, a_e: f64) -> Result<(), GuideError> {
    for _ in 0..CENTRE_OFFSETS {
        let Some(last) = offsets.last() else { return Ok(()) };
        if last.curves.len() != 1 || !last.curves[0].line.closed {
            return Ok(());
        }
        let iso = offset_curve(support, &last.curves, a_e)?;
        // Only a single closed loop that is not a point: an inside of at least
        // one step of its own (2 area / length is the half-width of a strip).
        let mut inner: Vec<Curve> =
            iso.curves.into_iter().filter(|c| c.line.closed && c.line.points.len() >= 3).collect();
        if inner.len() != 1 || inner[0].line.length() < 4.0 * support.facet_size().min(a_e) {
            return Ok(());
        }
        let curves = vec![inner.swap_remove(0).inside_left()];
        offsets.push(OffsetStep { curves, split: false, flagged: iso.flagged, repaired: iso.repaired });
    }
    Ok(())
}

/// `mesh` with every edge longer than `longest` split at its midpoint,
/// longest first, in every facet that has it (each such facet bisected
/// through its opposite corner), until no edge is longer: a conforming
/// refinement on the same facets' planes (longest-edge bisection, Rivara
/// 1984). The offsets of `offset_curves` are linear in each facet and a
/// loop narrower than half the longest facet edge counts as vanished
/// ([`scallop_guides::offset_curves`]), so a floor triangulated into long
/// slivers loses every offset without it.
///
/// # Errors
/// [`Rough5Error::BadSetting`] for a `longest` that is not finite and
/// positive.
pub fn refine_facets(mesh: &TriMesh, longest: f64) -> Result<TriMesh, Rough5Error> {
    if !(longest.is_finite() && longest > 0.0) {
        return Err(Rough5Error::BadSetting { name: "longest facet edge", value: longest });
    }
    let mut verts: Vec<Point3> = mesh.vertices().to_vec();
    let mut tris: Vec<[usize; 3]> = mesh.triangles().iter().map(|t| t.map(|i| i as usize)).collect();
    let key = |a: usize, b: usize| if a < b { (a, b) } else { (b, a) };
    let mut edges: HashMap<(usize, usize), Vec<usize>> = HashMap::new();
    // Lengths are positive and finite: their bit patterns order as they do.
    let mut heap: BinaryHeap<(u64, usize, usize)> = BinaryHeap::new();
    let push = |heap: &mut BinaryHeap<(u64, usize, usize)>, verts: &[Point3], (a, b): (usize, usize)| {
        let len = (verts[a] - verts[b]).norm();
        if len > longest {
            heap.push((len.to_bits(), a, b));
        }
    };
    for (t, tri) in tris.iter().enumerate() {
        for k in 0..3 {
            let e = key(tri[k], tri[(k + 1) % 3]);
            let list = edges.entry(e).or_default();
            if list.is_empty() {
                push(&mut heap, &verts, e);
            }
            list.push(t);
        }
    }
    while let Some((_, a, b)) = heap.pop() {
        let Some(faces) = edges.remove(&(a, b)) else { continue };
        let m = verts.len();
        verts.push(Point3::from((verts[a].coords + verts[b].coords) * 0.5));
        for t in faces {
            let tri = tris[t];
            // The corner where the edge starts in the facet's winding.
            let Some(k) = (0..3).find(|&k| key(tri[k], tri[(k + 1) % 3]) == (a, b)) else { continue };
            let (p, q, c) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
            let child = tris.len();
            tris[t] = [p, m, c];
            tris.push([m, q, c]);
            // The facet `t` keeps (p, m), (m, c), (c, p); the child takes (m, q), (q, c), (c, m).
            if let Some(list) = edges.get_mut(&key(q, c)) {
                for f in list.iter_mut().filter(|f| **f == t) {
                    *f = child;
                }
            }
            for (e, f) in [(key(p, m), t), (key(m, q), child)] {
                let list = edges.entry(e).or_default();
                if list.is_empty() {
                    push(&mut heap, &verts, e);
                }
                list.push(f);
            }
            let list = edges.entry(key(m, c)).or_default();
            if list.is_empty() {
                push(&mut heap, &verts, key(m, c));
            }
            list.extend([t, child]);
        }
    }
    Ok(TriMesh::from_indexed(&verts, &tris).map_or_else(|_| mesh.clone(), |(m, _)| m))
}

/// The bottom's sliver offsets added back at most this many times.
const CENTRE_OFFSETS: usize = 3;

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
    level_passes_with(bottom, flanks, guides, mode, &LevelOptions::default())
}

/// [`level_passes`] with the repairs of `options`.
///
/// # Errors
/// Those of [`build_guides`] and of the bottom level's offsets.
pub fn level_passes_with(
    bottom: &TriMesh,
    flanks: &TriMesh,
    guides: &GuideSettings,
    mode: TiltMode,
    options: &LevelOptions,
) -> Result<Vec<LevelPasses>, Rough5Error> {
    // An open pocket's levels are the offsets of its bottom extended across
    // its open edge, as the bottom level is: the offsets of the bottom alone
    // end on the virtual flank ruled by its normals there, which leans away
    // from a steep open end (52 deg at the impeller's inlet), so the wedge
    // between the crossable end and that flank was on no level.
    let extended = if options.open_bottom {
        scallop_guides::extended_bottom(bottom, flanks, guides.tool_radius + guides.flank_allowance, guides.voxel)
    } else {
        None
    };
    let set = build_guides(extended.as_ref().unwrap_or(bottom), flanks, guides)?;
    let mut own = vec![bottom_level((bottom, flanks), &set, guides, options)?];
    for l in set.levels {
        own.push(Own { distance: l.distance, support: l.support, loops: l.limit.loops, offsets: l.offsets });
    }
    // The bottom level's tilt curves stay those of the first level of the
    // bottom alone: over the strip the extended level's curves turn the
    // bottom's axes into the blades.
    let first_plain = match (&extended, mode) {
        (Some(_), TiltMode::Guides) => build_guides(bottom, flanks, guides)?.levels.into_iter().next().map(|l| Own {
            distance: l.distance,
            support: l.support,
            loops: l.limit.loops,
            offsets: l.offsets,
        }),
        _ => None,
    };
    let above_of = |j: usize| if j == 0 { first_plain.as_ref().or(own.get(1)) } else { own.get(j + 1) };
    let mut out = Vec::with_capacity(own.len());
    for (j, level) in own.iter().enumerate() {
        let paired = match (mode, above_of(j)) {
            (TiltMode::Zero, _) => Err("zero-tilt variant".to_string()),
            (TiltMode::Guides, None) => Err("top level: no level above".to_string()),
            (TiltMode::Guides, Some(above)) => match (level.level(), above.level()) {
                (Some(a), Some(b)) => pair_levels(&a, &b, guides.radial_step).map_err(|e| e.to_string()),
                _ => Err("a level without one closed limit loop".to_string()),
            },
        };
        let mut paired_by_rank = None;
        let (passes, untilted, outer) = match paired {
            Ok(p) => (p.path.into_iter().zip(p.tilt.into_iter().map(Some)).collect(), None, 1),
            Err(why) => match above_of(j) {
                Some(above) if options.pair_by_rank && mode == TiltMode::Guides => {
                    paired_by_rank = Some(why);
                    (by_rank(&level.passes(), &above.passes()), None, level.loops.len())
                }
                _ => (level.passes(), Some(why), level.loops.len()),
            },
        };
        out.push(LevelPasses {
            distance: level.distance,
            support: level.support.clone(),
            passes,
            untilted,
            outer,
            paired_by_rank,
        });
    }
    Ok(out)
}

/// The passes `below` (innermost first, no tilt) with the curves `above`
/// (the same order) as tilt curves by rank from the last (the limit): the
/// last with the last, and so on; the inner passes left over have none.
fn by_rank(below: &[(Curve, Option<Curve>)], above: &[(Curve, Option<Curve>)]) -> Vec<(Curve, Option<Curve>)> {
    let (n, m) = (below.len(), above.len());
    below
        .iter()
        .enumerate()
        .map(|(i, (c, _))| {
            let from_last = n - 1 - i;
            let tilt = (from_last < m).then(|| above[m - 1 - from_last].0.clone());
            (c.clone(), tilt)
        })
        .collect()
}
