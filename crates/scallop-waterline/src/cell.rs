//! Linking the crossings of an ambiguous grid cell (two or more exits) by
//! subdivision, so that no link joins two crossings across a feature of the
//! part that lies inside the cell.
//!
//! A cell whose boundary holds several exits (a saddle, or a gap of outside
//! found on an inside edge next to another outside stretch) can be linked in
//! two ways: the inside joined across the cell, or the outside. Neither rule is
//! right in general: a thin channel of outside may run through the cell (the
//! outside joined), or end inside it, or be cut by a thin band of inside (a low
//! ridge across a slot). A wrong link is a chord across the inside: the cutter
//! moving along it cuts into the part. So the cell is split into four: the
//! midpoints of its sides and its centre are classified on the exact
//! drop-cutter, the crossings of the four inner half-edges are found as on the
//! grid edges (a bisection where the ends differ, a cover walk for gaps where
//! both are inside), and each quarter is linked the same way, down to
//! [`tol::MAX_SUBDIVISION_DEPTH`] halvings. The links then run through the new
//! crossings: the contour is followed through the cell at the finer level.
//! At the depth limit, a plain saddle (one crossing per side) is decided by the
//! drop-cutter at its centre, as marching squares does; a cell with two gaps
//! joins the outside (a thin channel running through) only if the straight
//! line between the gaps' middles is outside; any other cell joins the inside,
//! the choice that never links across the inside (a sliver of outside finer
//! than the limit is left uncut rather than gouged).
//!
//! A segment with ends on different sides is given one crossing and may hold
//! three (a gap in its inside stretch, an inside sliver in its outside one).
//! Where a split finds a side's midpoint on the wrong side for the crossings
//! before it, the side's piece is named ([`Resolver::resolve`],
//! [`Resolver::into_parts`]) and its crossings found again on its two halves
//! ([`refine_piece`]): here for a piece of an inner half-edge, by the caller
//! (`contour::trace`, for both cells that share it) for a piece of a grid edge;
//! then the cell is linked again (docs/waterline.md, step 3).

use scallop_geom::Point2;

use crate::refine::Local;
use crate::tol;

/// A rectangle being linked: corners counter-clockwise from its lowest x and
/// y, which corners are inside, the crossings (node numbers) of side `k`
/// (from corner `k` to corner `k + 1`) in walk order, and the segment each
/// side lies on.
pub(crate) struct Cell {
    pub(crate) corners: [Point2; 4],
    pub(crate) inside: [bool; 4],
    pub(crate) sides: [Vec<usize>; 4],
    pub(crate) bases: [Base; 4],
}

/// The segment whose crossings a side of a cell takes a piece of: a side (0
/// to 3) of the grid cell being linked (a grid edge), or an inner half-edge of
/// a split, from the midpoint of a side to the centre.
#[derive(Clone, Copy, PartialEq)]
pub(crate) enum Base {
    Grid(usize),
    Inner(Point2, Point2),
}

/// A piece of a side of the grid cell (the side, the piece's ends) whose
/// midpoint did not match its crossings.
pub(crate) type GridPiece = (usize, Point2, Point2);

/// Times [`Resolver::resolve`] links a grid cell again after finding pieces
/// of inner half-edges that hold more crossings than were found on them.
const INNER_ROUNDS: usize = 3;

/// The links of the cells of one grid cell and the crossings it adds.
pub(crate) struct Resolver<'a> {
    local: &'a Local<'a>,
    /// Every node: the grid crossings first (numbers below `first_new`), then
    /// the crossings found on inner half-edges.
    nodes: Vec<Point2>,
    first_new: usize,
    /// Pieces of inner half-edges (the half-edge's ends, the piece's ends)
    /// whose crossings are found on the piece's two halves.
    inner_fixes: Vec<[Point2; 4]>,
    /// The pieces of sides whose midpoint's side did not match the parity of
    /// the crossings found before it, at the last linking.
    asked: Vec<(Base, Point2, Point2)>,
}

