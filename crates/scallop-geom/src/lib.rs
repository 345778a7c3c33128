//! Geometric foundation of scallop: the one linear-algebra type (re-exported
//! `nalgebra`, f64), axis-aligned boxes, tolerances and exact predicates.
//!
//! ```
//! use scallop_geom::{Aabb3, Point3};
//! let b = Aabb3::from_points([Point3::new(0.0, 1.0, 2.0), Point3::new(-1.0, 3.0, 0.5)]).unwrap();
//! assert_eq!(b.min, Point3::new(-1.0, 1.0, 0.5));
//! ```
//!
//! # Invariants
//! - Never performs I/O; never prints.
//! - All lengths are millimetres, all angles radians.
//! - Every numeric threshold of the workspace lives in [`tol`].

pub mod num;
pub mod predicates;
pub mod rng;
pub mod tol;

pub use nalgebra;
pub use tol::{Eps, Tolerances};

/// A point in 3D (mm).
pub type Point3 = nalgebra::Point3<f64>;
/// A vector in 3D (mm).
pub type Vec3 = nalgebra::Vector3<f64>;
/// A point in the XY plane (mm).
pub type Point2 = nalgebra::Point2<f64>;
/// A vector in the XY plane (mm).
pub type Vec2 = nalgebra::Vector2<f64>;

/// Axis-aligned box in 3D. `min <= max` component-wise once built from points.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb3 {
    /// Lowest corner.
    pub min: Point3,
    /// Highest corner.
    pub max: Point3,
}

impl Aabb3 {
    /// The box around `points`, or `None` when there are none.
    ///
    /// ```
    /// # use scallop_geom::Aabb3;
    /// assert!(Aabb3::from_points(std::iter::empty()).is_none());
    /// ```
    pub fn from_points(points: impl IntoIterator<Item = Point3>) -> Option<Self> {
        let mut it = points.into_iter();
        let first = it.next()?;
        let mut b = Aabb3 { min: first, max: first };
        for p in it {
            b.grow(&p);
        }
        Some(b)
    }

    /// Enlarges the box to contain `p`.
    pub fn grow(&mut self, p: &Point3) {
        self.min = self.min.inf(p);
        self.max = self.max.sup(p);
    }

    /// Extent along each axis.
    #[must_use]
    pub fn size(&self) -> Vec3 {
        self.max - self.min
    }

    /// Length of the diagonal.
    #[must_use]
    pub fn diagonal(&self) -> f64 {
        self.size().norm()
    }

    /// The largest absolute value of any coordinate of the box (rounding error scale).
    #[must_use]
    pub fn max_abs_coord(&self) -> f64 {
        self.min.coords.abs().max().max(self.max.coords.abs().max())
    }

    /// Centre of the box.
    #[must_use]
    pub fn center(&self) -> Point3 {
        nalgebra::center(&self.min, &self.max)
    }
}

/// Axis-aligned box in the XY plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb2 {
    /// Lowest corner.
    pub min: Point2,
    /// Highest corner.
    pub max: Point2,
}

impl Aabb2 {
    /// A square of half-size `r` around `c`.
    ///
    /// ```
    /// # use scallop_geom::{Aabb2, Point2};
    /// let b = Aabb2::around(Point2::new(1.0, 1.0), 0.5);
    /// assert!(b.overlaps(&Aabb2::around(Point2::new(2.0, 1.0), 0.5)));
    /// ```
    #[must_use]
    pub fn around(c: Point2, r: f64) -> Self {
        Aabb2 { min: Point2::new(c.x - r, c.y - r), max: Point2::new(c.x + r, c.y + r) }
    }

    /// Closed overlap test.
    #[must_use]
    pub fn overlaps(&self, o: &Aabb2) -> bool {
        self.min.x <= o.max.x && o.min.x <= self.max.x && self.min.y <= o.max.y && o.min.y <= self.max.y
    }

    /// Squared distance from `p` to the box (0 inside).
    #[must_use]
    pub fn distance_squared(&self, p: &Point2) -> f64 {
        let dx = (self.min.x - p.x).max(0.0).max(p.x - self.max.x);
        let dy = (self.min.y - p.y).max(0.0).max(p.y - self.max.y);
        dx * dx + dy * dy
    }
}

/// Asserts that two floats differ by at most an explicit tolerance.
///
/// ```
/// scallop_geom::assert_near!(1.0, 1.0 + 1e-12, 1e-9);
/// ```
#[macro_export]
macro_rules! assert_near {
    ($a:expr, $b:expr, $eps:expr) => {{
        let (a, b, eps): (f64, f64, f64) = ($a, $b, $eps);
        assert!((a - b).abs() <= eps, "assert_near failed: {a} vs {b} (|diff| = {} > {eps})", (a - b).abs());
    }};
}
