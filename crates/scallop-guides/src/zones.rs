//! Degeneracy zones of non-convex limit curves (Jousselin 2020, Ch. 2 §3.3,
//! Ch. 4 §1.3.2 and §3.1, Fig. 4.21): where the offsets of a level split,
//! the level is cut into zones, each an outer curve and its offsets that do
//! not split: the non-degenerate zone from the limit curve inward to the last
//! unsplit offset, then one zone per branch, starting at its first
//! degenerated curve (recursively, where a branch splits again). Zones of two
//! neighbouring levels are matched branch to branch (nearest arc-length
//! barycentres, mutually) and each matched pair gets its own path and tilt
//! curves by [`pair_levels`] (projection, morph, swap and count rules per
//! zone); a branch without a partner is reported, never paired arbitrarily.

use scallop_geom::Point3;

use crate::GuideError;
use crate::field::CurveField;
use crate::morph::{GuidePairs, Level, pair_levels};
use crate::offset::OffsetStep;
use crate::support::{Curve, Support};

/// One degeneracy zone of a level.
#[derive(Clone, Debug, PartialEq)]
pub struct Zone {
    /// The outer curve: the limit curve C_n for the non-degenerate zone, the
    /// first degenerated curve (the degeneracy limit curve) of a branch.
    pub outer: Curve,
    /// Its offsets in the zone, outermost first, one loop each; the last is
    /// the non-degeneracy limit curve of the zone when it has branches.
    pub offsets: Vec<OffsetStep>,
    /// The zone it branches from (`None` for the non-degenerate zone).
    pub parent: Option<usize>,
    /// The offset step of the level that [`Zone::outer`] is (0 for C_n, `k`
    /// for the k-th offset).
    pub first_step: usize,
}

impl Zone {
    /// The zone's family innermost first, as [`pair_levels`] reads it.
    #[must_use]
    pub fn level<'a>(&'a self, support: &'a Support) -> Level<'a> {
        Level { support, limit: &self.outer, offsets: &self.offsets }
    }
}

/// The degeneracy zones of the offsets `offsets` of `limit` (outermost
/// first, as [`crate::offset_curves`] gives them): zone 0 is the
/// non-degenerate zone; a zone's branches follow it. Each offset loop is put
/// under the loop of the previous step that contains it (the largest signed
/// distance at its first point).
#[must_use]
pub fn degeneracy_zones(limit: &Curve, offsets: &[OffsetStep]) -> Vec<Zone> {
    // Node (step, loop); step 0 is the limit itself.
    let parents: Vec<Vec<usize>> = (0..offsets.len())
        .map(|j| {
            let prev: &[Curve] = if j == 0 { std::slice::from_ref(limit) } else { &offsets[j - 1].curves };
            let fields: Vec<CurveField> = prev.iter().map(|c| CurveField::new(std::slice::from_ref(c))).collect();
            offsets[j].curves.iter().map(|c| container(&fields, &c.line.points[0])).collect()
        })
        .collect();
    let mut zones = vec![Zone { outer: limit.clone(), offsets: Vec::new(), parent: None, first_step: 0 }];
    // The zone of each loop of the previous step.
    let mut zone_of: Vec<usize> = vec![0];
    for (j, step) in offsets.iter().enumerate() {
        let children = |p: usize| parents[j].iter().filter(|&&q| q == p).count();
        let mut next = Vec::with_capacity(step.curves.len());
        for (k, c) in step.curves.iter().enumerate() {
            let p = parents[j][k];
            let z = zone_of.get(p).copied().unwrap_or(0);
            if children(p) == 1 {
                zones[z].offsets.push(OffsetStep { curves: vec![c.clone()], split: false, flagged: 0, repaired: 0 });
                next.push(z);
            } else {
                zones.push(Zone { outer: c.clone(), offsets: Vec::new(), parent: Some(z), first_step: j + 1 });
                next.push(zones.len() - 1);
            }
        }
        zone_of = next;
    }
    zones
}

/// The index of the field whose curve contains `p` most deeply (largest
/// signed distance), or the nearest when none contains it.
fn container(fields: &[CurveField], p: &Point3) -> usize {
    let key = |f: &CurveField| {
        let s = f.signed(p);
        if s > 0.0 { (1, s) } else { (0, -s.abs()) }
    };
    (0..fields.len())
        .max_by(|&i, &j| {
            let (a, b) = (key(&fields[i]), key(&fields[j]));
            a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)).then(j.cmp(&i))
        })
        .unwrap_or(0)
}