impl<'a> Resolver<'a> {
    /// A resolver on the candidate triangles of `local` (a box holding the
    /// cell) whose new nodes are numbered from `first_new`.
    pub(crate) fn new(local: &'a Local<'a>, first_new: usize) -> Self {
        Resolver { local, nodes: Vec::new(), first_new, inner_fixes: Vec::new(), asked: Vec::new() }
    }

    /// The new crossings, numbered from `first_new` in order, and the pieces
    /// of the grid cell's sides whose midpoint's side does not match the
    /// parity of the crossings found before it (a segment with ends on
    /// different sides is given one crossing, step 2 of docs/waterline.md,
    /// but may hold three): the cell was linked without splitting there; the
    /// caller finds those pieces' crossings again ([`refine_piece`]) and links
    /// the cell again.
    pub(crate) fn into_parts(self) -> (Vec<Point2>, Vec<GridPiece>) {
        let grid = self
            .asked
            .iter()
            .filter_map(|&(base, p, q)| match base {
                Base::Grid(k) => Some((k, p, q)),
                Base::Inner(..) => None,
            })
            .collect();
        (self.nodes, grid)
    }

    /// The links (exit, entry) of the grid cell `cell`, possibly through new
    /// crossings. `point(id)` gives the position of a grid crossing. Where a
    /// split finds a piece of an inner half-edge whose midpoint disagrees with
    /// its crossings, that piece's crossings are found on its two halves and
    /// the cell is linked again (at most [`INNER_ROUNDS`] times).
    pub(crate) fn resolve(&mut self, cell: &Cell, point: &dyn Fn(usize) -> Point2) -> Vec<(usize, usize)> {
        let mut round = 0;
        loop {
            self.nodes.clear();
            self.asked.clear();
            let links = self.link(cell, point, 0);
            let fixes: Vec<[Point2; 4]> = self
                .asked
                .iter()
                .filter_map(|&(base, p, q)| match base {
                    Base::Inner(a, b) => Some([a, b, p, q]),
                    Base::Grid(_) => None,
                })
                .filter(|f| !self.inner_fixes.contains(f))
                .collect();
            if fixes.is_empty() || round == INNER_ROUNDS {
                return links;
            }
            self.inner_fixes.extend(fixes);
            round += 1;
        }
    }

    /// The links of `cell` at subdivision `depth`.
    fn link(&mut self, cell: &Cell, point: &dyn Fn(usize) -> Point2, depth: u32) -> Vec<(usize, usize)> {
        let met = walk(cell);
        let exits = met.iter().filter(|m| m.1).count();
        if exits <= 1 {
            return join(&met, true);
        }
        if depth < tol::MAX_SUBDIVISION_DEPTH {
            let mark = self.nodes.len();
            if let Some(quarters) = self.split(cell, point) {
                let mut links = Vec::new();
                for q in &quarters {
                    links.extend(self.link(q, point, depth + 1));
                }
                return links;
            }
            self.nodes.truncate(mark); // inconsistent sides: decide at this level
        }
        let plain = exits == 2 && cell.sides.iter().all(|s| s.len() == 1);
        let join_inside = if plain {
            self.local.height_slot(centre(cell)).0 > 0.0
        } else {
            exits > 2 || !self.channel_runs_through(&met, point)
        };
        join(&met, join_inside)
    }

    /// At the depth limit, a cell with two outside stretches (gaps) on its
    /// boundary: whether a channel of outside runs from one to the other, taken
    /// from the drop-cutter at three points of the straight line between their
    /// middles (the cell is so small that a channel is straight across it). If
    /// any is inside, the channel is cut (a thin band of inside crosses it) or
    /// bends away: the inside is joined, which leaves the channel uncut rather
    /// than cutting the band.
    fn channel_runs_through(&self, met: &[(usize, bool)], point: &dyn Fn(usize) -> Point2) -> bool {
        let n = met.len();
        // The middle of each outside stretch: between an exit and the next crossing.
        let middles: Vec<Point2> = (0..n)
            .filter(|&k| met[k].1)
            .map(|k| midpoint(self.position(met[k].0, point), self.position(met[(k + 1) % n].0, point)))
            .collect();
        let [a, b] = middles[..] else { return false };
        [0.25, 0.5, 0.75].iter().all(|&t| self.local.height_slot(a + (b - a) * t).0 <= 0.0)
    }

