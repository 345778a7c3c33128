//! Generic forward kinematics and the analytic Jacobian (spec 3.1, 3.8): product of
//! exponentials over the two chains, written with axis + point, never Denavit-Hartenberg.
//!
//! ```text
//! rotary joint i:  E_i(q_i): x -> p_i + R(u_i, q_i)(x - p_i)        (u_i, p_i at q = 0)
//! linear joint i:  E_i(q_i): x -> x + q_i d_i
//! T_part = E_1 o E_2 o ...  over chains.part (bed outwards);  T_tool likewise
//! tip_M = T_tool(t0),  a_M = R_tool a0,  P = W0^-1 T_part^-1 tip_M,  O = R_w^T R_part^T a_M
//! ```

use scallop_geom::nalgebra::{Isometry3, Matrix3, SMatrix, SVector, Translation3, Unit, UnitQuaternion};
use scallop_geom::{Point3, Vec3};

use crate::desc::{AxisKind, ChainSide, FamilyChoice, Machine};
use crate::error::MachineError;
use crate::tol;

/// Joint values in the machine's joint order ([`Machine::axis_names`]): mm for linear
/// axes, rad for rotary axes; physical values (NC word = `nc_sign * q`).
pub type Joints = SVector<f64, 5>;

/// The 6x5 Jacobian, rows `[omega; P_dot]` in the part frame (spec 3.8, layout of V.11).
pub type Jacobian6 = SMatrix<f64, 6, 5>;

/// A tool pose in the part frame W: the controlled point and the unit tool axis
/// (pointing from the tip towards the spindle).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// Controlled point (mm).
    pub tip: Point3,
    /// Unit tool axis.
    pub axis: Vec3,
}

impl Pose {
    /// A pose from a tip and a tool axis (normalised here).
    ///
    /// ```
    /// use scallop_geom::{Point3, Vec3};
    /// let p = scallop_machine::Pose::new(Point3::origin(), Vec3::new(0.0, 0.0, 2.0));
    /// assert_eq!(p.axis, Vec3::z());
    /// ```
    #[must_use]
    pub fn new(tip: Point3, axis: Vec3) -> Pose {
        Pose { tip, axis: axis.normalize() }
    }
}

/// Kinematic class of a 5-axis machine (spec 2.1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Class {
    /// Both rotaries carry the part.
    TableTable,
    /// Both rotaries carry the tool.
    HeadHead,
    /// One rotary on each side.
    HeadTable,
}

/// A closed-form family (spec 3.3).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Family {
    /// Table-table, C carried by A.
    TtAc,
    /// Table-table, C carried by B.
    TtBc,
    /// Head-head, A carried by C.
    HhCa,
    /// Head-head, B carried by C.
    HhCb,
    /// B head, C table.
    HtBc,
    /// A head, C table.
    HtAc,
}

/// Which inverse is used.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Solver {
    /// The closed form of a standard family (spec 3.3).
    Closed(Family),
    /// The generic two-rotary solver (Paden-Kahan subproblem 2, spec 3.2): any rotary
    /// directions.
    Generic,
    /// Levenberg-Marquardt on the forward model ([`Kinematics::ik_numeric`]), seeded
    /// with the previous joints; any chain.
    Numeric,
}

