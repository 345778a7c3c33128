//! Open pockets closed by virtual flanks (Jousselin 2020, Ch. 4 §1.3.1 and
//! §2.1): where the flanks do not close a level, its limit curves are open
//! chains. The pocket is then closed by a virtual, crossable flank: the
//! surface swept by the bottom's normals along the bottom's open edge (the
//! levels are offsets of the bottom, so this is where they stop being over
//! it). Being crossable, it is not offset by the tool radius.
//!
//! The closed limit loops are the boundary of the level region where both
//! hold: the tool clears the flanks (signed distance to them at least
//! R + s_f on the pocket side) and the point lies over the bottom (its offset
//! direction from its closest bottom point is normal there, not round an open
//! edge). That is the zero iso-line of
//! `F(P) = min(side(P) d(P, S_f) - (R + s_f), VIRTUAL_REACH - t(P))`, with
//! `t(P)` the part of `P - c` tangent to the bottom at its closest point `c`
//! when `c` lies on an open edge (0 elsewhere), extracted on the level by
//! Marching Facets with root finding on the exact `F`.

use rayon::prelude::*;
use scallop_field::{Feature, Surface};
use scallop_geom::Point3;
use scallop_mesh::{FastMap, TriMesh};

use crate::facets::march;
use crate::support::{Curve, Support};

/// How far round the bottom's open edge (mm, tangent to the bottom) a level
/// point may lie and still count as over the bottom: small against the
/// voxel size, so the virtual flank stays within this of the swept surface,
/// and positive, so that `F` changes sign across it.
pub const VIRTUAL_REACH: f64 = 1e-3;

/// The bottom and flanks of an open pocket, prepared for [`open_limit`].
pub(crate) struct OpenPocket {
    bottom: Surface,
    flanks: Surface,
    /// Undirected edges of the bottom used by one triangle (its open edge).
    boundary: FastMap<(u32, u32), ()>,
    /// Bottom vertices on an open edge.
    boundary_vertex: Vec<bool>,
    clearance: f64,
}

impl OpenPocket {
    /// Prepares the bottom and flank faces; `clearance` is R + s_f (mm).
    pub(crate) fn new(bottom: &TriMesh, flanks: &TriMesh, clearance: f64) -> OpenPocket {
        let mut count: FastMap<(u32, u32), u32> = FastMap::default();
        for t in bottom.triangles() {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *count.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        let mut boundary_vertex = vec![false; bottom.vertices().len()];
        let mut boundary = FastMap::default();
        for (&(a, b), &n) in &count {
            if n == 1 {
                boundary.insert((a, b), ());
                boundary_vertex[a as usize] = true;
                boundary_vertex[b as usize] = true;
            }
        }
        OpenPocket { bottom: Surface::new(bottom), flanks: Surface::new(flanks), boundary, boundary_vertex, clearance }
    }

    /// `F(P)` of the module documentation: positive inside the closed pocket.
    fn field(&self, p: &Point3) -> f64 {
        let flank = self.flanks.closest(p, f64::INFINITY).map_or(f64::INFINITY, |c| {
            let d = c.dist2.sqrt();
            if (p - c.point).dot(&self.flanks.pseudo_normal(&c)) > 0.0 { -d } else { d }
        });
        let Some(c) = self.bottom.closest(p, f64::INFINITY) else { return f64::NEG_INFINITY };
        let t = self.bottom.mesh().triangles()[c.triangle];
        let open = match c.feature {
            Feature::Face => false,
            Feature::Edge(k) => {
                let (a, b) = (t[k as usize], t[(k as usize + 1) % 3]);
                self.boundary.contains_key(&(a.min(b), a.max(b)))
            }
            Feature::Vertex(k) => self.boundary_vertex[t[k as usize] as usize],
        };
        let tangent = if open {
            let n = self.bottom.mesh().triangle(c.triangle);
            let normal = (n[1] - n[0]).cross(&(n[2] - n[0]));
            let len = normal.norm();
            let v = p - c.point;
            if len > 0.0 { (v - normal * (v.dot(&normal) / (len * len))).norm() } else { v.norm() }
        } else {
            0.0
        };
        (flank - self.clearance).min(VIRTUAL_REACH - tangent)
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
