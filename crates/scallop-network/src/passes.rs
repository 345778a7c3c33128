//! PLANE_PASSES (finishing.md 6.3): plane-network intersection by marching
//! squares, traced quad to quad, clipped to a zone.
//!
//! Edges: the u-edge `(a, b)` joins nodes `(a, b)` and `(a + 1, b)` (id
//! `a (N_v + 1) + b`); the v-edge `(a, b)` joins `(a, b)` and `(a, b + 1)` (id
//! `N_u (N_v + 1) + a N_v + b`). Local edges of quad `(a, b)`: 0 = u-edge
//! `(a, b)`, 1 = v-edge `(a + 1, b)`, 2 = u-edge `(a, b + 1)`, 3 = v-edge `(a, b)`.
//! A node is "above" when `m . Q >= d`; an edge crosses when its nodes differ.

use scallop_geom::Point3;

use super::spacing::ToolModel;
use super::time::pass_length_time;
use super::{CellLabels, Network, Pass, RawNormal, Zoning};
use scallop_strategy::tol;

/// A point of a pass under construction.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Vertex {
    pub(crate) p: Point3,
    /// The exact normal at `uv`, finished only when the spacing needs it.
    pub(crate) n: RawNormal,
    pub(crate) uv: [f64; 2],
}

impl Vertex {
    /// The point at `t` between two vertices, with `self`'s normal (the
    /// caller sets the normal at the new `uv`).
    fn lerp(&self, other: &Vertex, t: f64) -> Vertex {
        Vertex {
            p: self.p + (other.p - self.p) * t,
            n: self.n,
            uv: [self.uv[0] + (other.uv[0] - self.uv[0]) * t, self.uv[1] + (other.uv[1] - self.uv[1]) * t],
        }
    }
}

/// Reusable buffers of a sweep (one per thread).
#[derive(Debug, Default)]
pub(crate) struct Workspace {
    g: Vec<f64>,
    marks: Vec<u32>,
    stamp: u32,
    spans: Vec<Span>,
    sorted: Vec<Span>,
    /// The spans of a plane's bucket window that it cuts.
    live: Vec<u32>,
    starts: Vec<usize>,
    fill: Vec<usize>,
    forward: Vec<Vertex>,
    backward: Vec<Vertex>,
    piece: Vec<Vertex>,
}

/// A network quad by its indices along u and v.
#[derive(Debug, Clone, Copy)]
struct Quad {
    a: usize,
    b: usize,
}

/// A quad's range of `g`, its indices (stored, not divided out of the quad
/// index on every plane) and its corner values (read in sequence by the planes
/// instead of gathered from the nodes).
#[derive(Debug, Clone, Copy, Default)]
struct Span {
    lo: f64,
    hi: f64,
    a: u32,
    b: u32,
    c: [f64; 4],
}

/// The passes of one plane and its NEXT_SPACING.
pub(crate) struct PlaneCut {
    pub(crate) passes: Vec<Pass>,
    pub(crate) spacing: f64,
    /// The vertex that set the spacing.
    pub(crate) worst: Point3,
}

/// A network, a direction and (optionally) a zone, ready to cut planes.
pub(crate) struct PlaneCutter<'a> {
    net: &'a Network,
    zoning: Option<(&'a Zoning, u32)>,
    f: [f64; 2],
    m: [f64; 2],
    ws: &'a mut Workspace,
    g0: f64,
    inv_width: f64,
    buckets: usize,
    extent: f64,
    range: (f64, f64),
    cos_sharp: f64,
    machine: scallop_analysis::MachineLimits,
    /// `N_u (N_v + 1)`: the first v-edge id.
    u_edges: usize,
}