/// The kinematics of one machine with one tool length and one part placement:
/// forward, inverse and Jacobian. Cheap to query; build once per setup.
///
/// ```
/// use scallop_machine::{Kinematics, Machine, Joints};
/// let k = Kinematics::new(&Machine::builtin("mx330").unwrap(), 100.0);
/// let pose = k.fk(&Joints::new(0.0, 0.0, 100.0, 0.0, 0.0));
/// assert!(pose.tip.coords.norm() < 1e-12 && (pose.axis.z - 1.0).abs() < 1e-15);
/// ```
#[derive(Clone, Debug)]
pub struct Kinematics {
    pub(crate) machine: Machine,
    /// Controlled point at q = 0 in M: `t0 = g0 - L a0`.
    pub(crate) t0: Point3,
    pub(crate) a0: Vec3,
    pub(crate) w0: Isometry3<f64>,
    pub(crate) class: Class,
    /// Primary rotary (nearer the bed; the table axis for head-table).
    pub(crate) primary: usize,
    /// Secondary rotary (the head axis for head-table).
    pub(crate) secondary: usize,
    /// The rotary that is free at the pole (C).
    pub(crate) pole: usize,
    /// The other rotary (the tilt); its sign names the branch.
    pub(crate) tilt: usize,
    pub(crate) solver: Solver,
    /// Maps `D` (spec 3.2) to the linear joint values.
    pub(crate) linear_inverse: Matrix3<f64>,
    /// Every linear axis is nearer the bed than the rotaries of its chain (closed position step).
    pub(crate) linear_first: bool,
    /// For a tool chain of linear axes and a part chain of rotaries only: the first part
    /// rotary's point `p1` and the constant `K` of the distance bound
    /// `D0 <= |tip_M - p1| + K` of `feed::deviation_bound_relaxed`.
    pub(crate) ball_bound: Option<(Point3, f64)>,
    /// Per joint: `Some((k, sign))` when the direction is exactly `sign e_k` (the closed
    /// forms rotate about it without the general Rodrigues formula).
    pub(crate) principal: [Option<(usize, f64)>; 5],
    /// The part frame W0 is exactly the identity (its transforms are skipped).
    pub(crate) w0_identity: bool,
    /// The rotaries of the part chain and of the tool chain, innermost first (the
    /// closed position step applies them in this order).
    pub(crate) rotaries_inward: (Vec<usize>, Vec<usize>),
    /// Per joint: rotary (else linear).
    pub(crate) rotary: [bool; 5],
}

/// The rotary joints of `chain`, innermost first.
fn rotaries_inward(machine: &Machine, chain: &[usize]) -> Vec<usize> {
    chain.iter().rev().copied().filter(|&i| machine.axes[i].kind == AxisKind::Rotary).collect()
}

/// `Some((k, sign))` when `d` is exactly `sign e_k`.
fn principal_direction(d: &Vec3) -> Option<(usize, f64)> {
    // Exact comparisons on purpose: only an exactly axis-aligned direction (as the
    // closed-form families have) takes the short formula.
    #[allow(clippy::float_cmp, reason = "exactly a unit axis")]
    let k = (0..3).find(|&k| d[k].abs() == 1.0)?;
    #[allow(clippy::float_cmp, reason = "exact zeros")]
    let rest_zero = (0..3).all(|j| j == k || d[j] == 0.0);
    rest_zero.then_some((k, d[k]))
}

/// `p` rotated by the angle with `(s, c)` about the line through `point` along
/// `sign e_k`: [`rotate_about`] for a principal direction, two terms per component.
pub(crate) fn rotate_about_principal(k: usize, sign: f64, point: &Point3, (s, c): (f64, f64), p: &Point3) -> Point3 {
    let v = p - point;
    let s = sign * s;
    let r = match k {
        0 => Vec3::new(v.x, c * v.y - s * v.z, s * v.y + c * v.z),
        1 => Vec3::new(c * v.x + s * v.z, v.y, c * v.z - s * v.x),
        _ => Vec3::new(c * v.x - s * v.y, s * v.x + c * v.y, v.z),
    };
    point + r
}

/// `(p1, K)` of [`Kinematics::ball_bound`]: walking the part chain from the bed, the tip
/// carried back through rotary `k` lies within `|tip - p1| + sum_{j < k} |p_j - p_{j+1}|`
/// of `p_k`, so its distance to line `k + 1` is at most that plus the distance from `p_k`
/// to line `k + 1` (line 1: at most `|tip - p1|`).
fn ball_bound(machine: &Machine) -> Option<(Point3, f64)> {
    let tool_linear = machine.tool_chain.iter().all(|&i| machine.axes[i].kind == AxisKind::Linear);
    let part_rotary = machine.part_chain.iter().all(|&i| machine.axes[i].kind == AxisKind::Rotary);
    let first = *machine.part_chain.first()?;
    if !(tool_linear && part_rotary) {
        return None;
    }
    let (mut k, mut walked) = (0.0f64, 0.0f64);
    for w in machine.part_chain.windows(2) {
        let (a, b) = (&machine.axes[w[0]], &machine.axes[w[1]]);
        let off = a.point - b.point;
        let to_line = (off - b.direction * off.dot(&b.direction)).norm();
        k = k.max(walked + to_line);
        walked += off.norm();
    }
    Some((machine.axes[first].point, k))
}