    fn position(&self, id: usize, point: &dyn Fn(usize) -> Point2) -> Point2 {
        if id >= self.first_new { self.nodes[id - self.first_new] } else { point(id) }
    }

    /// The four quarters of `cell`, with the crossings of its inner half-edges
    /// added as new nodes; `None` if a side's crossings do not match the side
    /// of its midpoint (more crossings on the side than were found, or a
    /// crossing within the tolerance of the midpoint), those sides recorded.
    fn split(&mut self, cell: &Cell, point: &dyn Fn(usize) -> Point2) -> Option<[Cell; 4]> {
        let c = cell.corners;
        let mid: [Point2; 4] = std::array::from_fn(|k| midpoint(c[k], c[(k + 1) % 4]));
        let centre = centre(cell);
        let at_c = self.local.height_slot(centre);
        let hc = at_c.0;
        // Each side's crossings before and after its midpoint.
        let mut halves: [[Vec<usize>; 2]; 4] = Default::default();
        let mut mid_h = [(0.0, None); 4];
        let mut agree = true;
        for k in 0..4 {
            let (a, b) = (c[k], c[(k + 1) % 4]);
            let d = b - a;
            for &id in &cell.sides[k] {
                let t = (self.position(id, point) - a).dot(&d) / d.norm_squared();
                halves[k][usize::from(t >= 0.5)].push(id);
            }
            mid_h[k] = self.local.height_slot(mid[k]);
            if (halves[k][0].len() % 2 == 1) != (cell.inside[k] != (mid_h[k].0 > 0.0)) {
                self.asked.push((cell.bases[k], a, b));
                agree = false;
            }
        }
        if !agree {
            return None;
        }
        // Inner half-edge k, from mid[k] to the centre: its crossings in that order.
        let mut inner: [Vec<usize>; 4] = Default::default();
        for k in 0..4 {
            let mut found = crossings(self.local, mid[k], mid_h[k], centre, at_c)?;
            for f in self.inner_fixes.iter().filter(|f| f[0] == mid[k] && f[1] == centre) {
                refine_piece(self.local, &mut found, mid[k], centre, f[2], f[3])?;
            }
            for p in found {
                inner[k].push(self.first_new + self.nodes.len());
                self.nodes.push(p);
            }
        }
        let rev = |v: &Vec<usize>| v.iter().rev().copied().collect::<Vec<_>>();
        let (m_in, c_in) = (mid_h.map(|h| h.0 > 0.0), hc > 0.0);
        let [h0, h1, h2, h3] = halves;
        let [[s0a, s0b], [s1a, s1b], [s2a, s2b], [s3a, s3b]] = [h0, h1, h2, h3];
        let b = cell.bases;
        let half: [Base; 4] = std::array::from_fn(|k| Base::Inner(mid[k], centre));
        Some([
            Cell {
                corners: [c[0], mid[0], centre, mid[3]],
                inside: [cell.inside[0], m_in[0], c_in, m_in[3]],
                sides: [s0a, inner[0].clone(), rev(&inner[3]), s3b],
                bases: [b[0], half[0], half[3], b[3]],
            },
            Cell {
                corners: [mid[0], c[1], mid[1], centre],
                inside: [m_in[0], cell.inside[1], m_in[1], c_in],
                sides: [s0b, s1a, inner[1].clone(), rev(&inner[0])],
                bases: [b[0], b[1], half[1], half[0]],
            },
            Cell {
                corners: [centre, mid[1], c[2], mid[2]],
                inside: [c_in, m_in[1], cell.inside[2], m_in[2]],
                sides: [rev(&inner[1]), s1b, s2a, inner[2].clone()],
                bases: [half[1], b[1], b[2], half[2]],
            },
            Cell {
                corners: [mid[3], centre, mid[2], c[3]],
                inside: [m_in[3], c_in, m_in[2], cell.inside[3]],
                sides: [inner[3].clone(), rev(&inner[2]), s2b, s3a],
                bases: [half[3], half[2], b[2], b[3]],
            },
        ])
    }
}