/// The zones of one level and a pairing result for each matched pair.
#[derive(Clone, Debug)]
pub struct ZonePair {
    /// Zone index on the lower level (`None`: no partner).
    pub lower: Option<usize>,
    /// Zone index on the upper level (`None`: no partner).
    pub upper: Option<usize>,
    /// The paired path and tilt curves, or why not.
    pub pairs: Result<GuidePairs, GuideError>,
}

/// Matches the zones of level `n` (`zones_n` on `s_n`) with those of level
/// `n + 1` and pairs each match (Jousselin 2020, Fig. 4.21; the swap and count
/// rules per zone). Non-degenerate zones match each other; the branches of
/// two matched zones match by mutually nearest barycentres of their outer
/// curves; a branch of either level without a partner gives a
/// [`GuideError::Unpaired`] entry.
#[must_use]
pub fn pair_zones(s_n: &Support, zones_n: &[Zone], s_n1: &Support, zones_n1: &[Zone], a_e: f64) -> Vec<ZonePair> {
    let mut out = Vec::new();
    if zones_n.is_empty() || zones_n1.is_empty() {
        return out;
    }
    let mut stack = vec![(0usize, 0usize)];
    while let Some((a, b)) = stack.pop() {
        let pairs = pair_zone(s_n, &zones_n[a], s_n1, &zones_n1[b], a_e);
        out.push(ZonePair { lower: Some(a), upper: Some(b), pairs });
        let kids = |zones: &[Zone], z: usize| -> Vec<usize> {
            (0..zones.len()).filter(|&i| zones[i].parent == Some(z)).collect()
        };
        let (ka, kb) = (kids(zones_n, a), kids(zones_n1, b));
        let matched = mutual_nearest(
            &ka.iter().map(|&i| &zones_n[i].outer).collect::<Vec<_>>(),
            &kb.iter().map(|&i| &zones_n1[i].outer).collect::<Vec<_>>(),
        );
        for (i, m) in matched.iter().enumerate() {
            match m {
                Some(j) => stack.push((ka[i], kb[*j])),
                None => out.push(unpaired(Some(ka[i]), None)),
            }
        }
        for (j, &zb) in kb.iter().enumerate() {
            if !matched.contains(&Some(j)) {
                out.push(unpaired(None, Some(zb)));
            }
        }
    }
    out.sort_by_key(|p| (p.lower, p.upper));
    out
}

/// [`pair_levels`] on two zones; two zones of one curve each pair as they
/// are (one step: no morph would add a curve between them).
fn pair_zone(s_n: &Support, a: &Zone, s_n1: &Support, b: &Zone, a_e: f64) -> Result<GuidePairs, GuideError> {
    if a.offsets.is_empty() && b.offsets.is_empty() {
        crate::offset::check_step(a_e)?;
        return Ok(GuidePairs {
            path: vec![a.outer.clone()],
            tilt: vec![b.outer.clone()],
            steps: 0,
            path_morphed: false,
            tilt_morphed: false,
            projection_fallbacks: 0,
            path_spacing: 0.0,
            tilt_spacing: 0.0,
        });
    }
    pair_levels(&a.level(s_n), &b.level(s_n1), a_e)
}

fn unpaired(lower: Option<usize>, upper: Option<usize>) -> ZonePair {
    let (what, zone) = match lower {
        Some(z) => ("lower", z),
        None => ("upper", upper.unwrap_or(0)),
    };
    ZonePair { lower, upper, pairs: Err(GuideError::Unpaired { what, zone }) }
}

/// For each curve of `a`, the index of the curve of `b` whose barycentre is
/// nearest, when `a`'s is also the nearest to it (mutual), else `None`.
fn mutual_nearest(a: &[&Curve], b: &[&Curve]) -> Vec<Option<usize>> {
    let bary = |c: &Curve| c.line.barycentre().unwrap_or(c.line.points[0]);
    let (pa, pb): (Vec<Point3>, Vec<Point3>) =
        (a.iter().map(|c| bary(c)).collect(), b.iter().map(|c| bary(c)).collect());
    let nearest = |p: &Point3, set: &[Point3]| {
        (0..set.len()).min_by(|&i, &j| (set[i] - p).norm().total_cmp(&(set[j] - p).norm()))
    };
    pa.iter().enumerate().map(|(i, p)| nearest(p, &pb).filter(|&j| nearest(&pb[j], &pa) == Some(i))).collect()
}