pub(crate) fn joint_isometry(direction: &Vec3, point: &Point3, kind: AxisKind, q: f64) -> Isometry3<f64> {
    match kind {
        AxisKind::Linear => Isometry3::from_parts(Translation3::from(direction * q), UnitQuaternion::identity()),
        AxisKind::Rotary => {
            let rot = UnitQuaternion::from_axis_angle(&Unit::new_unchecked(*direction), q);
            Isometry3::rotation_wrt_point(rot, *point)
        }
    }
}

/// `joint_isometry(direction, point, kind, q) * p` without building the isometry: a
/// translation, or a rotation about the line by Rodrigues' formula from one `sin_cos`
/// (`direction` is a unit vector). `q -> -q` applies the inverse.
pub(crate) fn joint_apply(direction: &Vec3, point: &Point3, kind: AxisKind, q: f64, p: &Point3) -> Point3 {
    match kind {
        AxisKind::Linear => p + direction * q,
        AxisKind::Rotary => rotate_about(direction, point, q.sin_cos(), p),
    }
}

/// `p` rotated about the line through `point` along the unit `direction` by the angle
/// whose `(sin, cos)` is given (Rodrigues' formula).
pub(crate) fn rotate_about(direction: &Vec3, point: &Point3, (s, c): (f64, f64), p: &Point3) -> Point3 {
    let v = p - point;
    point + v * c + direction.cross(&v) * s + direction * (direction.dot(&v) * (1.0 - c))
}

fn along(v: &Vec3, e: &Vec3) -> Option<f64> {
    if (v - e).norm() < tol::PARALLEL {
        Some(1.0)
    } else if (v + e).norm() < tol::PARALLEL {
        Some(-1.0)
    } else {
        None
    }
}

impl Kinematics {
    /// Kinematics of `machine` with the tool length `tool_length` (gauge point to
    /// controlled point, mm; 0 when the controller applies the length) and the
    /// machine's default part frame. The solver is chosen from `kinematics.family`:
    /// the closed form when the axes fit a standard family, else the generic
    /// two-rotary solver (a family named in the file that does not fit the axes falls
    /// back to it: same solutions, spec test K4). When a linear axis is carried by a
    /// rotary, the orientation step is unchanged and the linear joints come from an
    /// exact affine solve. [`Solver::Numeric`] is only used when asked for.
    ///
    /// ```
    /// use scallop_machine::{Kinematics, Machine, Solver, Family};
    /// let k = Kinematics::new(&Machine::builtin("ucp710").unwrap(), 0.0);
    /// assert_eq!(k.solver(), Solver::Closed(Family::TtAc));
    /// ```
    #[must_use]
    pub fn new(machine: &Machine, tool_length: f64) -> Kinematics {
        let a0 = machine.tool_axis;
        let t0 = machine.gauge_point - a0 * tool_length;
        let (r3, r4) = (3, 4);
        let pos_in = |chain: &[usize], i: usize| chain.iter().position(|j| *j == i);
        let (class, primary, secondary) = match (machine.axes[r3].side, machine.axes[r4].side) {
            (ChainSide::Part, ChainSide::Part) => {
                let first = if pos_in(&machine.part_chain, r3) < pos_in(&machine.part_chain, r4) { r3 } else { r4 };
                (Class::TableTable, first, r3 + r4 - first)
            }
            (ChainSide::Tool, ChainSide::Tool) => {
                let first = if pos_in(&machine.tool_chain, r3) < pos_in(&machine.tool_chain, r4) { r3 } else { r4 };
                (Class::HeadHead, first, r3 + r4 - first)
            }
            (ChainSide::Part, ChainSide::Tool) => (Class::HeadTable, r3, r4),
            (ChainSide::Tool, ChainSide::Part) => (Class::HeadTable, r4, r3),
        };
        let (pole, tilt) = match class {
            Class::TableTable => (secondary, primary),
            Class::HeadHead | Class::HeadTable => (primary, secondary),
        };
        let linear_first = |chain: &[usize]| {
            let first_rotary =
                chain.iter().position(|i| machine.axes[*i].kind == AxisKind::Rotary).unwrap_or(chain.len());
            chain[first_rotary..].iter().all(|i| machine.axes[*i].kind == AxisKind::Rotary)
        };
        let linear_first = linear_first(&machine.part_chain) && linear_first(&machine.tool_chain);
        let family = Self::detect_family(machine, class, primary, secondary);
        let solver = match (machine.family, family) {
            (FamilyChoice::Generic, _) | (_, None) => Solver::Generic,
            (_, Some(f)) => Solver::Closed(f),
        };
        let sigma = |i: usize| if machine.axes[i].side == ChainSide::Tool { 1.0 } else { -1.0 };
        let m = Matrix3::from_columns(&[
            machine.axes[0].direction * sigma(0),
            machine.axes[1].direction * sigma(1),
            machine.axes[2].direction * sigma(2),
        ]);
        // INVARIANT: Machine validation guarantees independent linear directions.
        let linear_inverse = m.try_inverse().unwrap_or_else(Matrix3::zeros);
        Kinematics {
            machine: machine.clone(),
            t0,
            a0,
            w0: machine.part_frame,
            class,
            primary,
            secondary,
            pole,
            tilt,
            solver,
            linear_inverse,
            linear_first,
            ball_bound: ball_bound(machine),
            principal: std::array::from_fn(|i| machine.axes.get(i).and_then(|a| principal_direction(&a.direction))),
            w0_identity: machine.part_frame == Isometry3::identity(),
            rotaries_inward: (
                rotaries_inward(machine, &machine.part_chain),
                rotaries_inward(machine, &machine.tool_chain),
            ),
            rotary: std::array::from_fn(|i| machine.axes.get(i).is_some_and(|a| a.kind == AxisKind::Rotary)),
        }
    }

