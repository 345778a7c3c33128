//! The walls of a tool-centre region for adaptive clearing: the grid's
//! iso-lines meet a wall at the cell centres next to it (up to a cell side
//! inside, in steps); their wall points are moved onto the wall itself, and
//! the wall's corners between two of them are put back, so a pass that runs
//! along a wall follows it exactly and reaches into its corners (material
//! left there would be cut by the region's contour at the end, at an
//! engagement the corner sets, not the step).

use std::collections::HashMap;

use scallop_contour::{P2, Region};

use crate::grid::IsoPoint;
use crate::tol;

/// The region's rings as chords, bucketed for nearest-point queries.
pub(crate) struct Walls {
    rings: Vec<Vec<P2>>,
    /// How far a wall point may be moved (mm).
    reach: f64,
    /// Bucket (i, j) of side `side` to the (ring, segment) pairs near it.
    buckets: HashMap<(i64, i64), Vec<(usize, usize)>>,
    side: f64,
}

/// The nearest wall point: ring, segment, the point.
type Foot = (usize, usize, P2);

impl Walls {
    /// The walls of `region`, chords within [`tol::WALL_CHORD`], found from
    /// up to `reach` mm away.
    pub fn new(region: &Region, reach: f64) -> Walls {
        let rings: Vec<Vec<P2>> = region.rings().iter().map(|c| c.to_points(tol::WALL_CHORD)).collect();
        let side = reach.max(1e-6);
        let mut buckets: HashMap<(i64, i64), Vec<(usize, usize)>> = HashMap::new();
        for (r, ring) in rings.iter().enumerate() {
            for s in 0..ring.len() {
                let (a, b) = (ring[s], ring[(s + 1) % ring.len()]);
                let (i0, j0) = Self::key([a[0].min(b[0]) - side, a[1].min(b[1]) - side], side);
                let (i1, j1) = Self::key([a[0].max(b[0]) + side, a[1].max(b[1]) + side], side);
                for i in i0..=i1 {
                    for j in j0..=j1 {
                        buckets.entry((i, j)).or_default().push((r, s));
                    }
                }
            }
        }
        Walls { rings, reach, buckets, side }
    }

    fn key(p: P2, side: f64) -> (i64, i64) {
        #[allow(clippy::cast_possible_truncation, reason = "bucket indices of finite coordinates")]
        let k = ((p[0] / side).floor() as i64, (p[1] / side).floor() as i64);
        k
    }

    /// The wall point nearest `p` within the reach, if any.
    fn foot(&self, p: P2) -> Option<Foot> {
        let mut best: Option<(f64, Foot)> = None;
        for &(r, s) in self.buckets.get(&Self::key(p, self.side))? {
            let ring = &self.rings[r];
            let (a, b) = (ring[s], ring[(s + 1) % ring.len()]);
            let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
            let l2 = dx * dx + dy * dy;
            let t = if l2 > 0.0 { (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2).clamp(0.0, 1.0) } else { 0.0 };
            let q = [a[0] + t * dx, a[1] + t * dy];
            let d = (p[0] - q[0]).hypot(p[1] - q[1]);
            if best.is_none_or(|x| d < x.0) {
                best = Some((d, (r, s, q)));
            }
        }
        best.filter(|x| x.0 <= self.reach).map(|x| x.1)
    }

    /// The loop with its wall points on the wall and the wall's vertices
    /// between two consecutive wall points on nearby segments of one ring.
    pub fn snap(&self, lp: &[IsoPoint]) -> Vec<IsoPoint> {
        let mut out: Vec<IsoPoint> = Vec::with_capacity(lp.len());
        let mut last: Option<Foot> = None;
        for p in lp {
            let foot = if p.2 { self.foot(p.0) } else { None };
            let Some((r, s, q)) = foot else {
                out.push(*p);
                last = None;
                continue;
            };
            if let Some((_, s0, _)) = last.filter(|l| l.0 == r) {
                let n = self.rings[r].len();
                let (fwd, back) = ((s + n - s0) % n, (s0 + n - s) % n);
                if fwd > 0 && fwd <= back && fwd <= tol::WALL_CORNERS {
                    out.extend((1..=fwd).map(|k| (self.rings[r][(s0 + k) % n], p.1, true)));
                } else if back > 0 && back < fwd && back <= tol::WALL_CORNERS {
                    out.extend((0..back).map(|k| (self.rings[r][(s0 + n - k) % n], p.1, true)));
                }
            }
            out.push((q, p.1, true));
            last = Some((r, s, q));
        }
        out
    }
}
