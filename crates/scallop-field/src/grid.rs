//! The voxel grid: samples at `origin + h (i, j, k)`.

use scallop_geom::{Aabb3, Point3, Vec3};

use crate::FieldError;

/// A regular grid of samples (voxel corners) of spacing `h` (mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    origin: Point3,
    h: f64,
    dims: [usize; 3],
}

impl Grid {
    /// The grid that covers `bounds` grown by `margin` on every side, with spacing
    /// `h`, refused when it would hold more than `max_samples` samples.
    ///
    /// # Errors
    /// [`FieldError::BadVoxel`] when `h` is not finite and positive,
    /// [`FieldError::BadMargin`] when `margin` is not finite and non-negative,
    /// [`FieldError::GridTooLarge`] over `max_samples` (it names the smallest voxel
    /// size that fits).
    pub fn around(bounds: &Aabb3, margin: f64, h: f64, max_samples: usize) -> Result<Grid, FieldError> {
        if !(h.is_finite() && h > 0.0) {
            return Err(FieldError::BadVoxel { voxel: h });
        }
        if !(margin.is_finite() && margin >= 0.0) {
            return Err(FieldError::BadMargin { margin });
        }
        let origin = bounds.min - Vec3::repeat(margin);
        let size = bounds.size() + Vec3::repeat(2.0 * margin);
        let counts = [size.x, size.y, size.z].map(|s| (s / h).ceil() + 1.0);
        let samples: f64 = counts.iter().product();
        // usize -> f64: exact for any limit a machine can hold in memory.
        #[allow(clippy::cast_precision_loss, reason = "sample counts far below 2^52")]
        let limit = max_samples as f64;
        if samples.is_nan() || samples > limit {
            let min_voxel = h * (samples / limit).cbrt() * 1.01;
            return Err(FieldError::GridTooLarge { samples, limit: max_samples, min_voxel });
        }
        #[allow(
            clippy::cast_possible_truncation,
            clippy::cast_sign_loss,
            reason = "finite, positive and bounded by max_samples above"
        )]
        let dims = counts.map(|c| c as usize);
        Ok(Grid { origin, h, dims })
    }

    /// Spacing (mm).
    #[must_use]
    pub fn h(&self) -> f64 {
        self.h
    }

    /// Samples per axis.
    #[must_use]
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// The sample of lowest coordinates.
    #[must_use]
    pub fn origin(&self) -> Point3 {
        self.origin
    }

    /// Number of samples.
    #[must_use]
    pub fn samples(&self) -> usize {
        self.dims[0] * self.dims[1] * self.dims[2]
    }

    /// Linear number of sample `(i, j, k)` (x fastest).
    #[must_use]
    pub fn linear(&self, i: usize, j: usize, k: usize) -> usize {
        i + self.dims[0] * (j + self.dims[1] * k)
    }

    /// Position of sample `(i, j, k)`.
    #[must_use]
    pub fn point(&self, i: usize, j: usize, k: usize) -> Point3 {
        #[allow(clippy::cast_precision_loss, reason = "indices far below 2^52")]
        let v = Vec3::new(i as f64, j as f64, k as f64);
        self.origin + v * self.h
    }
}