    fn detect_family(machine: &Machine, class: Class, primary: usize, secondary: usize) -> Option<Family> {
        if along(&machine.tool_axis, &Vec3::z()) != Some(1.0) {
            return None;
        }
        let (ex, ey, ez) = (Vec3::x(), Vec3::y(), Vec3::z());
        let u1 = &machine.axes[primary].direction;
        let u2 = &machine.axes[secondary].direction;
        let detected = match class {
            Class::TableTable if along(u2, &ez).is_some() => {
                if along(u1, &ex).is_some() {
                    Some(Family::TtAc)
                } else if along(u1, &ey).is_some() {
                    Some(Family::TtBc)
                } else {
                    None
                }
            }
            Class::HeadHead | Class::HeadTable if along(u1, &ez).is_some() => {
                let a = along(u2, &ex).is_some();
                let b = along(u2, &ey).is_some();
                match (class, a, b) {
                    (Class::HeadHead, true, _) => Some(Family::HhCa),
                    (Class::HeadHead, _, true) => Some(Family::HhCb),
                    (Class::HeadTable, true, _) => Some(Family::HtAc),
                    (Class::HeadTable, _, true) => Some(Family::HtBc),
                    _ => None,
                }
            }
            _ => None,
        };
        let wanted = match machine.family {
            FamilyChoice::Auto | FamilyChoice::Generic => return detected,
            FamilyChoice::TtAc => Family::TtAc,
            FamilyChoice::TtBc => Family::TtBc,
            FamilyChoice::HhCa => Family::HhCa,
            FamilyChoice::HhCb => Family::HhCb,
            FamilyChoice::HtBc => Family::HtBc,
            FamilyChoice::HtAc => Family::HtAc,
        };
        detected.filter(|d| *d == wanted)
    }

    /// The same kinematics with the part placed by `part_frame` (x_M = W0 x_W) instead
    /// of the machine's default.
    ///
    /// ```
    /// use scallop_geom::nalgebra::{Isometry3, Vector3};
    /// use scallop_machine::{Kinematics, Machine, Joints};
    /// let k = Kinematics::new(&Machine::builtin("ucp710").unwrap(), 0.0)
    ///     .with_part_frame(Isometry3::translation(0.0, 0.0, 10.0));
    /// assert!((k.fk(&Joints::zeros()).tip.z + 10.0).abs() < 1e-12);
    /// ```
    #[must_use]
    pub fn with_part_frame(mut self, part_frame: Isometry3<f64>) -> Kinematics {
        self.w0 = part_frame;
        self.w0_identity = part_frame == Isometry3::identity();
        self
    }