impl<'a> PlaneCutter<'a> {
    /// Prepares planes of direction `theta` over the zone's quads (all quads
    /// without a zoning). `None` when the zone has no quad.
    pub(crate) fn new(
        net: &'a Network,
        zoning: Option<(&'a Zoning, u32)>,
        theta: f64,
        cos_sharp: f64,
        machine: scallop_analysis::MachineLimits,
        ws: &'a mut Workspace,
    ) -> Option<PlaneCutter<'a>> {
        let (sin, cos) = theta.sin_cos();
        let f = [cos, sin];
        let m = [-sin, cos];
        // g = m . Q at the nodes the zone's quads use (all nodes without a zoning);
        // the others are never read.
        let dot = |p: &Point3| m[0] * p.x + m[1] * p.y;
        ws.g.resize(net.points.len(), 0.0);
        let edges = net.quads_u * (net.quads_v + 1) + (net.quads_u + 1) * net.quads_v;
        if ws.marks.len() != edges {
            ws.marks = vec![0; edges];
            ws.stamp = 0;
        }
        let (nu, nv) = (net.quads_u, net.quads_v);
        ws.spans.clear();
        // The span of g over a quad's corners (a, b), (a + 1, b), (a + 1, b + 1),
        // (a, b + 1); plain comparisons: g is finite (no NaN handling needed).
        let span_of = |c: [f64; 4], a: usize, b: usize| {
            let (mut lo, mut hi) = (c[0], c[0]);
            for &x in &c[1..] {
                lo = if x < lo { x } else { lo };
                hi = if x > hi { x } else { hi };
            }
            // INVARIANT: a < N_u, b < N_v, both below MAX_NETWORK_QUADS.
            #[allow(clippy::cast_possible_truncation)]
            Span { lo, hi, a: a as u32, b: b as u32, c }
        };
        let mut range = (f64::INFINITY, f64::NEG_INFINITY);
        match zoning {
            None => {
                for (g, p) in ws.g.iter_mut().zip(&net.points) {
                    *g = dot(p);
                }
                let g = &ws.g;
                ws.spans.extend((0..nu).flat_map(|a| {
                    (0..nv).map(move |b| {
                        let (n00, n10) = (net.node(a, b), net.node(a + 1, b));
                        span_of([g[n00], g[n10], g[n10 + 1], g[n00 + 1]], a, b)
                    })
                }));
                for s in &ws.spans {
                    range = (range.0.min(s.lo), range.1.max(s.hi));
                }
            }
            Some((zoning, zone)) => {
                // One pass over the zone's quads: corner values, span, extent.
                let k = zoning.zones.binary_search(&zone).ok()?;
                let quads = &zoning.quads[k];
                ws.spans.reserve(quads.len());
                for &[a, b] in quads {
                    let (a, b) = (a as usize, b as usize);
                    let (n00, n10) = (net.node(a, b), net.node(a + 1, b));
                    let c = [
                        dot(&net.points[n00]),
                        dot(&net.points[n10]),
                        dot(&net.points[n10 + 1]),
                        dot(&net.points[n00 + 1]),
                    ];
                    ws.g[n00] = c[0];
                    ws.g[n10] = c[1];
                    ws.g[n10 + 1] = c[2];
                    ws.g[n00 + 1] = c[3];
                    let s = span_of(c, a, b);
                    ws.spans.push(s);
                    range = zone_extent(net, zoning, zone, &ws.g, (a, b), &s, range);
                }
            }
        }
        if ws.spans.is_empty() || range.0 > range.1 {
            return None;
        }
        // Bucket the quads by their minimum (counting sort, one bucket per quad).
        let (mut g0, mut g1, mut extent) = (f64::INFINITY, f64::NEG_INFINITY, 0.0f64);
        for s in &ws.spans {
            g0 = if s.lo < g0 { s.lo } else { g0 };
            g1 = if s.lo > g1 { s.lo } else { g1 };
            let e = s.hi - s.lo;
            extent = if e > extent { e } else { extent };
        }
        let buckets = ws.spans.len();
        let width = (g1 - g0) / buckets as f64;
        let inv_width = if width > 0.0 { width.recip() } else { 0.0 };
        let bucket = |x: f64| -> usize {
            // INVARIANT: clamped into [0, buckets - 1].
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
            // `as` saturates: a negative (or NaN) position is bucket 0.
            let b = ((x - g0) * inv_width) as usize;
            b.min(buckets - 1)
        };
        ws.starts.clear();
        ws.starts.resize(buckets + 1, 0);
        for s in &ws.spans {
            ws.starts[bucket(s.lo) + 1] += 1;
        }
        for i in 0..buckets {
            ws.starts[i + 1] += ws.starts[i];
        }
        ws.sorted.clear();
        ws.sorted.resize(ws.spans.len(), Span::default());
        ws.fill.clear();
        ws.fill.extend_from_slice(&ws.starts);
        for s in &ws.spans {
            let b = bucket(s.lo);
            ws.sorted[ws.fill[b]] = *s;
            ws.fill[b] += 1;
        }
        let u_edges = nu * (nv + 1);
        Some(PlaneCutter { net, zoning, f, m, ws, g0, inv_width, buckets, extent, range, cos_sharp, machine, u_edges })
    }

