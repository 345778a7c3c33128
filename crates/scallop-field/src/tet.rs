//! Iso-surfaces by marching tetrahedra on the Kuhn (Freudenthal) split of each
//! voxel into six tetrahedra around its main diagonal.
//!
//! Why tetrahedra rather than the 256-case Marching Cubes table (Lorensen and
//! Cline 1987): a cube face with alternating corner states is ambiguous, and
//! the classic table can join it differently from the neighbouring cube, leaving
//! holes; consistent tables (MC33, Chernyaev 1995) resolve it with extra tests.
//! A tetrahedron has no ambiguous configuration (one triangle or one quad per
//! tetrahedron), and the Kuhn split is the same on both sides of every shared
//! face (each square face is cut along the diagonal from its lowest to its
//! highest corner), so the output is watertight and manifold by construction
//! wherever the grid does not clip it. The price is about twice as many
//! triangles as Marching Cubes, which welding and later decimation absorb.

use scallop_geom::Point3;
use scallop_mesh::FastMap;

use crate::{Field, tol};

/// The six tetrahedra of the unit cube (corner bit 1 = +x, 2 = +y, 4 = +z): one
/// per order of the axes along the path from corner 0 to corner 7.
const TETS: [[usize; 4]; 6] = [[0, 1, 3, 7], [0, 1, 5, 7], [0, 2, 3, 7], [0, 2, 6, 7], [0, 4, 5, 7], [0, 4, 6, 7]];

/// An indexed triangle soup, vertices welded by grid edge.
#[derive(Debug, Clone, Default)]
pub struct IsoMesh {
    /// Vertex positions.
    pub vertices: Vec<Point3>,
    /// Triangles, oriented with the normal towards increasing field values.
    pub triangles: Vec<[usize; 3]>,
}

fn corner(c: usize) -> [i64; 3] {
    [i64::from(c & 1 != 0), i64::from(c & 2 != 0), i64::from(c & 4 != 0)]
}

fn det(a: [i64; 3], b: [i64; 3], c: [i64; 3]) -> i64 {
    a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0])
}

fn sub(a: [i64; 3], b: [i64; 3]) -> [i64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

struct Extractor<'a> {
    field: &'a Field,
    iso: f64,
    edges: FastMap<(usize, usize), usize>,
    out: IsoMesh,
}

impl Extractor<'_> {
    /// The vertex on the edge from the inside sample `a` to the outside sample `b`.
    fn vertex(&mut self, a: [usize; 3], b: [usize; 3]) -> usize {
        let g = self.field.grid();
        let (la, lb) = (g.linear(a[0], a[1], a[2]), g.linear(b[0], b[1], b[2]));
        if let Some(&v) = self.edges.get(&(la.min(lb), la.max(lb))) {
            return v;
        }
        let (va, vb) = (self.field.value(a[0], a[1], a[2]), self.field.value(b[0], b[1], b[2]));
        let t = ((self.iso - va) / (vb - va)).clamp(tol::INTERP_CLAMP, 1.0 - tol::INTERP_CLAMP);
        let t = if t.is_nan() { 0.5 } else { t };
        let (pa, pb) = (g.point(a[0], a[1], a[2]), g.point(b[0], b[1], b[2]));
        self.out.vertices.push(pa + (pb - pa) * t);
        let v = self.out.vertices.len() - 1;
        self.edges.insert((la.min(lb), la.max(lb)), v);
        v
    }

    fn cell(&mut self, base: [usize; 3]) {
        let at = |c: usize| [base[0] + (c & 1), base[1] + ((c >> 1) & 1), base[2] + ((c >> 2) & 1)];
        let values: [f64; 8] = std::array::from_fn(|c| {
            let p = at(c);
            self.field.value(p[0], p[1], p[2])
        });
        let inside = values.map(|v| v <= self.iso);
        if inside.iter().all(|&s| s) || inside.iter().all(|&s| !s) {
            return;
        }
        for tet in TETS {
            let (ins, outs): (Vec<usize>, Vec<usize>) = tet.iter().partition(|&&c| inside[c]);
            match (ins.len(), outs.len()) {
                (1, 3) => self.fan(ins[0], [outs[0], outs[1], outs[2]], false, &at),
                (3, 1) => self.fan(outs[0], [ins[0], ins[1], ins[2]], true, &at),
                (2, 2) => self.quad([ins[0], ins[1]], [outs[0], outs[1]], &at),
                _ => {}
            }
        }
    }

    /// One triangle around the lone corner `a` of a tetrahedron, normal away
    /// from `a` (towards it when `a` is the lone outside corner).
    fn fan(&mut self, a: usize, mut o: [usize; 3], lone_outside: bool, at: &impl Fn(usize) -> [usize; 3]) {
        let (ca, c) = (corner(a), o.map(corner));
        let away = det(sub(c[0], ca), sub(c[1], ca), sub(c[2], ca)) > 0;
        if away == lone_outside {
            o.swap(1, 2);
        }
        let tri = o.map(|x| if lone_outside { self.vertex(at(x), at(a)) } else { self.vertex(at(a), at(x)) });
        self.out.triangles.push(tri);
    }

    /// Two triangles separating inside corners `i` from outside corners `o`,
    /// normal towards the outside pair (decided on the cube's integer corners).
    fn quad(&mut self, i: [usize; 2], o: [usize; 2], at: &impl Fn(usize) -> [usize; 3]) {
        let (a, b, c, d) = (corner(i[0]), corner(i[1]), corner(o[0]), corner(o[1]));
        // Cycle ac, ad, bd, bc at the edge midpoints (doubled coordinates).
        let mid = |p: [i64; 3], q: [i64; 3]| [p[0] + q[0], p[1] + q[1], p[2] + q[2]];
        let (m0, m1, m2) = (mid(a, c), mid(a, d), mid(b, d));
        let n_dir = sub(mid(c, d), mid(a, b));
        let forward = det(sub(m1, m0), sub(m2, m0), n_dir) > 0;
        let mut q = [
            self.vertex(at(i[0]), at(o[0])),
            self.vertex(at(i[0]), at(o[1])),
            self.vertex(at(i[1]), at(o[1])),
            self.vertex(at(i[1]), at(o[0])),
        ];
        if !forward {
            q.reverse();
        }
        self.out.triangles.push([q[0], q[1], q[2]]);
        self.out.triangles.push([q[0], q[2], q[3]]);
    }
}

/// The iso-surface `{field = iso}` of `field`, with the normals towards higher
/// values; vertices on one grid edge are one vertex (welded by construction).
/// Cells are visited in a fixed order, so the output depends only on the field.
#[must_use]
pub fn iso_surface(field: &Field, iso: f64) -> IsoMesh {
    let dims = field.grid().dims();
    let mut ex = Extractor { field, iso, edges: FastMap::default(), out: IsoMesh::default() };
    for k in 0..dims[2].saturating_sub(1) {
        for j in 0..dims[1].saturating_sub(1) {
            for i in 0..dims[0].saturating_sub(1) {
                ex.cell([i, j, k]);
            }
        }
    }
    ex.out
}
