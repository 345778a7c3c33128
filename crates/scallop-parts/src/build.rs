//! Building a tagged mesh from rings of vertices.

use scallop_geom::{Aabb3, Point2, Point3, Vec3, predicates::orient2d};
use scallop_mesh::TriMesh;

use crate::{FaceTag, PartError, TestPart};

/// Vertices, triangles and tags under construction.
#[derive(Debug, Default)]
pub(crate) struct Builder {
    pub(crate) vertices: Vec<Point3>,
    triangles: Vec<[usize; 3]>,
    tags: Vec<FaceTag>,
}

impl Builder {
    /// Adds vertices, returning their indices.
    pub(crate) fn ring(&mut self, points: impl IntoIterator<Item = Point3>) -> Vec<usize> {
        points
            .into_iter()
            .map(|p| {
                self.vertices.push(p);
                self.vertices.len() - 1
            })
            .collect()
    }

    fn tri(&mut self, t: [usize; 3], tag: FaceTag) {
        self.triangles.push(t);
        self.tags.push(tag);
    }

    /// Adds a triangle, flipped if its normal points against `hint`.
    pub(crate) fn tri_towards(&mut self, t: [usize; 3], tag: FaceTag, hint: &Vec3) {
        let [a, b, c] = t.map(|i| self.vertices[i]);
        if (b - a).cross(&(c - a)).dot(hint) < 0.0 {
            self.tri([t[0], t[2], t[1]], tag);
        } else {
            self.tri(t, tag);
        }
    }

    /// Quads between two closed rings of equal length: `(a_i, a_i+1, b_i+1)`,
    /// `(a_i, b_i+1, b_i)`, outward when `a` runs counter-clockwise about the
    /// outward direction's axis below `b`. `tag(i)` tags segment `i`.
    pub(crate) fn band(&mut self, a: &[usize], b: &[usize], closed: bool, tag: impl Fn(usize) -> FaceTag) {
        let n = a.len();
        let segments = if closed { n } else { n - 1 };
        for i in 0..segments {
            let j = (i + 1) % n;
            self.tri([a[i], a[j], b[j]], tag(i));
            self.tri([a[i], b[j], b[i]], tag(i));
        }
    }

    /// Quads between two closed rings, each triangle turned towards `hint(centroid)`.
    pub(crate) fn band_towards(&mut self, a: &[usize], b: &[usize], tag: FaceTag, hint: impl Fn(&Point3) -> Vec3) {
        let n = a.len();
        for i in 0..n {
            let j = (i + 1) % n;
            for t in [[a[i], a[j], b[j]], [a[i], b[j], b[i]]] {
                let c = Point3::from(t.iter().map(|&k| self.vertices[k].coords).sum::<Vec3>() / 3.0);
                self.tri_towards(t, tag, &hint(&c));
            }
        }
    }

    /// A planar cap over a simple polygon ring (in XY, any orientation), by ear
    /// clipping with exact orientation tests, normals along `up` (+z or -z).
    pub(crate) fn cap(&mut self, ring: &[usize], tag: FaceTag, up: f64) {
        let pts: Vec<Point2> = ring.iter().map(|&i| Point2::new(self.vertices[i].x, self.vertices[i].y)).collect();
        let area: f64 = (0..pts.len())
            .map(|i| {
                let (p, q) = (pts[i], pts[(i + 1) % pts.len()]);
                p.x * q.y - q.x * p.y
            })
            .sum();
        let mut idx: Vec<usize> = (0..ring.len()).collect();
        if area < 0.0 {
            idx.reverse();
        }
        let hint = Vec3::new(0.0, 0.0, up);
        while idx.len() > 3 {
            let n = idx.len();
            let ear = (0..n).find(|&k| {
                let (a, b, c) = (pts[idx[(k + n - 1) % n]], pts[idx[k]], pts[idx[(k + 1) % n]]);
                orient2d(&a, &b, &c) > 0.0
                    && idx.iter().all(|&m| {
                        let p = pts[m];
                        p == a
                            || p == b
                            || p == c
                            || !(orient2d(&a, &b, &p) >= 0.0
                                && orient2d(&b, &c, &p) >= 0.0
                                && orient2d(&c, &a, &p) >= 0.0)
                    })
            });
            // A simple polygon always has an ear; the fallback keeps the loop finite.
            let k = ear.unwrap_or(0);
            let t = [idx[(k + n - 1) % n], idx[k], idx[(k + 1) % n]].map(|i| ring[i]);
            self.tri_towards(t, tag, &hint);
            idx.remove(k);
        }
        let t = [idx[0], idx[1], idx[2]].map(|i| ring[i]);
        self.tri_towards(t, tag, &hint);
    }

