use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

use scallop_geom::{Aabb3, Eps, Point2, Point3, Vec3, predicates::orient2d, tol};

/// Why a set of triangles is not a usable mesh. Each variant names the place
/// (triangle and vertex numbers count from 0 in input order) and the fix.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MeshError {
    /// No triangles at all. Fix: check that the file holds a part, not only a header.
    #[error("the mesh has no triangles")]
    Empty,
    /// Every triangle was degenerate (zero area). Fix: export the part again with real faces.
    #[error("all {count} triangles are degenerate (zero area)")]
    AllDegenerate {
        /// Number of input triangles.
        count: usize,
    },
    /// A coordinate is NaN or infinite. Fix: repair the export; scallop never guesses a value.
    #[error("triangle {triangle}, vertex {vertex}: coordinate is not finite ({value:?})")]
    NonFinite {
        /// Triangle number in input order.
        triangle: usize,
        /// Vertex within the triangle (0..3).
        vertex: usize,
        /// The offending point.
        value: [f64; 3],
    },
    /// An indexed triangle names a vertex that does not exist.
    #[error("triangle {triangle} refers to vertex {index}, but there are only {vertex_count} vertices")]
    IndexOutOfRange {
        /// Triangle number in input order.
        triangle: usize,
        /// The bad index.
        index: usize,
        /// How many vertices there are.
        vertex_count: usize,
    },
    /// A scale factor that is not finite and positive.
    #[error("scale factor {0} is not a finite positive number")]
    BadScale(f64),
}

/// What loading cleaned up or found; travels with the mesh, never an error.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MeshDiagnostics {
    /// Triangles in the input.
    pub input_triangles: usize,
    /// Vertex references in the input (3 per triangle for a soup).
    pub input_vertices: usize,
    /// Vertices after welding.
    pub welded_vertices: usize,
    /// Weld distance used (mm): `tol::REL_WELD` times the model diagonal.
    pub weld_distance: f64,
    /// Triangles dropped because they had zero area (after welding).
    pub degenerate_dropped: usize,
    /// Edges used by one triangle only (open mesh).
    pub boundary_edges: usize,
    /// Edges used by more than two triangles.
    pub non_manifold_edges: usize,
}

/// A validated triangle mesh with f64 coordinates (mm).
#[derive(Debug, Clone)]
pub struct TriMesh {
    vertices: Vec<Point3>,
    triangles: Vec<[u32; 3]>,
    bounds: Aabb3,
}

impl TriMesh {
    /// Builds a mesh from a triangle soup: validates, welds vertices closer than
    /// the model-scaled weld distance and drops degenerate triangles.
    ///
    /// # Errors
    /// [`MeshError::Empty`], [`MeshError::NonFinite`] or [`MeshError::AllDegenerate`].
    pub fn from_soup(soup: &[[Point3; 3]]) -> Result<(TriMesh, MeshDiagnostics), MeshError> {
        let vertices: Vec<Point3> = soup.iter().flatten().copied().collect();
        let triangles: Vec<[usize; 3]> = (0..soup.len()).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
        Self::from_indexed(&vertices, &triangles)
    }

    /// Builds a mesh from vertices and index triples, with the same cleaning
    /// as [`TriMesh::from_soup`].
    ///
    /// # Errors
    /// As [`TriMesh::from_soup`], plus [`MeshError::IndexOutOfRange`].
    pub fn from_indexed(
        vertices: &[Point3],
        triangles: &[[usize; 3]],
    ) -> Result<(TriMesh, MeshDiagnostics), MeshError> {
        if triangles.is_empty() {
            return Err(MeshError::Empty);
        }
        for (t, tri) in triangles.iter().enumerate() {
            for (k, &i) in tri.iter().enumerate() {
                let Some(p) = vertices.get(i) else {
                    return Err(MeshError::IndexOutOfRange { triangle: t, index: i, vertex_count: vertices.len() });
                };
                if !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()) {
                    return Err(MeshError::NonFinite { triangle: t, vertex: k, value: [p.x, p.y, p.z] });
                }
            }
        }
        // INVARIANT: triangles is non-empty and every index was checked above.
        let bounds = Aabb3::from_points(triangles.iter().flatten().map(|&i| vertices[i])).ok_or(MeshError::Empty)?;
        let weld_distance = tol::REL_WELD * bounds.diagonal();
        let (welded, remap) = weld(vertices, weld_distance);

