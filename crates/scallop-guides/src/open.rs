//! Open pockets closed by virtual flanks (Jousselin 2020, Ch. 4 §1.3.1 and
//! §2.1): where the flanks do not close a level, its limit curves are open
//! chains. The thesis closes the pocket with virtual, crossable flanks and
//! extended flanks built by the user; here they are built from the faces
//! (docs/guides-curves.md, "Open pockets"):
//!
//! - the virtual flank is the surface ruled by the bottom's vertex normals
//!   along the bottom's open edge (its edges used by one bottom triangle and
//!   by no flank triangle): the levels are offsets of the bottom, so this is
//!   where they stop lying over it. Being crossable, it is not offset by the
//!   tool radius;
//! - round the flanks' own open edge, the flanks are extended by their
//!   tangent planes, so a level above a flank's top stays on its side.
//!
//! The closed limit loops are the zero iso-line of
//! `F(P) = min(c(P) - (R + s_f), VIRTUAL_REACH - t(P))`, `c` the signed
//! clearance to the (extended) flanks, positive on the pocket side, and
//! `t(P) = (P - q) . o` when the closest bottom point `q` lies on the open
//! edge, `o` the virtual flank's outward normal there (`-inf` elsewhere),
//! extracted on the level by Marching Facets with root finding on the exact
//! `F`.

use rayon::prelude::*;
use scallop_field::{Closest, Feature, Surface};
use scallop_geom::{Point3, Vec3};
use scallop_mesh::{FastMap, TriMesh};

use crate::facets::march;
use crate::support::{Curve, Support, area_weighted_normals};

/// How far round the bottom's open edge (mm, tangent to the bottom) a level
/// point may lie and still count as over the bottom: small against the
/// voxel size, so the virtual flank stays within this of the swept surface,
/// and positive, so that `F` changes sign across it.
pub const VIRTUAL_REACH: f64 = 1e-3;

/// The edges of `mesh` used by one triangle, each `(a, b)` as travelled in
/// its triangle (the triangle on its left about the winding normal).
fn open_edges(mesh: &TriMesh) -> Vec<(u32, u32)> {
    let mut directed: Vec<(u32, u32)> =
        mesh.triangles().iter().flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3]))).collect();
    let mut undirected: Vec<(u32, u32)> = directed.iter().map(|&(a, b)| (a.min(b), a.max(b))).collect();
    undirected.sort_unstable();
    directed.retain(|&(a, b)| {
        let key = (a.min(b), a.max(b));
        let lo = undirected.partition_point(|x| *x < key);
        undirected.get(lo + 1) != Some(&key)
    });
    directed.sort_unstable();
    directed
}

/// A key of an undirected edge by its end points' coordinates.
fn coordinate_key(m: &TriMesh, a: u32, b: u32) -> [u64; 6] {
    let bits = |v: u32| m.vertices()[v as usize].coords.map(f64::to_bits);
    let (p, q) = (bits(a), bits(b));
    if (p.x, p.y, p.z) <= (q.x, q.y, q.z) { [p.x, p.y, p.z, q.x, q.y, q.z] } else { [q.x, q.y, q.z, p.x, p.y, p.z] }
}

/// The bottom and its open edge: the edges used by one bottom triangle and
/// by no flank triangle. The virtual flank along an edge `a -> b` is ruled
/// by the vertex normals interpolated along it, so its outward normal is
/// `(b - a) x n(s)`; at a vertex it is the mean direction of its open edges
/// crossed with the vertex normal. Every outward normal at a point is then
/// normal to the same `n`: the surface is continuous across the vertices.
struct OpenBottom {
    surface: Surface,
    normals: Vec<Vec3>,
    /// Undirected key to the edge as travelled in its triangle.
    edges: FastMap<(u32, u32), (u32, u32)>,
    /// Per vertex: the sum of the unit directions of its open edges.
    tangent: Vec<Vec3>,
}

