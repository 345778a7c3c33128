//! Test parts for 5-axis roughing by guide curves (docs/guides.md): the
//! thesis's CAD models (Jousselin 2020, PhD thesis, Universite Paris-Saclay,
//! Ch. 2 section 4, Ch. 4 sections 2 and 3) are not public, so scallop builds
//! look-alikes from parameters:
//!
//! - [`closed_pocket`]: a 100 x 100 x 35 mm block with a closed pocket whose
//!   flanks have drafts and undercuts over a tilted, domed bottom;
//! - [`impeller_channel`]: the channel between two twisted blades over a
//!   revolved hub, open at the inlet and the outlet;
//! - [`fitting_pocket`]: a closed non-convex pocket with two ribs.
//!
//! Each is the volume to remove as a triangle mesh (outward normals), every
//! triangle tagged bottom, flank or top ([`FaceTag`]), with its stock box.
//! Generators are pure and deterministic; [`svg_view`] draws a mesh as a shaded
//! isometric SVG. Never performs I/O.

mod build;
mod fitting;
mod impeller;
mod pocket;
mod svg;

pub use fitting::{FittingParams, fitting_pocket};
pub use impeller::{ImpellerParams, impeller_channel};
pub use pocket::{PocketParams, closed_pocket};
pub use svg::{svg_view, svg_view_with_lines};

use scallop_geom::Aabb3;
use scallop_mesh::{MeshError, TriMesh};

/// The role of a face of the volume to remove (Jousselin 2020, Ch. 2 section 1:
/// bottom S_0 and flanks S_f from the finished part, top S_N from the stock).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FaceTag {
    /// The pocket bottom S_0: not crossable.
    Bottom,
    /// A flank S_f: not crossable.
    Flank,
    /// The top S_N: crossable (stock).
    Top,
}

/// A tagged test part: the volume to remove and its stock.
#[derive(Debug, Clone)]
pub struct TestPart {
    /// The volume to remove, outward normals.
    pub mesh: TriMesh,
    /// One tag per triangle of `mesh`, in order.
    pub tags: Vec<FaceTag>,
    /// The stock box (mm).
    pub stock: Aabb3,
    /// The blank inside the stock box when the stock is not the whole box (a
    /// turned or cast blank: a closed mesh, outward normals); `None` when the
    /// box is the stock.
    pub blank: Option<TriMesh>,
}

impl TestPart {
    /// The triangles carrying one of `tags`, as a mesh of their own.
    ///
    /// # Errors
    /// [`PartError::Mesh`] when no triangle carries those tags.
    pub fn faces(&self, tags: &[FaceTag]) -> Result<TriMesh, PartError> {
        let tris: Vec<[usize; 3]> = self
            .mesh
            .triangles()
            .iter()
            .zip(&self.tags)
            .filter(|(_, t)| tags.contains(t))
            .map(|(t, _)| t.map(|i| i as usize))
            .collect();
        Ok(TriMesh::from_indexed(self.mesh.vertices(), &tris)?.0)
    }
}

/// Why a part could not be generated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PartError {
    /// A parameter out of its range.
    #[error("parameter `{name}` = {value} is out of range: {fix}")]
    BadParameter {
        /// The parameter's field name.
        name: &'static str,
        /// The value given.
        value: f64,
        /// What range it needs.
        fix: &'static str,
    },
    /// The generated mesh lost a triangle (degenerate parameters).
    #[error("the parameters make {lost} degenerate triangles; increase the sizes or the sample counts")]
    Degenerate {
        /// Triangles lost.
        lost: usize,
    },
    /// Mesh validation failed.
    #[error("part mesh: {0}")]
    Mesh(#[from] MeshError),
}

/// Checks that `value` lies in `[lo, hi]`.
fn check(name: &'static str, value: f64, lo: f64, hi: f64, fix: &'static str) -> Result<(), PartError> {
    if value.is_finite() && value >= lo && value <= hi {
        Ok(())
    } else {
        Err(PartError::BadParameter { name, value, fix })
    }
}
