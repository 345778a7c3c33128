//! Zone restriction of parallel-planes finishing: which contacts belong to one
//! zone of a labelled part (issue 8, zone machining by drop-cutter).

use std::collections::{HashMap, HashSet};

use scallop_cutter::{ClPoint, Contact};
use scallop_geom::Point3;
use scallop_mesh::{MeshIndex, TriMesh};

use crate::StrategyError;

/// One zone of a part whose mesh triangles carry zone labels, dilated by a
/// margin: the region [`crate::plan_zone_finishing`] machines.
///
/// A triangle belongs to the **dilated zone** when its label is the zone's, or
/// when all its vertices lie within the horizontal (XY, planning frame)
/// distance `margin` of the zone's vertices (so the dilation reaches at least
/// `margin` less one triangle). A cutter location
/// belongs to the region when its contact does: a facet contact's triangle is in
/// the dilated zone; an edge contact's triangle, or the other triangle of that
/// edge, is; a vertex contact's vertex has a triangle in the dilated zone.
///
/// **Why a margin.** Passes end where their contact leaves the region. Near such
/// a pass end the scallop is not held (the neighbouring pass may end earlier,
/// and the first and last planes lie half a spacing inside the region's edge):
/// the surface is finished only where both passes around a point run past it.
/// The cutter locations that shape a point have their contacts within about one
/// step-over of it, so a zone dilated by at least its largest step-over finishes
/// every point of the zone itself, whatever its neighbours do; the strip beyond
/// is machined twice. `scallop_engine::finish_zones` sizes the margin from the
/// plan (twice its largest plane spacing) and the stock simulation of the whole
/// program checks the borders.
#[derive(Debug, Clone, PartialEq)]
pub struct ZoneRegion {
    zone: u32,
    margin: f64,
    /// Per mesh triangle: in the dilated zone.
    accepted: Vec<bool>,
    /// Per mesh triangle: its vertex numbers (copied from the mesh).
    triangles: Vec<[u32; 3]>,
    /// Per mesh vertex: a triangle around it is accepted.
    vertex_accepted: Vec<bool>,
    /// Edges `(lower, higher vertex)` with an accepted triangle on them.
    edge_accepted: HashSet<(u32, u32)>,
    /// Triangles with the zone's label.
    core: usize,
}

impl ZoneRegion {
    /// The zone `zone` of `mesh` under per-triangle `labels` (one per mesh
    /// triangle, in mesh order), dilated by `margin` mm (XY).
    ///
    /// ```
    /// use scallop_geom::Point3;
    /// use scallop_mesh::TriMesh;
    /// use scallop_strategy::ZoneRegion;
    /// let p = |x: f64, y: f64| Point3::new(x, y, 0.0);
    /// // Four 1 mm strips along y, labelled 0, 0, 1, 1.
    /// let soup: Vec<[Point3; 3]> = (0..4)
    ///     .flat_map(|i| {
    ///         let x = f64::from(i);
    ///         [[p(x, 0.), p(x + 1., 0.), p(x + 1., 5.)], [p(x, 0.), p(x + 1., 5.), p(x, 5.)]]
    ///     })
    ///     .collect();
    /// let (mesh, _) = TriMesh::from_soup(&soup).unwrap();
    /// let labels = [0, 0, 0, 0, 1, 1, 1, 1];
    /// let tight = ZoneRegion::new(&mesh, &labels, 0, 0.0).unwrap();
    /// assert_eq!(tight.accepted_triangles(), 4);
    /// let wide = ZoneRegion::new(&mesh, &labels, 0, 1.0).unwrap();
    /// assert_eq!(wide.accepted_triangles(), 6); // the strip x in [2, 3] too
    /// ```
    ///
    /// # Errors
    /// [`StrategyError::BadParameter`] when `labels` does not have one entry per
    /// triangle, the margin is negative or not finite, or no triangle carries `zone`.
    pub fn new(mesh: &TriMesh, labels: &[u32], zone: u32, margin: f64) -> Result<ZoneRegion, StrategyError> {
        let triangles = mesh.triangles();
        #[allow(clippy::cast_precision_loss, reason = "a count in an error message")]
        if labels.len() != triangles.len() {
            return Err(StrategyError::BadParameter {
                name: "zone labels",
                value: labels.len() as f64,
                fix: "give one zone label per triangle of the machining mesh, in mesh order",
            });
        }
        if !(margin.is_finite() && margin >= 0.0) {
            return Err(StrategyError::BadParameter {
                name: "zone margin",
                value: margin,
                fix: "give a non-negative distance in mm",
            });
        }
        let core = labels.iter().filter(|&&l| l == zone).count();
        if core == 0 {
            return Err(StrategyError::EmptyZone { zone });
        }
        let vertices = mesh.vertices();
        let mut in_zone = vec![false; vertices.len()];
        for (t, tri) in triangles.iter().enumerate() {
            if labels[t] == zone {
                for &v in tri {
                    in_zone[v as usize] = true;
                }
            }
        }
        let near =
            if margin > 0.0 { near_vertices(vertices, triangles, labels, zone, &in_zone, margin) } else { in_zone };
        let accepted: Vec<bool> = triangles
            .iter()
            .enumerate()
            .map(|(t, tri)| labels[t] == zone || tri.iter().all(|&v| near[v as usize]))
            .collect();
        let mut vertex_accepted = vec![false; vertices.len()];
        let mut edge_accepted = HashSet::new();
        for (tri, &ok) in triangles.iter().zip(&accepted) {
            if ok {
                for k in 0..3 {
                    vertex_accepted[tri[k] as usize] = true;
                    edge_accepted.insert(edge_key(tri[k], tri[(k + 1) % 3]));
                }
            }
        }
        Ok(ZoneRegion { zone, margin, accepted, triangles: triangles.to_vec(), vertex_accepted, edge_accepted, core })
    }

