//! Tilted work planes for indexed (3+2) operations (spec 3.13): the frame F with
//! `z_f = O`, and its angles in the controllers' conventions; [`SetupFrame`], the frame
//! of a 3+2 setup. Formatting is done by `scallop-post`; the frames are computed here
//! because frames change only in this crate.

use scallop_geom::nalgebra::Rotation3;
use scallop_geom::{Point3, Vec3};

use crate::tol;

/// The tilted-plane rotation `R_f` (columns `x_f, y_f, z_f` in the part frame) for the
/// tool axis `axis`: `z_f = O`, `x_f` = normalised projection of `x_W` on the plane
/// normal to `O` (of `y_W` when `O` is along `x_W`), `y_f = z_f x x_f`.
///
/// ```
/// use scallop_geom::Vec3;
/// let r = scallop_machine::frame::tilted_plane(&Vec3::z());
/// assert!((r.matrix() - scallop_geom::nalgebra::Matrix3::identity()).norm() < 1e-15);
/// ```
#[must_use]
pub fn tilted_plane(axis: &Vec3) -> Rotation3<f64> {
    let z = axis.normalize();
    let project = |v: Vec3| v - z * z.dot(&v);
    let px = project(Vec3::x());
    let x = if px.norm() > tol::PARALLEL { px.normalize() } else { project(Vec3::y()).normalize() };
    let y = z.cross(&x);
    Rotation3::from_basis_unchecked(&[x, y, z])
}

/// Fanuc `G68.2` Euler angles `(I, J, K)` in radians, Z-X-Z about the moving axes:
/// `R_f = Rz(I) Rx(J) Rz(K)`; `J = acos(R33)`, `I = atan2(R13, -R23)`,
/// `K = atan2(R31, R32)`; at `J = 0` only `I + K` is defined and `K = 0` is returned.
///
/// ```
/// use scallop_geom::Vec3;
/// use scallop_machine::frame::{fanuc_g68_2, tilted_plane};
/// let (i, j, _k) = fanuc_g68_2(&tilted_plane(&Vec3::new(0.0, -1.0, 1.0)));
/// assert!((j - std::f64::consts::FRAC_PI_4).abs() < 1e-12 && i.abs() < 1e-12);
/// ```
#[must_use]
pub fn fanuc_g68_2(r: &Rotation3<f64>) -> (f64, f64, f64) {
    let m = r.matrix();
    let j = m[(2, 2)].clamp(-1.0, 1.0).acos();
    if j.sin().abs() <= tol::PARALLEL {
        return (m[(1, 0)].atan2(m[(0, 0)]), j, 0.0);
    }
    (m[(0, 2)].atan2(-m[(1, 2)]), j, m[(2, 0)].atan2(m[(2, 1)]))
}

/// Heidenhain `PLANE SPATIAL` angles `(SPA, SPB, SPC)` in radians: rotations about the
/// fixed X, then Y, then Z, `R_f = Rz(SPC) Ry(SPB) Rx(SPA)`; `SPB = atan2(-R31,
/// sqrt(R11^2 + R21^2))`, `SPA = atan2(R32, R33)`, `SPC = atan2(R21, R11)`.
///
/// ```
/// use scallop_geom::Vec3;
/// use scallop_machine::frame::{plane_spatial, tilted_plane};
/// let (a, b, c) = plane_spatial(&tilted_plane(&Vec3::new(1.0, 0.0, 1.0)));
/// assert!(a.abs() < 1e-12 && (b - std::f64::consts::FRAC_PI_4).abs() < 1e-12 && c.abs() < 1e-12);
/// ```
#[must_use]
pub fn plane_spatial(r: &Rotation3<f64>) -> (f64, f64, f64) {
    let m = r.matrix();
    let b = (-m[(2, 0)]).atan2(m[(0, 0)].hypot(m[(1, 0)]));
    (m[(2, 1)].atan2(m[(2, 2)]), b, m[(1, 0)].atan2(m[(0, 0)]))
}

/// The frame of a 3+2 (indexed) setup: the part frame turned by `rotation` about
/// `centre` into the setup frame, where the tool axis is +Z:
/// `p_setup = c + R (p_part - c)`, and back `p_part = c + R^T (p_setup - c)`.
///
/// ```
/// use scallop_geom::{Point3, Vec3};
/// use scallop_machine::frame::SetupFrame;
/// let f = SetupFrame::tilted_plane(&Vec3::new(0.0, -1.0, 1.0));
/// assert!((f.tool_axis() - Vec3::new(0.0, -1.0, 1.0).normalize()).norm() < 1e-15);
/// let p = Point3::new(1.0, 2.0, 3.0);
/// assert!((f.to_part(&f.to_setup(&p)) - p).norm() < 1e-14);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SetupFrame {
    /// Part frame -> setup frame.
    pub rotation: Rotation3<f64>,
    /// Centre of the rotation (part frame).
    pub centre: Point3,
}

impl SetupFrame {
    /// The setup turned by `rotation` (part frame -> setup frame) about the part origin.
    #[must_use]
    pub fn about_origin(rotation: Rotation3<f64>) -> SetupFrame {
        SetupFrame { rotation, centre: Point3::origin() }
    }

    /// The tilted work plane of the tool axis `axis` ([`tilted_plane`]) at the part origin.
    #[must_use]
    pub fn tilted_plane(axis: &Vec3) -> SetupFrame {
        SetupFrame::about_origin(tilted_plane(axis).inverse())
    }

    /// The tilted-plane rotation `R_f` (columns `x_f, y_f, z_f` in the part frame): the
    /// inverse of `rotation`, what [`fanuc_g68_2`] and [`plane_spatial`] read.
    #[must_use]
    pub fn plane(&self) -> Rotation3<f64> {
        self.rotation.inverse()
    }

    /// The tool axis (+Z of the setup frame) in the part frame.
    #[must_use]
    pub fn tool_axis(&self) -> Vec3 {
        self.rotation.inverse() * Vec3::z()
    }

    /// A part-frame point in the setup frame.
    #[must_use]
    pub fn to_setup(&self, p: &Point3) -> Point3 {
        self.centre + self.rotation * (p - self.centre)
    }

    /// A setup-frame point in the part frame.
    #[must_use]
    pub fn to_part(&self, p: &Point3) -> Point3 {
        self.centre + self.rotation.inverse() * (p - self.centre)
    }
}