        let mut kept: Vec<[u32; 3]> = Vec::with_capacity(triangles.len());
        let mut degenerate = 0usize;
        for tri in triangles {
            let t = [remap[tri[0]], remap[tri[1]], remap[tri[2]]];
            let pts = t.map(|i| welded[i as usize]);
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || is_collinear(&pts) {
                degenerate += 1;
            } else {
                kept.push(t);
            }
        }
        if kept.is_empty() {
            return Err(MeshError::AllDegenerate { count: triangles.len() });
        }
        // Drop vertices no kept triangle uses, keeping first-use order (deterministic).
        let mut new_index = vec![u32::MAX; welded.len()];
        let mut used = Vec::new();
        for t in &mut kept {
            for i in t.iter_mut() {
                if new_index[*i as usize] == u32::MAX {
                    new_index[*i as usize] = u32::try_from(used.len()).unwrap_or(u32::MAX);
                    used.push(welded[*i as usize]);
                }
                *i = new_index[*i as usize];
            }
        }
        let (boundary_edges, non_manifold_edges) = edge_counts(&kept);
        // INVARIANT: kept is non-empty, so used is too.
        let bounds = Aabb3::from_points(used.iter().copied()).ok_or(MeshError::Empty)?;
        let diag = MeshDiagnostics {
            input_triangles: triangles.len(),
            input_vertices: vertices.len(),
            welded_vertices: used.len(),
            weld_distance,
            degenerate_dropped: degenerate,
            boundary_edges,
            non_manifold_edges,
        };
        Ok((TriMesh { vertices: used, triangles: kept, bounds }, diag))
    }

    /// The vertices (mm).
    #[must_use]
    pub fn vertices(&self) -> &[Point3] {
        &self.vertices
    }

    /// The triangles as vertex index triples.
    #[must_use]
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// The three corners of triangle `i`.
    ///
    /// # Panics
    /// If `i` is out of range (a bug in the caller).
    #[must_use]
    pub fn triangle(&self, i: usize) -> [Point3; 3] {
        self.triangles[i].map(|v| self.vertices[v as usize])
    }

    /// Bounding box.
    #[must_use]
    pub fn bounds(&self) -> Aabb3 {
        self.bounds
    }

    /// Rounding epsilon of this model.
    #[must_use]
    pub fn eps(&self) -> Eps {
        Eps::for_bounds(&self.bounds)
    }

    /// The triangle soup (corners of every triangle).
    #[must_use]
    pub fn soup(&self) -> Vec<[Point3; 3]> {
        (0..self.triangles.len()).map(|i| self.triangle(i)).collect()
    }

    /// A copy scaled by `factor` about the origin (unit conversion).
    ///
    /// # Errors
    /// [`MeshError::BadScale`] when `factor` is not finite and positive.
    pub fn scaled(&self, factor: f64) -> Result<TriMesh, MeshError> {
        if !(factor.is_finite() && factor > 0.0) {
            return Err(MeshError::BadScale(factor));
        }
        Ok(self.mapped(|p| Point3::from(p.coords * factor)))
    }

    /// A copy translated by `offset`.
    #[must_use]
    pub fn translated(&self, offset: &Vec3) -> TriMesh {
        self.mapped(|p| p + offset)
    }

    fn mapped(&self, f: impl Fn(&Point3) -> Point3) -> TriMesh {
        let vertices: Vec<Point3> = self.vertices.iter().map(f).collect();
        let bounds = Aabb3::from_points(vertices.iter().copied()).unwrap_or(self.bounds);
        TriMesh { vertices, triangles: self.triangles.clone(), bounds }
    }

    /// Total surface area (mm²).
    #[must_use]
    pub fn area(&self) -> f64 {
        (0..self.triangles.len())
            .map(|i| {
                let [a, b, c] = self.triangle(i);
                0.5 * (b - a).cross(&(c - a)).norm()
            })
            .sum()
    }
}

/// Exactly collinear in 3D: all three axis projections are collinear.
fn is_collinear(p: &[Point3; 3]) -> bool {
    let xy = |q: &Point3| Point2::new(q.x, q.y);
    let yz = |q: &Point3| Point2::new(q.y, q.z);
    let zx = |q: &Point3| Point2::new(q.z, q.x);
    orient2d(&xy(&p[0]), &xy(&p[1]), &xy(&p[2])) == 0.0
        && orient2d(&yz(&p[0]), &yz(&p[1]), &yz(&p[2])) == 0.0
        && orient2d(&zx(&p[0]), &zx(&p[1]), &zx(&p[2])) == 0.0
}

/// Welds points closer than `dist` (the first point seen becomes the
/// representative, so the result is deterministic). Returns the kept points
/// and, per input point, its representative's index.
fn weld(points: &[Point3], dist: f64) -> (Vec<Point3>, Vec<u32>) {
    // Cells much larger than the weld distance: a point looks into a
    // neighbouring cell only along the axes where it lies within `dist` of a face.
    let cell = if dist > 0.0 { dist * WELD_CELL_FACTOR } else { f64::MIN_POSITIVE };
    let mut grid: FastMap<[i64; 3], Vec<u32>> = FastMap::with_capacity_and_hasher(points.len(), Default::default());
    let mut kept: Vec<Point3> = Vec::new();
    let mut remap = Vec::with_capacity(points.len());
    let d2 = dist * dist;
    for p in points {
        let mut k = [0i64; 3];
        let mut span = [(0i64, 0i64); 3];
        for axis in 0..3 {
            let q = p[axis] / cell;
            let f = q.floor();
            // Saturating float-to-int cast: huge coordinates share a cell, which is still correct.
            #[allow(clippy::cast_possible_truncation)]
            let ki = f as i64;
            k[axis] = ki;
            let lo = i64::from((q - f) * cell < dist);
            let hi = i64::from((f + 1.0 - q) * cell <= dist);
            span[axis] = (-lo, hi);
        }
        let mut found: Option<u32> = None;
        for dx in span[0].0..=span[0].1 {
            for dy in span[1].0..=span[1].1 {
                for dz in span[2].0..=span[2].1 {
                    if let Some(list) = grid.get(&[k[0] + dx, k[1] + dy, k[2] + dz]) {
                        for &i in list {
                            if (kept[i as usize] - p).norm_squared() <= d2 {
                                found = Some(found.map_or(i, |f| f.min(i)));
                            }
                        }
                    }
                }
            }
        }
        let idx = found.unwrap_or_else(|| {
            let i = u32::try_from(kept.len()).unwrap_or(u32::MAX);
            kept.push(*p);
            grid.entry(k).or_default().push(i);
            i
        });
        remap.push(idx);
    }
    (kept, remap)
}