    /// The zone's label.
    #[must_use]
    pub fn zone(&self) -> u32 {
        self.zone
    }

    /// The dilation margin (mm, XY).
    #[must_use]
    pub fn margin(&self) -> f64 {
        self.margin
    }

    /// Triangles carrying the zone's label.
    #[must_use]
    pub fn zone_triangles(&self) -> usize {
        self.core
    }

    /// Triangles of the dilated zone.
    #[must_use]
    pub fn accepted_triangles(&self) -> usize {
        self.accepted.iter().filter(|&&a| a).count()
    }

    /// Whether mesh triangle `triangle` lies in the dilated zone.
    #[must_use]
    pub fn contains_triangle(&self, triangle: usize) -> bool {
        self.accepted.get(triangle).copied().unwrap_or(false)
    }

    /// Whether the contact of `cl` belongs to the dilated zone (see the type's
    /// docs); `slots` maps mesh triangles to index slots.
    pub(crate) fn contains_contact(&self, index: &MeshIndex, slots: &[u32], cl: &ClPoint) -> bool {
        let (triangle, point, vertex) = match cl.contact {
            Contact::Floor => return false,
            Contact::Facet { triangle, .. } => return self.contains_triangle(triangle),
            Contact::Edge { triangle, point } => (triangle, point, false),
            Contact::Vertex { triangle, point } => (triangle, point, true),
        };
        if self.contains_triangle(triangle) {
            return true;
        }
        let (Some(&slot), Some(tri)) = (slots.get(triangle), self.triangles.get(triangle)) else { return false };
        let c = index.corners(slot as usize);
        if vertex {
            let k = nearest_corner(c, &point);
            return self.vertex_accepted[tri[k] as usize];
        }
        // The edge nearest the contact; accepted when the other triangle on it is.
        let k =
            (0..3).min_by(|&a, &b| edge_distance(c, a, &point).total_cmp(&edge_distance(c, b, &point))).unwrap_or(0);
        self.edge_accepted.contains(&edge_key(tri[k], tri[(k + 1) % 3]))
    }
}

fn edge_key(a: u32, b: u32) -> (u32, u32) {
    if a <= b { (a, b) } else { (b, a) }
}

fn nearest_corner(c: &[Point3; 3], p: &Point3) -> usize {
    (0..3).min_by(|&a, &b| (c[a] - p).norm_squared().total_cmp(&(c[b] - p).norm_squared())).unwrap_or(0)
}

fn edge_distance(c: &[Point3; 3], k: usize, p: &Point3) -> f64 {
    let (a, b) = (c[k], c[(k + 1) % 3]);
    let ab = b - a;
    let len2 = ab.norm_squared();
    let s = if len2 > 0.0 { ((p - a).dot(&ab) / len2).clamp(0.0, 1.0) } else { 0.0 };
    (p - (a + ab * s)).norm()
}