    /// The same kinematics with another inverse solver (for comparisons, spec test K4).
    /// [`Solver::Closed`] is ignored unless it is the detected family.
    ///
    /// ```
    /// use scallop_machine::{Kinematics, Machine, Solver};
    /// let k = Kinematics::new(&Machine::builtin("mx330").unwrap(), 100.0).with_solver(Solver::Generic);
    /// assert_eq!(k.solver(), Solver::Generic);
    /// ```
    #[must_use]
    pub fn with_solver(mut self, solver: Solver) -> Kinematics {
        self.solver = match solver {
            Solver::Numeric => Solver::Numeric,
            Solver::Generic => Solver::Generic,
            Solver::Closed(f) => match Self::detect_family(&self.machine, self.class, self.primary, self.secondary) {
                Some(d) if d == f => Solver::Closed(f),
                _ => self.solver,
            },
        };
        self
    }

    /// The machine.
    ///
    /// ```
    /// # use scallop_machine::{Kinematics, Machine};
    /// let k = Kinematics::new(&Machine::builtin("mx330").unwrap(), 100.0);
    /// assert_eq!(k.machine().axes().len(), 5);
    /// ```
    #[must_use]
    pub fn machine(&self) -> &Machine {
        &self.machine
    }

    /// The inverse solver in use.
    ///
    /// ```
    /// # use scallop_machine::{Kinematics, Machine, Solver, Family};
    /// let k = Kinematics::new(&Machine::builtin("generic-ht-bc").unwrap(), 0.0);
    /// assert_eq!(k.solver(), Solver::Closed(Family::HtBc));
    /// ```
    #[must_use]
    pub fn solver(&self) -> Solver {
        self.solver
    }

    /// The kinematic class.
    ///
    /// ```
    /// # use scallop_machine::{Kinematics, Machine, Class};
    /// let k = Kinematics::new(&Machine::builtin("generic-hh-ca").unwrap(), 0.0);
    /// assert_eq!(k.class(), Class::HeadHead);
    /// ```
    #[must_use]
    pub fn class(&self) -> Class {
        self.class
    }

    /// Index of the rotary that is free at the pole (the C axis of every standard family).
    ///
    /// ```
    /// # use scallop_machine::{Kinematics, Machine};
    /// let k = Kinematics::new(&Machine::builtin("mx330").unwrap(), 100.0);
    /// assert_eq!(k.pole_axis(), 4);
    /// ```
    #[must_use]
    pub fn pole_axis(&self) -> usize {
        self.pole
    }

    /// Index of the tilt rotary (A or B); the sign of its joint value names the branch.
    ///
    /// ```
    /// # use scallop_machine::{Kinematics, Machine};
    /// let k = Kinematics::new(&Machine::builtin("mx330").unwrap(), 100.0);
    /// assert_eq!(k.tilt_axis(), 3);
    /// ```
    #[must_use]
    pub fn tilt_axis(&self) -> usize {
        self.tilt
    }

    /// The part frame W0 in use.
    ///
    /// ```
    /// # use scallop_machine::{Kinematics, Machine};
    /// let k = Kinematics::new(&Machine::builtin("mx330").unwrap(), 100.0);
    /// assert_eq!(k.part_frame(), k.machine().part_frame());
    /// ```
    #[must_use]
    pub fn part_frame(&self) -> &Isometry3<f64> {
        &self.w0
    }

    /// The controlled point at q = 0 in the machine frame (`g0 - L a0`).
    ///
    /// ```
    /// # use scallop_machine::{Kinematics, Machine};
    /// let k = Kinematics::new(&Machine::builtin("mx330").unwrap(), 100.0);
    /// assert_eq!(k.controlled_point_at_home().z, -100.0);
    /// ```
    #[must_use]
    pub fn controlled_point_at_home(&self) -> Point3 {
        self.t0
    }

    pub(crate) fn chain_transform(&self, chain: &[usize], q: &Joints) -> Isometry3<f64> {
        let mut t = Isometry3::identity();
        for &i in chain {
            let a = &self.machine.axes[i];
            t *= joint_isometry(&a.direction, &a.point, a.kind, q[i]);
        }
        t
    }

