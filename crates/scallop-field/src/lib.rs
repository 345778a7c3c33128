//! Scalar fields on voxel grids and their iso-surfaces, for the axial levels of
//! 5-axis roughing by guide curves (Jousselin 2020, PhD thesis, Universite
//! Paris-Saclay, Ch. 2 sections 2.2 and 3.1; docs/guides.md).
//!
//! - [`Surface`]: a triangle mesh with a bounding-volume hierarchy, closest
//!   points and angle-weighted pseudo-normals (the side of a point).
//! - [`Grid`] and [`Field`]: samples stored by blocks; [`distance_field`] computes
//!   the unsigned distance in parallel, exactly in the band up to a cutoff and
//!   not at all in blocks beyond it; [`morph_field`] is Eq. 2.7.
//! - [`iso_surface`]: marching tetrahedra (watertight, no ambiguous case), welded
//!   by grid edge.
//! - [`offset_levels`] (several iso-levels of one field, one side kept) and
//!   [`morph_levels`] (the sheet between the two surfaces) return
//!   [`scallop_mesh::TriMesh`]es.
//!
//! Output does not depend on the thread count: fields are filled block by block
//! with indexed collection, extraction is sequential in cell order.
//! Never performs I/O.
//!
//! ```
//! use scallop_geom::Point3;
//! use scallop_mesh::TriMesh;
//! use scallop_field::{LevelOptions, Surface, offset_levels};
//! let p = |x, y, z| Point3::new(x, y, z);
//! let square = [[p(0., 0., 0.), p(4., 0., 0.), p(4., 4., 0.)], [p(0., 0., 0.), p(4., 4., 0.), p(0., 4., 0.)]];
//! let (mesh, _) = TriMesh::from_soup(&square).unwrap();
//! let levels = offset_levels(&Surface::new(&mesh), &[1.0], &LevelOptions::default()).unwrap();
//! // The sheet above the square (its normals point up) and its rounded rim.
//! assert!(levels[0].vertices().iter().all(|v| v.z > -0.5 && v.z < 1.25));
//! ```

mod field;
mod grid;
mod level;
mod surface;
mod tet;
pub mod tol;

pub use field::{Field, distance_field, morph_field};
pub use grid::Grid;
pub use level::{LevelOptions, Side, morph_levels, offset_levels};
pub use surface::{Closest, Feature, Surface};
pub use tet::{IsoMesh, iso_surface};

use scallop_mesh::MeshError;

/// Why a field or a level could not be made. Each message names the fix.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FieldError {
    /// The voxel size is not a finite positive number.
    #[error("voxel size {voxel} mm is not a finite positive number; give a size such as 0.5 mm")]
    BadVoxel {
        /// The value given.
        voxel: f64,
    },
    /// The grid margin is not finite and non-negative.
    #[error("grid margin {margin} mm is not a finite non-negative number")]
    BadMargin {
        /// The value given.
        margin: f64,
    },
    /// The grid would hold too many samples (memory).
    #[error(
        "the voxel grid needs {samples:.3e} samples, over the limit of {limit}; use a voxel size of at least {min_voxel:.3} mm or raise max_samples"
    )]
    GridTooLarge {
        /// Samples the grid would hold.
        samples: f64,
        /// The limit.
        limit: usize,
        /// The smallest voxel size (mm) that fits the limit.
        min_voxel: f64,
    },
    /// An offset distance is not finite and positive.
    #[error("offset distance {index} is {value} mm; give finite positive distances")]
    BadDistance {
        /// Position in the list.
        index: usize,
        /// The value given.
        value: f64,
    },
    /// Zero morph levels asked for.
    #[error("a morph needs at least one level between the two surfaces")]
    BadMorphCount,
    /// A level has no triangle on the side asked for.
    #[error(
        "level {index} (value {value}) has no triangle on the chosen side: check the surface's orientation (Side::Along is where its normals point) or the offset distance"
    )]
    EmptyLevel {
        /// Level number (0 = first).
        index: usize,
        /// Its offset distance (mm) or morph parameter `m`.
        value: f64,
    },
    /// The extracted mesh failed validation.
    #[error("level mesh: {0}")]
    Mesh(#[from] MeshError),
}