impl OpenBottom {
    fn new(mesh: &TriMesh, flanks: &TriMesh) -> OpenBottom {
        let flank_edges: std::collections::HashSet<[u64; 6]> =
            open_edges(flanks).into_iter().map(|(a, b)| coordinate_key(flanks, a, b)).collect();
        let mut edges = FastMap::default();
        let mut tangent = vec![Vec3::zeros(); mesh.vertices().len()];
        for (a, b) in open_edges(mesh) {
            if flank_edges.contains(&coordinate_key(mesh, a, b)) {
                continue;
            }
            let d = mesh.vertices()[b as usize] - mesh.vertices()[a as usize];
            let d = if d.norm() > 0.0 { d.normalize() } else { d };
            tangent[a as usize] += d;
            tangent[b as usize] += d;
            edges.insert((a.min(b), a.max(b)), (a, b));
        }
        OpenBottom { surface: Surface::new(mesh), normals: area_weighted_normals(mesh, Vec3::zeros()), edges, tangent }
    }

    /// How far `p` lies beyond the virtual flank (negative before it), when
    /// its closest point is on the open edge; `-inf` when it is not.
    fn beyond(&self, p: &Point3, c: &Closest) -> f64 {
        let t = self.surface.mesh().triangles()[c.triangle];
        let verts = self.surface.mesh().vertices();
        let out = match c.feature {
            Feature::Face => None,
            Feature::Edge(k) => {
                let (u, v) = (t[k as usize], t[(k as usize + 1) % 3]);
                self.edges.get(&(u.min(v), u.max(v))).map(|&(a, b)| {
                    let (pa, pb) = (verts[a as usize], verts[b as usize]);
                    let s = scallop_mesh::segment_parameter(&c.point, &pa, &pb);
                    let n = self.normals[a as usize] * (1.0 - s) + self.normals[b as usize] * s;
                    (pb - pa).cross(&n)
                })
            }
            Feature::Vertex(k) => {
                let v = t[k as usize] as usize;
                Some(self.tangent[v].cross(&self.normals[v])).filter(|_| self.tangent[v].norm() > 0.0)
            }
        };
        out.filter(|o| o.norm() > 0.0).map_or(f64::NEG_INFINITY, |o| (p - c.point).dot(&o.normalize()))
    }
}

/// The bottom extended across its open edge (the edges used by one bottom
/// triangle and by no flank triangle) by a strip `width` wide, so that the
/// bottom itself, as the lowest level, holds the virtual flank and a closed
/// limit loop. The strip runs along the horizontal part of the virtual
/// flank's outward normal (the normal itself where that is vertical): a
/// crossable end meets the stock beyond it, and a turned or cast blank is
/// level there, not on the bottom's tangent plane, which rises steeply where
/// the bottom does (the impeller's hub at its inlet). `None` when the bottom
/// has no open edge or the strip does not make a valid mesh. Its facets are
/// split in four until their edges are at most `edge` long (at most
/// [`MAX_SPLITS`] times): the curves on it are extracted facet by facet.
pub fn extended_bottom(bottom: &TriMesh, flanks: &TriMesh, width: f64, edge: f64) -> Option<TriMesh> {
    let open = OpenBottom::new(bottom, flanks);
    if open.edges.is_empty() {
        return None;
    }
    let mut vertices = bottom.vertices().to_vec();
    let mut triangles: Vec<[usize; 3]> = bottom.triangles().iter().map(|t| t.map(|v| v as usize)).collect();
    let mut moved: FastMap<u32, usize> = FastMap::default();
    let mut strip_vertex = |v: u32, vertices: &mut Vec<Point3>| -> usize {
        *moved.entry(v).or_insert_with(|| {
            let out = open.tangent[v as usize].cross(&open.normals[v as usize]);
            let level = Vec3::new(out.x, out.y, 0.0);
            let dir = if level.norm() > 0.5 * out.norm() { level.normalize() } else { out.normalize() };
            vertices.push(vertices[v as usize] + dir * width);
            vertices.len() - 1
        })
    };
    let mut edges: Vec<(u32, u32)> = open.edges.values().copied().collect();
    edges.sort_unstable();
    for (a, b) in edges {
        let (a2, b2) = (strip_vertex(a, &mut vertices), strip_vertex(b, &mut vertices));
        let (a, b) = (a as usize, b as usize);
        triangles.push([b, a, a2]);
        triangles.push([b, a2, b2]);
    }
    for _ in 0..MAX_SPLITS {
        if longest_edge(&vertices, &triangles) <= edge {
            break;
        }
        triangles = split_in_four(&mut vertices, &triangles);
    }
    let (mesh, _) = TriMesh::from_indexed(&vertices, &triangles).ok()?;
    (mesh.triangles().len() == triangles.len()).then_some(mesh)
}

/// Splits halving the facets of an extended bottom at most this many times.
const MAX_SPLITS: usize = 3;