    /// Forward kinematics: joints -> pose in the part frame (spec 3.1).
    ///
    /// ```
    /// use scallop_machine::{Kinematics, Machine, Joints};
    /// let k = Kinematics::new(&Machine::builtin("mx330").unwrap(), 100.0);
    /// let d = std::f64::consts::PI / 180.0;
    /// let pose = k.fk(&Joints::new(10.0, 20.0, 150.0, -45.0 * d, 30.0 * d)); // X Y Z A C
    /// assert!((pose.tip.x + 51.0867).abs() < 1e-4);
    /// ```
    #[must_use]
    pub fn fk(&self, q: &Joints) -> Pose {
        let t_part = self.chain_transform(&self.machine.part_chain, q);
        let t_tool = self.chain_transform(&self.machine.tool_chain, q);
        let tip_m = t_tool * self.t0;
        let axis_m = t_tool.rotation * self.a0;
        let tip = self.w0.inverse_transform_point(&t_part.inverse_transform_point(&tip_m));
        let axis = self.w0.inverse_transform_vector(&t_part.inverse_transform_vector(&axis_m));
        Pose { tip, axis }
    }

    /// The analytic Jacobian `[omega; P_dot]` (6x5, part frame, columns in joint order,
    /// spec 3.8): `O_dot = omega x O`.
    ///
    /// ```text
    /// rotary j: omega_j = sigma_j R_WM u_j(q),  P_dot_j = sigma_j R_WM (u_j(q) x (tip_M - p_j(q)))
    /// linear j: omega_j = 0,                    P_dot_j = sigma_j R_WM d_j(q)
    /// sigma = +1 on the tool chain, -1 on the part chain; R_WM = R_w^T R_part(q)^T
    /// ```
    ///
    /// ```
    /// use scallop_machine::{Kinematics, Machine, Joints};
    /// let k = Kinematics::new(&Machine::builtin("mx330").unwrap(), 100.0);
    /// let j = k.jacobian(&Joints::new(0.0, 0.0, 100.0, 0.0, 0.0));
    /// assert!((j[(5, 2)] - 1.0).abs() < 1e-15); // dPz/dZ = 1
    /// ```
    #[must_use]
    pub fn jacobian(&self, q: &Joints) -> Jacobian6 {
        let t_part = self.chain_transform(&self.machine.part_chain, q);
        let t_tool = self.chain_transform(&self.machine.tool_chain, q);
        let tip_m = t_tool * self.t0;
        let r_wm = (self.w0.rotation.inverse() * t_part.rotation.inverse()).to_rotation_matrix();
        let mut jac = Jacobian6::zeros();
        for (chain, sigma) in [(&self.machine.part_chain, -1.0), (&self.machine.tool_chain, 1.0)] {
            let mut prefix = Isometry3::identity();
            for &i in chain.iter() {
                let a = &self.machine.axes[i];
                let u = prefix.rotation * a.direction;
                let (omega, p_dot) = match a.kind {
                    AxisKind::Linear => (Vec3::zeros(), u),
                    AxisKind::Rotary => {
                        let p = prefix * a.point;
                        (u, u.cross(&(tip_m - p)))
                    }
                };
                let omega = r_wm * omega * sigma;
                let p_dot = r_wm * p_dot * sigma;
                jac.fixed_view_mut::<3, 1>(0, i).copy_from(&omega);
                jac.fixed_view_mut::<3, 1>(3, i).copy_from(&p_dot);
                prefix *= joint_isometry(&a.direction, &a.point, a.kind, q[i]);
            }
        }
        jac
    }

    /// The 5x5 task Jacobian `J5 = [P_dot rows; e1 . O_dot rows; e2 . O_dot rows]` with
    /// `(e1, e2)` an orthonormal basis perpendicular to the tool axis at `q` (spec 3.8;
    /// the 6x5 Jacobian has no inverse, erratum E7). Returns it with `(e1, e2)`.
    ///
    /// ```
    /// use scallop_machine::{Kinematics, Machine, Joints};
    /// let k = Kinematics::new(&Machine::builtin("mx330").unwrap(), 100.0);
    /// let d = std::f64::consts::PI / 180.0;
    /// let (j5, _, _) = k.task_jacobian(&Joints::new(10.0, 20.0, 150.0, -45.0 * d, 30.0 * d));
    /// assert!((j5.determinant().abs() - 0.707107).abs() < 1e-6); // |sin A|
    /// ```
    #[must_use]
    pub fn task_jacobian(&self, q: &Joints) -> (SMatrix<f64, 5, 5>, Vec3, Vec3) {
        let o = self.fk(q).axis;
        let jac = self.jacobian(q);
        let (e1, e2) = perpendicular_basis(&o);
        let mut j5 = SMatrix::<f64, 5, 5>::zeros();
        for c in 0..5 {
            let omega = Vec3::new(jac[(0, c)], jac[(1, c)], jac[(2, c)]);
            let o_dot = omega.cross(&o);
            j5[(0, c)] = jac[(3, c)];
            j5[(1, c)] = jac[(4, c)];
            j5[(2, c)] = jac[(5, c)];
            j5[(3, c)] = e1.dot(&o_dot);
            j5[(4, c)] = e2.dot(&o_dot);
        }
        (j5, e1, e2)
    }