/// The contour crossings of the segment from `a` to `b` (heights and
/// contact slots as `Local::height_slot` gives them), in order from `a`: one
/// where the ends are on different sides (the first from the inside end),
/// the gaps where both are inside (`Local::gaps`), none where both are
/// outside. `None` if `a` is inside without a contact triangle (outside the box).
fn crossings(
    local: &Local<'_>,
    a: Point2,
    (ha, slot_a): (f64, Option<usize>),
    b: Point2,
    (hb, slot_b): (f64, Option<usize>),
) -> Option<Vec<Point2>> {
    Some(match (ha > 0.0, hb > 0.0) {
        (true, false) => vec![local.bisect_heights(a, ha, slot_a, b, hb)],
        (false, true) => vec![local.bisect_heights(b, hb, slot_b, a, ha)],
        (true, true) => local.gaps(a, slot_a?, b, hb),
        (false, false) => Vec::new(),
    })
}

/// Replaces the crossings `found` of the segment from `a` to `b` (in order
/// from `a`) that lie on its piece between `p` and `q` by those found on the
/// piece's two halves ([`crossings`] on each), its midpoint classified on the
/// exact drop-cutter: where a piece holds three crossings (its ends on
/// different sides, a gap in the inside stretch or an inside sliver in the
/// outside one), the half whose ends are both inside is walked for its gaps,
/// and a half whose ends differ is given its crossing. The midpoint is the one
/// the split of a cell with that side classifies, so the crossings then match
/// it. `None` as [`crossings`] (`found` unchanged).
pub(crate) fn refine_piece(
    local: &Local<'_>,
    found: &mut Vec<Point2>,
    a: Point2,
    b: Point2,
    p: Point2,
    q: Point2,
) -> Option<()> {
    let d = b - a;
    let t = |x: Point2| (x - a).dot(&d) / d.norm_squared();
    let (p, q) = if t(p) <= t(q) { (p, q) } else { (q, p) };
    let (at_p, at_q) = (local.height_slot(p), local.height_slot(q));
    let m = midpoint(p, q);
    let at_m = local.height_slot(m);
    let mut new = crossings(local, p, at_p, m, at_m)?;
    new.extend(crossings(local, m, at_m, q, at_q)?);
    let (tp, tq) = (t(p), t(q));
    let first = found.partition_point(|&x| t(x) < tp);
    let last = found.partition_point(|&x| t(x) < tq);
    found.splice(first..last, new);
    Some(())
}

/// The links of a cell with at most one exit (an exit and its entry, which
/// need no drop-cutter), or `None` if the cell must be resolved.
pub(crate) fn simple_links(cell: &Cell) -> Option<Vec<(usize, usize)>> {
    let met = walk(cell);
    (met.iter().filter(|m| m.1).count() <= 1).then(|| join(&met, true))
}

/// The crossings of `cell` in walk order, each with whether it is an exit
/// (the walk leaves the inside there).
fn walk(cell: &Cell) -> Vec<(usize, bool)> {
    let mut met = Vec::new();
    for k in 0..4 {
        let mut inside = cell.inside[k];
        for &id in &cell.sides[k] {
            met.push((id, inside));
            inside = !inside;
        }
    }
    met
}

/// Each exit linked to the next crossing in walk order (`join_inside`: the
/// inside is joined across the cell) or to the previous one (the outside is).
fn join(met: &[(usize, bool)], join_inside: bool) -> Vec<(usize, usize)> {
    let n = met.len();
    (0..n)
        .filter(|&k| met[k].1)
        .map(|k| (met[k].0, if join_inside { met[(k + 1) % n].0 } else { met[(k + n - 1) % n].0 }))
        .collect()
}

fn midpoint(a: Point2, b: Point2) -> Point2 {
    Point2::new(0.5 * (a.x + b.x), 0.5 * (a.y + b.y))
}

fn centre(cell: &Cell) -> Point2 {
    midpoint(cell.corners[0], cell.corners[2])
}
