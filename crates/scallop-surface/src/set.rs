//! [`SurfaceSet`]: several named patches, and patch measures (area).

use scallop_geom::{Aabb3, Point3};

use crate::closest::{ClosestPoint, subdivide};
use crate::error::{Direction, PatchLabel, SurfaceError};
use crate::patch::Patch;
use crate::tessellate::{Tessellation, tessellate_patches};
use crate::tol;

/// A non-empty list of patches with distinct names, in a fixed order (indices
/// from 0 are used in error messages and in [`Tessellation::cells`]).
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceSet {
    patches: Vec<Patch>,
}

impl SurfaceSet {
    /// A set of `patches`.
    ///
    /// ```
    /// let rubio = scallop_surface::builtin("rubio").unwrap().patches()[0].clone();
    /// let err = scallop_surface::SurfaceSet::new(vec![rubio.clone(), rubio]).unwrap_err();
    /// assert_eq!(err.to_string(), r#"patch #1 "rubio": the name is already used by patch #0"#);
    /// ```
    ///
    /// # Errors
    /// [`SurfaceError::EmptySet`] or [`SurfaceError::DuplicateName`].
    pub fn new(patches: Vec<Patch>) -> Result<SurfaceSet, SurfaceError> {
        if patches.is_empty() {
            return Err(SurfaceError::EmptySet);
        }
        for (index, patch) in patches.iter().enumerate() {
            if let Some(first) = patches[..index].iter().position(|p| p.name() == patch.name()) {
                return Err(SurfaceError::DuplicateName {
                    patch: PatchLabel { index: Some(index), name: patch.name().to_owned() },
                    first,
                });
            }
        }
        Ok(SurfaceSet { patches })
    }

    /// The patches, in order.
    #[must_use]
    pub fn patches(&self) -> &[Patch] {
        &self.patches
    }

    /// The patch called `name`.
    #[must_use]
    pub fn get(&self, name: &str) -> Option<&Patch> {
        self.patches.iter().find(|p| p.name() == name)
    }

    /// Number of patches (at least 1).
    #[must_use]
    pub fn len(&self) -> usize {
        self.patches.len()
    }

    /// Always `false`: a set has at least one patch.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.patches.is_empty()
    }

    /// The patches, consumed.
    #[must_use]
    pub fn into_patches(self) -> Vec<Patch> {
        self.patches
    }

    /// Tessellates every patch within `tolerance` (mm) into one mesh; see
    /// [`Patch::tessellate`]. [`Tessellation::cells`] lists the grid of each patch.
    ///
    /// ```
    /// let set = scallop_surface::builtin("rubio").unwrap();
    /// let t = set.tessellate(0.1).unwrap();
    /// assert_eq!(t.cells.len(), 1);
    /// ```
    ///
    /// # Errors
    /// As [`Patch::tessellate`]; the error names the patch and its index.
    pub fn tessellate(&self, tolerance: f64) -> Result<Tessellation, SurfaceError> {
        tessellate_patches(&self.patches, tolerance)
    }

    /// The nearest point over all patches: the patch index and its
    /// [`Patch::closest_point`] (ties: the lowest index).
    #[must_use]
    pub fn closest_point(&self, query: &Point3) -> (usize, ClosestPoint) {
        let mut best: Option<(usize, ClosestPoint)> = None;
        for (index, patch) in self.patches.iter().enumerate() {
            let c = patch.closest_point(query);
            if best.is_none_or(|(_, b)| c.distance < b.distance) {
                best = Some((index, c));
            }
        }
        // INVARIANT: a set is never empty.
        best.unwrap_or_else(|| (0, self.patches[0].closest_point(query)))
    }

    /// The union of the patches' [`Patch::bounds`].
    #[must_use]
    pub fn bounds(&self) -> Aabb3 {
        let mut boxes = self.patches.iter().map(Patch::bounds);
        // INVARIANT: a set is never empty.
        let mut all = boxes.next().unwrap_or(Aabb3 { min: Point3::origin(), max: Point3::origin() });
        for b in boxes {
            all.grow(&b.min);
            all.grow(&b.max);
        }
        all
    }

    /// Total area of the patches (mm²), see [`Patch::area`].
    #[must_use]
    pub fn area(&self) -> f64 {
        self.patches.iter().map(Patch::area).sum()
    }
}

/// Nodes and weights of the 5-point Gauss-Legendre rule on [-1, 1].
const GAUSS_5: [(f64, f64); 5] = [
    (-0.906_179_845_938_664, 0.236_926_885_056_189_1),
    (-0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (0.0, 0.568_888_888_888_888_9),
    (0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (0.906_179_845_938_664, 0.236_926_885_056_189_1),
];

impl Patch {
    /// Surface area `integral |Su x Sv| du dv` (mm²), by composite 5-point
    /// Gauss-Legendre quadrature on `tol::AREA_SUBDIVISIONS_PER_SPAN` sub-intervals
    /// per knot span and direction (the integrand is smooth inside spans).
    ///
    /// ```
    /// let set = scallop_surface::builtin("choi").unwrap();
    /// let choi = &set.patches()[0];
    /// assert!((choi.area() - 3241.0).abs() < 1.0); // spec finishing.md 14.3
    /// ```
    #[must_use]
    pub fn area(&self) -> f64 {
        let [us, vs] = Direction::BOTH.map(|d| subdivide(&self.span_breaks(d), |_| tol::AREA_SUBDIVISIONS_PER_SPAN));
        let mut total = 0.0;
        for u_pair in us.windows(2) {
            let (u_mid, u_half) = (0.5 * (u_pair[0] + u_pair[1]), 0.5 * (u_pair[1] - u_pair[0]));
            for v_pair in vs.windows(2) {
                let (v_mid, v_half) = (0.5 * (v_pair[0] + v_pair[1]), 0.5 * (v_pair[1] - v_pair[0]));
                let mut cell = 0.0;
                for (xu, wu) in GAUSS_5 {
                    for (xv, wv) in GAUSS_5 {
                        let d = self.derivatives(u_mid + xu * u_half, v_mid + xv * v_half);
                        cell += wu * wv * d.du.cross(&d.dv).norm();
                    }
                }
                total += cell * u_half * v_half;
            }
        }
        total
    }
}