    /// Joint rates `q_dot = J5^-1 [P_dot; e1 . O_dot; e2 . O_dot]` for a tip velocity and a
    /// tool-axis rate in the part frame (spec 3.8). Near the pole the rotary rates blow
    /// up as `1/rho`.
    ///
    /// ```
    /// use scallop_geom::Vec3;
    /// use scallop_machine::{Kinematics, Machine, Joints};
    /// let k = Kinematics::new(&Machine::builtin("mx330").unwrap(), 100.0);
    /// let q = Joints::new(10.0, 20.0, 150.0, -0.5, 0.3);
    /// let rates = k.joint_rates(&q, &Vec3::new(1.0, 0.0, 0.0), &Vec3::zeros()).unwrap();
    /// assert!(rates[3].abs() < 1e-12 && rates[4].abs() < 1e-12);
    /// ```
    ///
    /// # Errors
    /// [`MachineError::Unreachable`] when `J5` is singular (exactly at the pole).
    pub fn joint_rates(&self, q: &Joints, tip_velocity: &Vec3, axis_rate: &Vec3) -> Result<Joints, MachineError> {
        let (j5, e1, e2) = self.task_jacobian(q);
        let rhs = SVector::<f64, 5>::new(
            tip_velocity.x,
            tip_velocity.y,
            tip_velocity.z,
            e1.dot(axis_rate),
            e2.dot(axis_rate),
        );
        j5.lu().solve(&rhs).ok_or_else(|| {
            let a = self.fk(q).axis;
            MachineError::Unreachable { block: None, axis: [a.x, a.y, a.z] }
        })
    }

    /// The largest fraction (at most 1) of the given part-frame rates that keeps every
    /// axis within its maximum velocity: `min(1, min_j vmax_j / |q_dot_j|)` (spec 3.8,
    /// the near-pole feed limit).
    ///
    /// ```
    /// use scallop_geom::Vec3;
    /// use scallop_machine::{Kinematics, Machine, Joints};
    /// let k = Kinematics::new(&Machine::builtin("mx330").unwrap(), 100.0);
    /// let s = k.feed_scale(&Joints::new(0.0, 0.0, 100.0, -0.5, 0.0), &Vec3::new(1.0, 0.0, 0.0), &Vec3::zeros()).unwrap();
    /// assert_eq!(s, 1.0);
    /// ```
    ///
    /// # Errors
    /// As [`Kinematics::joint_rates`].
    pub fn feed_scale(&self, q: &Joints, tip_velocity: &Vec3, axis_rate: &Vec3) -> Result<f64, MachineError> {
        let rates = self.joint_rates(q, tip_velocity, axis_rate)?;
        Ok(self
            .machine
            .axes
            .iter()
            .zip(rates.iter())
            .fold(1.0_f64, |s, (a, r)| if r.abs() > 0.0 { s.min(a.dynamics.vmax / r.abs()) } else { s }))
    }
}

/// An orthonormal pair perpendicular to the unit vector `o` (deterministic choice).
pub(crate) fn perpendicular_basis(o: &Vec3) -> (Vec3, Vec3) {
    let helper = if o.x.abs() <= o.y.abs() && o.x.abs() <= o.z.abs() {
        Vec3::x()
    } else if o.y.abs() <= o.z.abs() {
        Vec3::y()
    } else {
        Vec3::z()
    };
    let e1 = (helper - o * o.dot(&helper)).normalize();
    let e2 = o.cross(&e1);
    (e1, e2)
}