    /// `(d_min, d_max)`: the extent of the zone along `m` (its cells clipped to
    /// the bilinear network quads).
    pub(crate) fn range(&self) -> (f64, f64) {
        self.range
    }

    fn bucket(&self, x: f64) -> usize {
        // INVARIANT: clamped into [0, buckets - 1].
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        // `as` saturates: a negative (or NaN) position is bucket 0.
        let b = ((x - self.g0) * self.inv_width) as usize;
        b.min(self.buckets - 1)
    }

    fn in_zone(&self, q: usize) -> bool {
        self.zoning.is_none_or(|(z, zone)| z.quad_in_zone(q, zone))
    }

    /// The ids of local edges 0 to 3 of a quad (arrays indexed by the local
    /// edge: loads instead of a `match` on a data-dependent `k`).
    #[inline]
    fn edge_ids(&self, quad: Quad) -> [usize; 4] {
        let nv = self.net.quads_v;
        // u-edge (a, b) has the id of node (a, b); v-edge (a, b) is `u_edges + a N_v + b`.
        let e0 = self.net.node(quad.a, quad.b);
        let e3 = self.u_edges + quad.a * nv + quad.b;
        [e0, e3 + nv, e0 + 1, e3]
    }

    /// `(node0, node1)` of local edge `k` of a quad.
    #[inline]
    fn edge_nodes(&self, quad: Quad, k: usize) -> (usize, usize) {
        let n00 = self.net.node(quad.a, quad.b);
        let n10 = n00 + self.net.quads_v + 1;
        ([n00, n10, n00 + 1, n00][k & 3], [n10, n10 + 1, n10 + 1, n00 + 1][k & 3])
    }

    /// `g` at the corners `(a, b), (a + 1, b), (a + 1, b + 1), (a, b + 1)`.
    fn corners(&self, quad: Quad) -> [f64; 4] {
        let Quad { a, b } = quad;
        let g = &self.ws.g;
        let (n00, n10) = (self.net.node(a, b), self.net.node(a + 1, b));
        [g[n00], g[n10], g[n10 + 1], g[n00 + 1]]
    }

    /// Which local edges cross the plane, from the corner values: bit `k` for
    /// local edge `k`.
    #[inline]
    fn crossings(c: &[f64; 4], d: f64) -> usize {
        let s = c.map(|x| usize::from(x >= d));
        (s[0] ^ s[1]) | (s[1] ^ s[2]) << 1 | (s[3] ^ s[2]) << 2 | (s[0] ^ s[3]) << 3
    }