fn longest_edge(vertices: &[Point3], triangles: &[[usize; 3]]) -> f64 {
    triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| (vertices[t[k]] - vertices[t[(k + 1) % 3]]).norm()))
        .fold(0.0, f64::max)
}

/// Every triangle split in four at its edges' midpoints (shared between
/// neighbours, so the mesh stays connected; the surface is unchanged).
fn split_in_four(vertices: &mut Vec<Point3>, triangles: &[[usize; 3]]) -> Vec<[usize; 3]> {
    let mut mid: FastMap<(usize, usize), usize> = FastMap::default();
    let mut out = Vec::with_capacity(4 * triangles.len());
    for t in triangles {
        let m = [0, 1, 2].map(|k| {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                vertices.push(Point3::from((vertices[a].coords + vertices[b].coords) * 0.5));
                vertices.len() - 1
            })
        });
        out.extend([[t[0], m[0], m[2]], [m[0], t[1], m[1]], [m[2], m[1], t[2]], [m[0], m[1], m[2]]]);
    }
    out
}

/// The bottom and flanks of an open pocket, prepared for [`open_limit`].
pub(crate) struct OpenPocket {
    bottom: OpenBottom,
    flanks: Surface,
    /// Per flank vertex, whether it is on the flanks' open edge.
    flank_edge_vertex: Vec<bool>,
    flank_edges: FastMap<(u32, u32), ()>,
    clearance: f64,
}

impl OpenPocket {
    /// Prepares the bottom and flank faces; `clearance` is R + s_f (mm).
    pub(crate) fn new(bottom: &TriMesh, flanks: &TriMesh, clearance: f64) -> OpenPocket {
        let mut flank_edge_vertex = vec![false; flanks.vertices().len()];
        let mut flank_edges = FastMap::default();
        for (a, b) in open_edges(flanks) {
            flank_edge_vertex[a as usize] = true;
            flank_edge_vertex[b as usize] = true;
            flank_edges.insert((a.min(b), a.max(b)), ());
        }
        let (bottom, flanks) = (OpenBottom::new(bottom, flanks), Surface::new(flanks));
        OpenPocket { bottom, flanks, flank_edge_vertex, flank_edges, clearance }
    }

    /// The signed clearance to the flanks, positive on the pocket side. Round
    /// the flanks' open edge it is the distance to their tangent plane there:
    /// the flanks are extended by their tangent planes (the extended flank
    /// surfaces of Jousselin 2020, Ch. 4 §1.3.1), so a level that rises
    /// above a flank's top stays on its side.
    fn flank_clearance(&self, p: &Point3) -> f64 {
        let Some(c) = self.flanks.closest(p, f64::INFINITY) else { return f64::INFINITY };
        let n = self.flanks.pseudo_normal(&c);
        let t = self.flanks.mesh().triangles()[c.triangle];
        let on_edge = match c.feature {
            Feature::Face => false,
            Feature::Edge(k) => {
                let (a, b) = (t[k as usize], t[(k as usize + 1) % 3]);
                self.flank_edges.contains_key(&(a.min(b), a.max(b)))
            }
            Feature::Vertex(k) => self.flank_edge_vertex[t[k as usize] as usize],
        };
        let side = (p - c.point).dot(&n);
        if on_edge && n.norm() > 0.0 {
            -side / n.norm()
        } else {
            let d = c.dist2.sqrt();
            if side > 0.0 { -d } else { d }
        }
    }

    /// `F(P)` of the module documentation: positive inside the closed pocket.
    fn field(&self, p: &Point3) -> f64 {
        let Some(c) = self.bottom.surface.closest(p, f64::INFINITY) else { return f64::NEG_INFINITY };
        (self.flank_clearance(p) - self.clearance).min(VIRTUAL_REACH - self.bottom.beyond(p, &c))
    }
}

/// The limit curves of an open pocket on `support`: closed loops, inside on
/// the left, and any open chain left (the region reaches the level's edge).
pub(crate) fn open_limit(support: &Support, pocket: &OpenPocket) -> (Vec<Curve>, Vec<Curve>) {
    let f = |p: &Point3| pocket.field(p);
    let values: Vec<f64> = support.mesh().vertices().par_iter().map(f).collect();
    let curves = march(support, &values, &f, &|_| false).curves;
    curves.into_iter().partition(|c| c.line.closed)
}