/// Vertices within XY distance `margin` of a border vertex of the zone (a
/// vertex of the zone's triangles that also belongs to another triangle), and
/// the zone's own vertices. A uniform XY grid of cell `margin` over the border
/// vertices; each query reads the 3 x 3 cells around it (no output depends on
/// the hash order).
fn near_vertices(
    vertices: &[Point3],
    triangles: &[[u32; 3]],
    labels: &[u32],
    zone: u32,
    in_zone: &[bool],
    margin: f64,
) -> Vec<bool> {
    let mut border = vec![false; vertices.len()];
    for (t, tri) in triangles.iter().enumerate() {
        if labels[t] != zone {
            for &v in tri {
                if in_zone[v as usize] {
                    border[v as usize] = true;
                }
            }
        }
    }
    #[allow(clippy::cast_possible_truncation, reason = "grid cells of a finite mesh")]
    let cell = |p: &Point3| ((p.x / margin).floor() as i64, (p.y / margin).floor() as i64);
    let mut grid: HashMap<(i64, i64), Vec<u32>> = HashMap::new();
    for (v, p) in vertices.iter().enumerate() {
        if border[v] {
            grid.entry(cell(p)).or_default().push(u32::try_from(v).unwrap_or(u32::MAX));
        }
    }
    let m2 = margin * margin;
    vertices
        .iter()
        .enumerate()
        .map(|(v, p)| {
            if in_zone[v] {
                return true;
            }
            let (i, j) = cell(p);
            (i - 1..=i + 1).any(|a| {
                (j - 1..=j + 1).any(|b| {
                    grid.get(&(a, b)).is_some_and(|list| {
                        list.iter().any(|&w| {
                            let q = &vertices[w as usize];
                            (q.x - p.x).powi(2) + (q.y - p.y).powi(2) <= m2
                        })
                    })
                })
            })
        })
        .collect()
}

#[cfg(test)]
#[allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]
mod tests {
    use super::*;
    use crate::geometry::slots_by_original;

    /// Four 1 mm strips along y, labelled 0, 0, 1, 1: triangles `2 i` and `2 i + 1` in strip `i`.
    fn strips() -> (TriMesh, Vec<u32>) {
        let p = |x: f64, y: f64| Point3::new(x, y, 0.0);
        let soup: Vec<[Point3; 3]> = (0..4)
            .flat_map(|i| {
                let x = f64::from(i);
                [[p(x, 0.), p(x + 1., 0.), p(x + 1., 5.)], [p(x, 0.), p(x + 1., 5.), p(x, 5.)]]
            })
            .collect();
        (TriMesh::from_soup(&soup).unwrap().0, vec![0, 0, 0, 0, 1, 1, 1, 1])
    }

    /// Edge and vertex contacts count for the zone when the edge or vertex touches it.
    #[test]
    fn edge_and_vertex_contacts_on_the_border_belong_to_the_zone() {
        let (mesh, labels) = strips();
        let index = MeshIndex::build(&mesh);
        let slots = slots_by_original(&index);
        let region = ZoneRegion::new(&mesh, &labels, 0, 0.0).unwrap();
        let cl = |contact| ClPoint { tip: Point3::new(0.0, 0.0, 0.0), contact };
        let at = |x: f64, y: f64| Point3::new(x, y, 0.0);
        // Triangle 5 = [(2,0), (3,5), (2,5)] of strip 2 (label 1); its edge x = 2 is shared with strip 1.
        let inside = |c| region.contains_contact(&index, &slots, &cl(c));
        assert!(inside(Contact::Edge { triangle: 5, point: at(2.0, 3.0) }));
        assert!(!inside(Contact::Edge { triangle: 5, point: at(2.5, 5.0) })); // its top edge
        assert!(!inside(Contact::Edge { triangle: 4, point: at(2.5, 2.5) })); // the strip's diagonal
        assert!(inside(Contact::Vertex { triangle: 4, point: at(2.0, 0.0) }));
        assert!(!inside(Contact::Vertex { triangle: 4, point: at(3.0, 0.0) }));
        assert!(inside(Contact::Facet { triangle: 1, point: at(0.5, 4.0) }));
        assert!(!inside(Contact::Facet { triangle: 6, point: at(3.5, 1.0) }));
        assert!(!inside(Contact::Floor));
    }

    /// The dilation grows with the margin and never drops a zone triangle.
    #[test]
    fn dilation_is_monotone_in_the_margin() {
        let (mesh, labels) = strips();
        let counts: Vec<usize> = [0.0, 0.5, 1.0, 2.0, 5.0]
            .iter()
            .map(|&m| ZoneRegion::new(&mesh, &labels, 1, m).unwrap().accepted_triangles())
            .collect();
        assert_eq!(counts, vec![4, 4, 6, 8, 8]);
        assert!(matches!(ZoneRegion::new(&mesh, &labels, 7, 1.0), Err(StrategyError::EmptyZone { zone: 7 })));
        assert!(ZoneRegion::new(&mesh, &labels[1..], 0, 1.0).is_err());
        assert!(ZoneRegion::new(&mesh, &labels, 0, -1.0).is_err());
    }
}