    /// The crossing point of local edge `k` of a quad (the same from both quads).
    fn point(&self, quad: Quad, k: usize, d: f64) -> Vertex {
        let (i, j) = self.edge_nodes(quad, k);
        let (gi, gj) = (self.ws.g[i], self.ws.g[j]);
        let t = ((d - gi) / (gj - gi)).clamp(0.0, 1.0);
        let (nu, nv) = (self.net.quads_u as f64, self.net.quads_v as f64);
        let (pi, pj) = (self.net.points[i], self.net.points[j]);
        let p = pi + (pj - pi) * t;
        let Quad { a, b } = quad;
        // The exact normal at the crossing's (u, v) (6.4), along the edge's isoline.
        let (uv, n) = match k {
            0 | 2 => {
                let row = if k == 0 { b } else { b + 1 };
                let u = (a as f64 + t) / nu;
                ([u, row as f64 / nv], self.net.raw_normal_on_row(row, u))
            }
            _ => {
                let column = if k == 1 { a + 1 } else { a };
                let v = (b as f64 + t) / nv;
                ([column as f64 / nu, v], self.net.raw_normal_on_column(column, v))
            }
        };
        Vertex { p, n, uv }
    }

    /// The exit edge of a curve entering a quad of corner values `c` by local
    /// edge `k` (marching squares; a saddle is resolved by the sign at the
    /// quad centre).
    #[inline]
    fn partner(c: &[f64; 4], k: usize, d: f64) -> usize {
        let crossing = Self::crossings(c, d);
        if crossing == 15 {
            let centre = 0.25 * (c[0] + c[1] + c[2] + c[3]);
            // Same side as corner 0 at the centre: corners 1 and 3 are cut off.
            let pairs = if (centre >= d) == (c[0] >= d) { [1, 0, 3, 2] } else { [3, 2, 1, 0] };
            return pairs[k];
        }
        (0..4).find(|&e| e != k && crossing & (1 << e) != 0).unwrap_or(k)
    }

    /// The quad across local edge `k`, and that edge's local index there.
    #[inline]
    fn neighbour(&self, quad: Quad, k: usize) -> Option<(Quad, usize)> {
        let (nu, nv) = (self.net.quads_u, self.net.quads_v);
        let Quad { a, b } = quad;
        // Tables indexed by the local edge (no `match` on a data-dependent k):
        // whether a quad lies across, its offset, and the edge's index there.
        let next = match k {
            0 => (b > 0).then(|| (Quad { a, b: b - 1 }, 2)),
            1 => (a + 1 < nu).then(|| (Quad { a: a + 1, b }, 3)),
            2 => (b + 1 < nv).then(|| (Quad { a, b: b + 1 }, 0)),
            _ => (a > 0).then(|| (Quad { a: a - 1, b }, 1)),
        };
        next.filter(|(n, _)| self.in_zone(n.a * nv + n.b))
    }

    /// Walks from a quad entered by edge `k`, appending crossing points; true
    /// when it came back to a marked edge (a closed curve).
    fn walk(&mut self, mut quad: Quad, mut k: usize, d: f64, into: &mut Vec<Vertex>) -> bool {
        loop {
            let exit = Self::partner(&self.corners(quad), k, d);
            let id = self.edge_ids(quad)[exit];
            if self.ws.marks[id] == self.ws.stamp {
                return true;
            }
            self.ws.marks[id] = self.ws.stamp;
            into.push(self.point(quad, exit, d));
            match self.neighbour(quad, exit) {
                Some((n, e)) => (quad, k) = (n, e),
                None => return false,
            }
        }
    }

    /// The whole curve through local edge `k` of a quad.
    fn trace(&mut self, quad: Quad, k: usize, d: f64) -> Vec<Vertex> {
        let mut forward = std::mem::take(&mut self.ws.forward);
        let mut backward = std::mem::take(&mut self.ws.backward);
        forward.clear();
        backward.clear();
        let id = self.edge_ids(quad)[k & 3];
        self.ws.marks[id] = self.ws.stamp;
        forward.push(self.point(quad, k, d));
        if self.walk(quad, k, d, &mut forward) {
            forward.push(forward[0]);
        } else if let Some((n, e)) = self.neighbour(quad, k) {
            self.walk(n, e, d, &mut backward);
            backward.reverse();
            backward.append(&mut forward);
            std::mem::swap(&mut forward, &mut backward);
        }
        self.ws.backward = backward;
        forward
    }