    /// The unit normal of the first triangle tagged `tag` (by winding).
    pub(crate) fn first_normal(&self, tag: FaceTag) -> Option<Vec3> {
        let i = self.tags.iter().position(|&t| t == tag)?;
        let [a, b, c] = self.triangles[i].map(|k| self.vertices[k]);
        Some((b - a).cross(&(c - a)).normalize())
    }

    /// Caps the closed cross-section `ring` of [`crate::ImpellerParams`]'s
    /// layout (`samples = [_, nw, nt]`: `nw` points across the hub, `nt` up
    /// blade b, `nw` back across the tip, `nt` down blade a) by the grid of
    /// `point(w, t)` over `w, t` in `[0, 1]` whose boundary is the ring, each
    /// triangle tagged top and turned towards `side` times its radial
    /// direction from the z axis.
    pub(crate) fn section_cap(
        &mut self,
        ring: &[usize],
        point: impl Fn(f64, f64) -> Point3,
        samples: [usize; 3],
        side: f64,
    ) {
        let [_, nw, nt] = samples;
        #[allow(clippy::cast_precision_loss, reason = "small counts")]
        let grid: Vec<Vec<usize>> = (0..=nt)
            .map(|j| {
                (0..=nw)
                    .map(|i| match (i, j) {
                        (i, 0) if i < nw => ring[i],
                        (i, j) if i == nw && j < nt => ring[nw + j],
                        (i, j) if j == nt && i > 0 => ring[nw + nt + (nw - i)],
                        (0, j) => ring[2 * nw + nt + (nt - j)],
                        (i, j) => self.ring([point(i as f64 / nw as f64, j as f64 / nt as f64)])[0],
                    })
                    .collect()
            })
            .collect();
        for j in 0..nt {
            for i in 0..nw {
                let (a, b, c, d) = (grid[j][i], grid[j][i + 1], grid[j + 1][i + 1], grid[j + 1][i]);
                for t in [[a, b, c], [a, c, d]] {
                    let m = t.iter().map(|&k| self.vertices[k].coords).sum::<Vec3>() / 3.0;
                    let radial = Vec3::new(m.x, m.y, 0.0);
                    self.tri_towards(t, FaceTag::Top, &(radial * side));
                }
            }
        }
    }

    /// A fan from a new centre vertex to a closed ring, normals along `hint`.
    pub(crate) fn fan(&mut self, centre: Point3, ring: &[usize], tag: FaceTag, hint: &Vec3) {
        let c = self.ring([centre])[0];
        for i in 0..ring.len() {
            self.tri_towards([c, ring[i], ring[(i + 1) % ring.len()]], tag, hint);
        }
    }

    /// The validated part; every triangle must survive validation.
    pub(crate) fn finish(self, stock: Aabb3) -> Result<TestPart, PartError> {
        let (mesh, _) = TriMesh::from_indexed(&self.vertices, &self.triangles)?;
        let lost = self.triangles.len() - mesh.triangles().len();
        if lost > 0 {
            return Err(PartError::Degenerate { lost });
        }
        Ok(TestPart { mesh, tags: self.tags, stock, blank: None })
    }
}