/// Weld grid cell size in weld distances.
const WELD_CELL_FACTOR: f64 = 64.0;

/// A multiply-rotate hasher (the Fx hash of rustc) for integer keys: the
/// keys are our own cell numbers and indices, so no hash flooding can occur,
/// and iteration order never reaches an output.
#[derive(Default)]
struct FxHasher(u64);

impl Hasher for FxHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(u64::from(b));
        }
    }
    fn write_u64(&mut self, v: u64) {
        self.0 = (self.0.rotate_left(5) ^ v).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
    fn write_u32(&mut self, v: u32) {
        self.write_u64(u64::from(v));
    }
    fn write_i64(&mut self, v: i64) {
        self.write_u64(v.cast_unsigned());
    }
    fn write_usize(&mut self, v: usize) {
        self.write_u64(v as u64);
    }
}

type FastMap<K, V> = HashMap<K, V, BuildHasherDefault<FxHasher>>;

fn edge_counts(triangles: &[[u32; 3]]) -> (usize, usize) {
    let mut edges: FastMap<(u32, u32), u32> =
        FastMap::with_capacity_and_hasher(triangles.len() * 3 / 2, Default::default());
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *edges.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let boundary = edges.values().filter(|&&c| c == 1).count();
    let non_manifold = edges.values().filter(|&&c| c > 2).count();
    (boundary, non_manifold)
}

#[cfg(test)]
#[allow(
    clippy::unwrap_used,
    clippy::float_cmp,
    reason = "tests: a panic is the failure report; exact values are intended"
)]
mod tests {
    use super::*;

    fn p(x: f64, y: f64, z: f64) -> Point3 {
        Point3::new(x, y, z)
    }

    #[test]
    fn welds_near_duplicates_and_counts_edges() {
        let e = 1e-12;
        let soup =
            [[p(0., 0., 0.), p(1., 0., 0.), p(0., 1., 0.)], [p(1. + e, 0., 0.), p(1., 1., 0.), p(0., 1. - e, 0.)]];
        let (m, d) = TriMesh::from_soup(&soup).unwrap();
        assert_eq!(m.vertices().len(), 4);
        assert_eq!(d.boundary_edges, 4);
        assert_eq!(d.non_manifold_edges, 0);
    }

    #[test]
    fn rejects_nan_with_place() {
        let soup = [[p(0., 0., 0.), p(1., 0., 0.), p(0., 1., 0.)], [p(0., 0., 0.), p(f64::NAN, 0., 0.), p(0., 1., 0.)]];
        let err = TriMesh::from_soup(&soup).unwrap_err();
        assert!(matches!(err, MeshError::NonFinite { triangle: 1, vertex: 1, .. }), "{err:?}");
    }

    #[test]
    fn rejects_empty_and_all_degenerate() {
        assert_eq!(TriMesh::from_soup(&[]).unwrap_err(), MeshError::Empty);
        let soup = [[p(0., 0., 0.), p(1., 1., 1.), p(2., 2., 2.)]];
        assert_eq!(TriMesh::from_soup(&soup).unwrap_err(), MeshError::AllDegenerate { count: 1 });
    }

    #[test]
    fn index_out_of_range_is_an_error() {
        let v = [p(0., 0., 0.), p(1., 0., 0.), p(0., 1., 0.)];
        let err = TriMesh::from_indexed(&v, &[[0, 1, 3]]).unwrap_err();
        assert_eq!(err, MeshError::IndexOutOfRange { triangle: 0, index: 3, vertex_count: 3 });
    }

    #[test]
    fn scale_rejects_absurd_factors() {
        let (m, _) = TriMesh::from_soup(&[[p(0., 0., 0.), p(1., 0., 0.), p(0., 1., 0.)]]).unwrap();
        assert!(m.scaled(0.0).is_err());
        assert!(m.scaled(f64::NAN).is_err());
        let s = m.scaled(25.4).unwrap();
        scallop_geom::assert_near!(s.area(), 0.5 * 25.4 * 25.4, 1e-9);
    }
}