    /// PLANE_PASSES at offset `d` with its NEXT_SPACING.
    pub(crate) fn plane(&mut self, d: f64, tool: &ToolModel) -> PlaneCut {
        // A plane through the lowest node would cut nothing (nodes on it are
        // "above"): move it a rounding step inside, so that it yields the
        // boundary as the top plane does.
        let d = d.max(self.g0 + tol::PLANE_NUDGE_REL * (self.extent + (self.range.1 - self.range.0)).max(1.0));
        self.ws.stamp = self.ws.stamp.wrapping_add(1);
        if self.ws.stamp == 0 {
            self.ws.marks.fill(0);
            self.ws.stamp = 1;
        }
        let mut cut = PlaneCut { passes: Vec::new(), spacing: f64::INFINITY, worst: Point3::origin() };
        let (first, last) = (self.bucket(d - self.extent), self.bucket(d));
        // The spans of the window that the plane cuts, listed without a branch
        // (the index is written always, the count moves when the span is cut).
        let window = self.ws.starts[first]..self.ws.starts[last + 1];
        let mut live = std::mem::take(&mut self.ws.live);
        live.resize(window.len(), 0);
        let mut count = 0;
        for (i, span) in window.clone().zip(&self.ws.sorted[window]) {
            // INVARIANT: fewer spans than quads (u32-indexed).
            #[allow(clippy::cast_possible_truncation)]
            let i = i as u32;
            live[count] = i;
            count += usize::from(span.lo < d && span.hi >= d);
        }
        for &i in &live[..count] {
            let span = self.ws.sorted[i as usize];
            let quad = Quad { a: span.a as usize, b: span.b as usize };
            let ids = self.edge_ids(quad);
            // The crossing edges not yet traced, as bits; most cut quads have
            // none left (their curve came through already), so the loop below
            // rarely runs. Marks are read again there: a trace marks edges.
            let mut todo = Self::crossings(&span.c, d);
            for (k, &id) in ids.iter().enumerate() {
                todo &= !(usize::from(self.ws.marks[id] == self.ws.stamp) << k);
            }
            while todo != 0 {
                let k = todo.trailing_zeros() as usize;
                todo &= todo - 1;
                if self.ws.marks[ids[k]] != self.ws.stamp {
                    let mut line = self.trace(quad, k, d);
                    self.emit(&mut line, tool, &mut cut);
                    self.ws.forward = line;
                }
            }
        }
        self.ws.live = live;
        cut.passes.sort_by(|a, b| self.mid(a).total_cmp(&self.mid(b)));
        cut
    }

    fn mid(&self, pass: &Pass) -> f64 {
        let (a, b) = (pass.points[0], pass.points[pass.points.len() - 1]);
        0.5 * (self.f[0] * (a.x + b.x) + self.f[1] * (a.y + b.y))
    }

    /// Orients a traced curve along +f, clips it to the zone and adds its passes.
    fn emit(&mut self, line: &mut [Vertex], tool: &ToolModel, cut: &mut PlaneCut) {
        if line.len() < 2 {
            return;
        }
        let along = |v: &Vertex| self.f[0] * v.p.x + self.f[1] * v.p.y;
        if along(&line[line.len() - 1]) < along(&line[0]) {
            line.reverse();
        }
        match self.zoning {
            None => self.finish(line, tool, cut),
            Some((zoning, zone)) => {
                let mut piece = std::mem::take(&mut self.ws.piece);
                let net = self.net;
                clip(
                    line,
                    &zoning.labels,
                    zone,
                    &mut piece,
                    |uv| net.raw_normal_at(uv[0], uv[1]),
                    |p| {
                        self.finish(p, tool, cut);
                    },
                );
                self.ws.piece = piece;
            }
        }
    }

    /// Counts a piece's vertices for the spacing and keeps it as a pass unless short.
    fn finish(&self, piece: &[Vertex], tool: &ToolModel, cut: &mut PlaneCut) {
        for v in piece {
            // Most vertices allow more than the plane's spacing so far: a
            // conservative test on the raw normal spares them the square roots
            // and divisions of the normalisation and of the exact spacing (the
            // minimum and the vertex that sets it stay the same, bit for bit).
            if let Some(w) = self.net.normal_direction(&v.n)
                && tool.exceeds(&w, self.f, self.m, cut.spacing)
            {
                continue;
            }
            let n = self.net.unit_normal(&v.n, v.uv[0], v.uv[1]);
            let spacing = tool.spacing(&n, self.f, self.m);
            if spacing < cut.spacing {
                cut.spacing = spacing;
                cut.worst = v.p;
            }
        }
        if piece.len() < 2 {
            return;
        }
        let points: Vec<Point3> = piece.iter().map(|v| v.p).collect();
        let (length, time) = pass_length_time(&points, self.cos_sharp, &self.machine);
        if length < tol::MIN_PASS_LENGTH {
            return;
        }
        cut.passes.push(Pass { points, params: piece.iter().map(|v| v.uv).collect(), length, time });
    }
}

/// Splits `line` where the clustering-cell label changes (exact crossing of the
/// axis-aligned cell boundaries, the boundary point inserted) and hands each
/// maximal piece of label `zone` to `out`; inserted points get the exact
/// `normal` at their `(u, v)`.
fn clip(
    line: &[Vertex],
    labels: &CellLabels,
    zone: u32,
    piece: &mut Vec<Vertex>,
    normal: impl Fn([f64; 2]) -> RawNormal,
    mut out: impl FnMut(&[Vertex]),
) {
    let (cu, cv) = (labels.cells_u, labels.cells_v);
    let cell = |v: &Vertex| (CellLabels::cell_index(v.uv[0], cu), CellLabels::cell_index(v.uv[1], cv));
    let label = |(i, j): (usize, usize)| labels.labels[i * cv + j];
    let mut current = cell(&line[0]);
    let mut inside = label(current) == zone;
    piece.clear();
    if inside {
        piece.push(line[0]);
    }
    let mut crossings: Vec<(f64, isize, isize)> = Vec::new();
    for w in line.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        let target = cell(b);
        let (du, dv) = (target.0.abs_diff(current.0), target.1.abs_diff(current.1));
        if du + dv <= 1 {
            // No or one cell boundary crossed (the common cases, one predictable
            // branch): no list to sort, and the boundary's fraction (two
            // divisions) only where the label changes there; the same values as
            // the general path below. (`inside` is the label test of `current`,
            // so a segment within its cell changes nothing.)
            let now = label(target) == zone;
            if now != inside {
                let t = if du == 1 {
                    boundary_at(a.uv[0], b.uv[0], current.0.max(target.0), cu)
                } else {
                    boundary_at(a.uv[1], b.uv[1], current.1.max(target.1), cv)
                };
                let mut x = a.lerp(b, t);
                x.n = normal(x.uv);
                piece.push(x);
                if inside {
                    out(piece);
                    piece.clear();
                }
                inside = now;
            }
            current = target;
        } else {
            crossings.clear();
            boundary_crossings(a.uv[0], b.uv[0], current.0, target.0, cu, |t, step| crossings.push((t, step, 0)));
            boundary_crossings(a.uv[1], b.uv[1], current.1, target.1, cv, |t, step| crossings.push((t, 0, step)));
            crossings.sort_by(|x, y| x.0.total_cmp(&y.0));
            let (mut i, mut j) = (current.0.cast_signed(), current.1.cast_signed());
            for &(t, di, dj) in &crossings {
                i = (i + di).clamp(0, cu.cast_signed() - 1);
                j = (j + dj).clamp(0, cv.cast_signed() - 1);
                let now = label((i.cast_unsigned(), j.cast_unsigned())) == zone;
                if now != inside {
                    let mut x = a.lerp(b, t);
                    x.n = normal(x.uv);
                    if inside {
                        piece.push(x);
                        out(piece);
                        piece.clear();
                    } else {
                        piece.push(x);
                    }
                    inside = now;
                }
            }
            let final_inside = label(target) == zone;
            if final_inside != inside {
                // Rounding left the walk in another cell than b's: follow b.
                if inside {
                    out(piece);
                    piece.clear();
                } else {
                    piece.push(*a);
                }
                inside = final_inside;
            }
            current = target;
        }
        if inside {
            piece.push(*b);
        }
    }
    if inside && !piece.is_empty() {
        out(piece);
    }
}

/// Calls `push(t, step)` for each cell boundary `k / cells` crossed between
/// parameters `a` (cell `from`) and `b` (cell `to`), `t` the fraction along.
fn boundary_crossings(a: f64, b: f64, from: usize, to: usize, cells: usize, mut push: impl FnMut(f64, isize)) {
    let at = |k: usize| boundary_at(a, b, k, cells);
    if to > from {
        for k in from + 1..=to {
            push(at(k), 1);
        }
    } else {
        for k in (to + 1..=from).rev() {
            push(at(k), -1);
        }
    }
}

/// The fraction along `[a, b]` of the cell boundary `k / cells`.
#[inline]
fn boundary_at(a: f64, b: f64, k: usize, cells: usize) -> f64 {
    (((k as f64 / cells as f64) - a) / (b - a)).clamp(0.0, 1.0)
}

/// Widens `range` by the extent along `m` of quad `q`'s part in `zone`: its
/// corners when all its cells are the zone's, else the corners of its
/// intersection with each cell of the zone, on the bilinear quad.
fn zone_extent(
    net: &Network,
    zoning: &Zoning,
    zone: u32,
    g: &[f64],
    (a, b): (usize, usize),
    span: &Span,
    range: (f64, f64),
) -> (f64, f64) {
    let (nu, nv) = (net.quads_u, net.quads_v);
    if zoning.quad_label[a * nv + b] == zone {
        let lo = if span.lo < range.0 { span.lo } else { range.0 };
        let hi = if span.hi > range.1 { span.hi } else { range.1 };
        return (lo, hi);
    }
    let gc = [g[net.node(a, b)], g[net.node(a + 1, b)], g[net.node(a, b + 1)], g[net.node(a + 1, b + 1)]];
    let labels = &zoning.labels;
    let ((i0, i1), (j0, j1)) = (zoning.ranges_u[a], zoning.ranges_v[b]);
    let local = |cell: usize, cells: usize, k: usize, n: usize| {
        let lo = (cell as f64 / cells as f64 * n as f64 - k as f64).clamp(0.0, 1.0);
        let hi = ((cell + 1) as f64 / cells as f64 * n as f64 - k as f64).clamp(0.0, 1.0);
        [lo, hi]
    };
    let mut range = range;
    for i in i0..=i1 {
        for j in j0..=j1 {
            if labels.labels[i * labels.cells_v + j] != zone {
                continue;
            }
            for s in local(i, labels.cells_u, a, nu) {
                for t in local(j, labels.cells_v, b, nv) {
                    let x = (1.0 - s) * ((1.0 - t) * gc[0] + t * gc[2]) + s * ((1.0 - t) * gc[1] + t * gc[3]);
                    range = (range.0.min(x), range.1.max(x));
                }
            }
        }
    }
    range
}
