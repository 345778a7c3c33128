//! Inverse kinematics (spec 3.2-3.4, 3.6): closed forms of the standard families, the
//! generic two-rotary solver (Paden-Kahan subproblem 2), and a Levenberg-Marquardt
//! fallback on the forward model for any chain. Both branches are returned.
//!
//! Generic orientation step (spec 3.2), find `theta1, theta2` with
//! `R(u1, theta1) R(u2, theta2) b = a`:
//! ```text
//! table-table: u1, u2 = part-chain rotaries (bed outwards), b = v = R_w O, a = a0
//! head-head:   u1, u2 = tool-chain rotaries,                b = a0, a = v
//! head-table:  u1 = -u_table (theta1 = q_table), u2 = u_head, b = a0, a = v
//! k12 = u1.u2, n = u1 x u2
//! mu1 = (k12 (u2.b) - u1.a)/(k12^2 - 1),  mu2 = (k12 (u1.a) - u2.b)/(k12^2 - 1)
//! mu3^2 = (|b|^2 - mu1^2 - mu2^2 - 2 mu1 mu2 k12)/|n|^2      (< 0: unreachable)
//! c = mu1 u1 + mu2 u2 +- mu3 n                                (the two branches)
//! theta2 rotates b into c about u2, theta1 rotates c into a about u1
//! ```
//! Position step: `D = F_part(x) - F_tool(t0)` (rotary joints only), then
//! `sum_tool q_i d_i - sum_part q_i d_i = D` (a constant 3x3 solve).

use std::f64::consts::PI;

use scallop_geom::nalgebra::{Matrix3, SMatrix, Unit, UnitQuaternion};
use scallop_geom::{Point3, Vec3};

use crate::chain::{Class, Family, Joints, Kinematics, Pose, Solver, rotate_about, rotate_about_principal};
use crate::desc::AxisKind;
use crate::error::MachineError;
use crate::tol;

/// The two solution branches, named by the sign of the tilt axis's joint value
/// ([`Kinematics::tilt_axis`]); at the pole (tilt 0) both are `Positive`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Branch {
    /// Tilt joint value >= 0.
    Positive,
    /// Tilt joint value < 0.
    Negative,
}

impl Branch {
    /// The branch of a joint value of the tilt axis.
    ///
    /// ```
    /// use scallop_machine::Branch;
    /// assert_eq!(Branch::of_tilt(-0.1), Branch::Negative);
    /// ```
    #[must_use]
    pub fn of_tilt(q_tilt: f64) -> Branch {
        if q_tilt < 0.0 { Branch::Negative } else { Branch::Positive }
    }
}

/// One inverse solution. Rotary values are in `(-pi, pi]`; unwrapping to windings is
/// the planner's job ([`crate::plan`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IkSolution {
    /// Joint values (mm, rad).
    pub joints: Joints,
    /// Branch (sign of the tilt joint).
    pub branch: Branch,
    /// The pose was on the pole: the pole axis was held at the given previous value.
    pub at_pole: bool,
}

/// One or two inverse solutions (two for the analytic solvers; they coincide at the pole).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IkSolutions {
    items: [IkSolution; 2],
    len: usize,
}

impl IkSolutions {
    /// The solutions.
    ///
    /// ```
    /// use scallop_geom::{Point3, Vec3};
    /// use scallop_machine::{Kinematics, Machine, Joints, Pose};
    /// let k = Kinematics::new(&Machine::builtin("mx330").unwrap(), 100.0);
    /// let s = k.ik(&Pose::new(Point3::new(1.0, 2.0, 3.0), Vec3::new(0.0, 0.5, 1.0)), &Joints::zeros()).unwrap();
    /// assert_eq!(s.as_slice().len(), 2);
    /// ```
    #[must_use]
    pub fn as_slice(&self) -> &[IkSolution] {
        &self.items[..self.len]
    }
}

/// The inverse solutions of one pose, the position step of each closed-form branch done
/// on demand ([`Kinematics::ik_lazy`], [`Kinematics::complete`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct LazyIk {
    /// The solutions; the linear joints of a pending one are zero.
    pub(crate) sols: IkSolutions,
    /// Per solution, the `(sin, cos)` of its primary and secondary rotaries while its
    /// linear joints are pending.
    pending: [Option<[(f64, f64); 2]>; 2],
    /// `W0 tip` (closed position step) or the tip (affine position step).
    x_m: Point3,
    tip: Point3,
}

impl LazyIk {
    /// No solutions (a buffer for [`Kinematics::ik_lazy`]).
    pub(crate) fn empty() -> LazyIk {
        let none = IkSolution { joints: Joints::zeros(), branch: Branch::Positive, at_pole: false };
        LazyIk::complete(IkSolutions { items: [none; 2], len: 0 })
    }

    /// Solutions with nothing pending.
    pub(crate) fn complete(sols: IkSolutions) -> LazyIk {
        LazyIk { sols, pending: [None; 2], x_m: Point3::origin(), tip: Point3::origin() }
    }
}

fn normalize_angle(a: f64) -> f64 {
    // `rem_euclid` is `a % 2 pi` (exact, a call to fmod) then `+ 2 pi` for a negative
    // remainder; for |a| < 2 pi the remainder is `a` itself: same value without fmod.
    let r = if a.abs() < 2.0 * PI { if a < 0.0 { a + 2.0 * PI } else { a } } else { a.rem_euclid(2.0 * PI) };
    if r > PI { r - 2.0 * PI } else { r }
}

/// The angle that rotates `from` into `to` about the unit axis `u` (projections on the
/// plane normal to `u`; spec 3.2), and the smaller of the two projected lengths.
fn rotation_angle(u: &Vec3, from: &Vec3, to: &Vec3) -> (f64, f64) {
    let f = from - u * u.dot(from);
    let t = to - u * u.dot(to);
    (u.dot(&f.cross(&t)).atan2(f.dot(&t)), f.norm().min(t.norm()))
}

fn rotate(u: &Vec3, angle: f64, v: &Vec3) -> Vec3 {
    UnitQuaternion::from_axis_angle(&Unit::new_unchecked(*u), angle) * v
}

impl Kinematics {
    /// Both inverse solutions of `pose` (part frame). `hold` gives the previous joints:
    /// on the pole (`rho < pole_eps`) the pole axis keeps `hold`'s value and the other
    /// rotary is solved for it (spec 3.6 rule 1); the numeric solver also starts from it.
    /// Strokes are not checked here ([`crate::plan::select`] does).
    ///
    /// ```
    /// use scallop_geom::{Point3, Vec3};
    /// use scallop_machine::{Kinematics, Machine, Joints, Pose};
    /// let k = Kinematics::new(&Machine::builtin("ucp710").unwrap(), 0.0);
    /// let pose = Pose::new(Point3::new(5.0, -3.0, 10.0), Vec3::new(0.3, -0.2, 0.9));
    /// for s in k.ik(&pose, &Joints::zeros()).unwrap().as_slice() {
    ///     let back = k.fk(&s.joints);
    ///     assert!((back.tip - pose.tip).norm() < 1e-9 && (back.axis - pose.axis).norm() < 1e-9);
    /// }
    /// ```
    ///
    /// # Errors
    /// [`MachineError::Unreachable`] for a tool axis outside the chain's orientation set;
    /// [`MachineError::NoConvergence`] when the numeric solver fails;
    /// [`MachineError::BadInput`] for a zero or non-finite tool axis.
    pub fn ik(&self, pose: &Pose, hold: &Joints) -> Result<IkSolutions, MachineError> {
        let n = pose.axis.norm();
        if !(n.is_finite() && n > 0.0 && pose.tip.coords.iter().all(|c| c.is_finite())) {
            return Err(MachineError::BadInput {
                place: "Kinematics::ik".into(),
                problem: "the pose has a zero or non-finite tool axis or tip".into(),
                fix: "give a finite tip and a non-zero tool axis".into(),
            });
        }
        let pose = Pose { tip: pose.tip, axis: pose.axis / n };
        match self.solver {
            Solver::Closed(f) => {
                let mut lazy = LazyIk::empty();
                self.ik_closed(f, &pose, hold, &mut lazy)?;
                self.complete(&mut lazy, 0);
                self.complete(&mut lazy, 1);
                Ok(lazy.sols)
            }
            Solver::Generic => self.ik_generic(&pose, hold),
            Solver::Numeric => self.ik_numeric_both(&pose, hold),
        }
    }

    /// [`Kinematics::ik`] with the position step of each closed-form branch left to
    /// [`Kinematics::complete`]: the planner drops most candidates on their rotary values
    /// alone. Same solutions, bit for bit, once completed.
    pub(crate) fn ik_lazy(&self, pose: &Pose, hold: &Joints, out: &mut LazyIk) -> Result<(), MachineError> {
        match self.solver {
            Solver::Closed(f) => {
                let n = pose.axis.norm();
                if !(n.is_finite() && n > 0.0 && pose.tip.coords.iter().all(|c| c.is_finite())) {
                    *out = LazyIk::complete(self.ik(pose, hold)?);
                    return Ok(());
                }
                self.ik_closed(f, &Pose { tip: pose.tip, axis: pose.axis / n }, hold, out)
            }
            Solver::Generic | Solver::Numeric => {
                *out = LazyIk::complete(self.ik(pose, hold)?);
                Ok(())
            }
        }
    }

    /// Solves the linear joints of solution `k` of `lazy` if they are still pending.
    pub(crate) fn complete(&self, lazy: &mut LazyIk, k: usize) {
        if let Some([trig_primary, trig_secondary]) = lazy.pending[k].take() {
            let q = &mut lazy.sols.items[k].joints;
            if self.linear_first {
                let mut trig = [(0.0, 1.0); 5];
                trig[self.primary] = trig_primary;
                trig[self.secondary] = trig_secondary;
                self.solve_linear_machine(&lazy.x_m, q, &trig);
            } else {
                self.solve_linear_affine(&lazy.tip, q);
            }
        }
    }

    fn solution(&self, tip: &Point3, theta_primary: f64, theta_secondary: f64, at_pole: bool) -> IkSolution {
        let mut q = Joints::zeros();
        q[self.primary] = normalize_angle(theta_primary);
        q[self.secondary] = normalize_angle(theta_secondary);
        self.solve_linear(tip, &mut q);
        IkSolution { joints: q, branch: Branch::of_tilt(q[self.tilt]), at_pole }
    }

    /// The rotary part of [`Kinematics::solution`] with the rotaries' `(sin, cos)` known
    /// (the closed forms get them from the tool axis's components without evaluating
    /// `sin_cos`); the linear joints are left at zero and the trigonometry is returned for
    /// [`Kinematics::complete`].
    fn rotary_solution(
        &self,
        (theta_primary, trig_primary): (f64, (f64, f64)),
        (theta_secondary, trig_secondary): (f64, (f64, f64)),
    ) -> (IkSolution, [(f64, f64); 2]) {
        let mut q = Joints::zeros();
        q[self.primary] = normalize_angle(theta_primary);
        q[self.secondary] = normalize_angle(theta_secondary);
        (
            IkSolution { joints: q, branch: Branch::of_tilt(q[self.tilt]), at_pole: false },
            [trig_primary, trig_secondary],
        )
    }

    /// Fills the linear joints of `q` (rotaries given) so that the controlled point is at
    /// `tip` (part frame). Linear axes nearer the bed: `D = F_part(x) - F_tool(t0)`,
    /// `q_lin = M^-1 D` (spec 3.2). Otherwise the tip is affine in the linear joints for
    /// fixed rotaries: `P(q_lin) = P(0) + A q_lin`, with A from three forward evaluations.
    pub(crate) fn solve_linear(&self, tip: &Point3, q: &mut Joints) {
        if self.linear_first {
            let mut trig = [(0.0, 1.0); 5];
            for (i, t) in trig.iter_mut().enumerate() {
                if self.machine.axes[i].kind == AxisKind::Rotary {
                    *t = q[i].sin_cos();
                }
            }
            self.solve_linear_machine(&(self.w0 * tip), q, &trig);
        } else {
            self.solve_linear_affine(tip, q);
        }
    }

    /// The closed position step (`linear_first`) with `trig[i] = (sin q_i, cos q_i)` given
    /// for the rotaries and the tip `x` in the machine frame.
    fn solve_linear_machine(&self, x: &Point3, q: &mut Joints, trig: &[(f64, f64); 5]) {
        // The chains' rotaries applied to a point, innermost first, each by Rodrigues'
        // formula (or its principal-axis form) from one sin_cos (no quaternion or
        // isometry composition).
        let rotate = |i: usize, p: Point3| {
            let a = &self.machine.axes[i];
            match self.principal[i] {
                Some((k, sign)) => rotate_about_principal(k, sign, &a.point, trig[i], &p),
                None => rotate_about(&a.direction, &a.point, trig[i], &p),
            }
        };
        let part = self.rotaries_inward.0.iter().fold(*x, |p, &i| rotate(i, p));
        let tool = self.rotaries_inward.1.iter().fold(self.t0, |p, &i| rotate(i, p));
        let lin = self.linear_inverse * (part - tool);
        q[0] = lin[0];
        q[1] = lin[1];
        q[2] = lin[2];
    }

    /// The affine position step (a linear axis carried by a rotary): the tip is affine in
    /// the linear joints for fixed rotaries.
    fn solve_linear_affine(&self, tip: &Point3, q: &mut Joints) {
        q[0] = 0.0;
        q[1] = 0.0;
        q[2] = 0.0;
        let p0 = self.fk(q).tip;
        let mut a = Matrix3::zeros();
        for i in 0..3 {
            let mut qi = *q;
            qi[i] = 1.0;
            a.set_column(i, &(self.fk(&qi).tip - p0));
        }
        // INVARIANT: rigid motions keep the three linear directions independent.
        let lin = a.lu().solve(&(tip - p0)).unwrap_or_else(Vec3::zeros);
        q[0] = lin[0];
        q[1] = lin[1];
        q[2] = lin[2];
    }

    fn ik_closed(&self, family: Family, pose: &Pose, hold: &Joints, out: &mut LazyIk) -> Result<(), MachineError> {
        let v = if self.w0_identity { pose.axis } else { self.w0.rotation * pose.axis };
        // `v` is a unit vector: no overflow, and an underflowing square only makes rho
        // smaller than pole_eps, where hypot would be too (square roots instead of hypot).
        let rho_sq = v.x * v.x + v.y * v.y;
        let rho = rho_sq.sqrt();
        if rho < self.machine.pole_eps {
            *out = LazyIk::complete(self.ik_generic(pose, hold)?);
            return Ok(());
        }
        let sign = |i: usize| {
            let d = &self.machine.axes[i].direction;
            // INVARIANT: family detection checked that d is +-e_x, +-e_y or +-e_z.
            d.x + d.y + d.z
        };
        let (s_tilt, s_pole) = (sign(self.tilt), sign(self.pole));
        let r = (rho_sq + v.z * v.z).sqrt();
        // atan2 is odd in its first argument (exactly: the sign is applied last).
        let tilt_positive = rho.atan2(v.z);
        // The machine-frame tip of the closed position step, shared by both branches.
        let x_m = if self.linear_first && !self.w0_identity { self.w0 * pose.tip } else { pose.tip };
        // gamma = atan2(y, x) with (y, x) of length rho, on the branch k = +1; the branch
        // k = -1 has (-y, -x): its angle is gamma -+ pi (no second atan2; the two agree
        // after `normalize_angle`, which maps -pi and pi to pi), and its sines and cosines
        // are the exact negatives.
        let (y, x) = match family {
            Family::TtAc => (v.x, v.y),
            Family::TtBc => (v.y, -v.x),
            Family::HhCa => (v.x, -v.y),
            Family::HhCb => (v.y, v.x),
            Family::HtBc => (-v.y, v.x),
            Family::HtAc => (-v.x, -v.y),
        };
        let gamma = y.atan2(x);
        let gamma_other = if gamma > 0.0 { gamma - PI } else { gamma + PI };
        // The sines and cosines from the same components (no sin_cos of the angles); the
        // branch k = -1 negates the tilt sine and both pole terms (exactly).
        let (tilt_sin, tilt_cos) = (s_tilt * rho / r, v.z / r);
        let (pole_sin, pole_cos) = (s_pole * y / rho, x / rho);
        out.sols.len = 2;
        out.x_m = x_m;
        out.tip = pose.tip;
        for ((slot, trig), k) in out.sols.items.iter_mut().zip(&mut out.pending).zip([1.0, -1.0]) {
            let (tilt, gamma, tilt_trig, pole_trig) = if k > 0.0 {
                (tilt_positive, gamma, (tilt_sin, tilt_cos), (pole_sin, pole_cos))
            } else {
                (-tilt_positive, gamma_other, (-tilt_sin, tilt_cos), (-pole_sin, -pole_cos))
            };
            let (q_tilt, q_pole) = ((s_tilt * tilt, tilt_trig), (s_pole * gamma, pole_trig));
            let (primary, secondary) = if self.tilt == self.primary { (q_tilt, q_pole) } else { (q_pole, q_tilt) };
            let (solution, t) = self.rotary_solution(primary, secondary);
            *slot = solution;
            *trig = Some(t);
        }
        Ok(())
    }

    /// The subproblem-2 vectors `(u1, u2, b, a)` for the class (see the module docs).
    fn subproblem_vectors(&self, v: &Vec3) -> (Vec3, Vec3, Vec3, Vec3) {
        let u1 = self.machine.axes[self.primary].direction;
        let u2 = self.machine.axes[self.secondary].direction;
        match self.class {
            Class::TableTable => (u1, u2, *v, self.a0),
            Class::HeadHead => (u1, u2, self.a0, *v),
            Class::HeadTable => (-u1, u2, self.a0, *v),
        }
    }

    pub(crate) fn ik_generic(&self, pose: &Pose, hold: &Joints) -> Result<IkSolutions, MachineError> {
        let v = self.w0.rotation * pose.axis;
        let (u1, u2, b, a) = self.subproblem_vectors(&v);
        let eps = self.machine.pole_eps;
        // Pole: the tool axis along the axis that cannot change it (spec 3.6).
        let b_perp = (b - u2 * u2.dot(&b)).norm();
        let a_perp = (a - u1 * u1.dot(&a)).norm();
        let pole_secondary = self.pole == self.secondary && b_perp < eps;
        let pole_primary = self.pole == self.primary && a_perp < eps;
        let unreachable = || MachineError::Unreachable { block: None, axis: [pose.axis.x, pose.axis.y, pose.axis.z] };
        if pole_secondary {
            // theta2 is free: hold it, then rotate c = R2 b into a about u1.
            let theta2 = hold[self.secondary];
            let c = rotate(&u2, theta2, &b);
            let (theta1, _) = rotation_angle(&u1, &c, &a);
            if (u1.dot(&c) - u1.dot(&a)).abs() > eps {
                return Err(unreachable());
            }
            let s = self.solution(&pose.tip, theta1, theta2, true);
            return Ok(IkSolutions { items: [s, s], len: 2 });
        }
        if pole_primary {
            // theta1 is free: hold it, then rotate b into R1^T a about u2.
            let theta1 = hold[self.primary];
            let a1 = rotate(&u1, -theta1, &a);
            let (theta2, _) = rotation_angle(&u2, &b, &a1);
            if (u2.dot(&b) - u2.dot(&a1)).abs() > eps {
                return Err(unreachable());
            }
            let s = self.solution(&pose.tip, theta1, theta2, true);
            return Ok(IkSolutions { items: [s, s], len: 2 });
        }
        let k12 = u1.dot(&u2);
        let n = u1.cross(&u2);
        let den = k12 * k12 - 1.0;
        let mu1 = (k12 * u2.dot(&b) - u1.dot(&a)) / den;
        let mu2 = (k12 * u1.dot(&a) - u2.dot(&b)) / den;
        let mu3_sq = (b.norm_squared() - mu1 * mu1 - mu2 * mu2 - 2.0 * mu1 * mu2 * k12) / n.norm_squared();
        if mu3_sq < -tol::SUBPROBLEM_ROUNDING {
            return Err(unreachable());
        }
        let mu3 = mu3_sq.max(0.0).sqrt();
        let mut items = [IkSolution { joints: Joints::zeros(), branch: Branch::Positive, at_pole: false }; 2];
        for (slot, k) in items.iter_mut().zip([1.0, -1.0]) {
            let c = u1 * mu1 + u2 * mu2 + n * (k * mu3);
            let (theta2, _) = rotation_angle(&u2, &b, &c);
            let (theta1, _) = rotation_angle(&u1, &c, &a);
            *slot = self.solution(&pose.tip, theta1, theta2, false);
        }
        if items[1].branch < items[0].branch {
            items.swap(0, 1);
        }
        Ok(IkSolutions { items, len: 2 })
    }

    fn ik_numeric_both(&self, pose: &Pose, hold: &Joints) -> Result<IkSolutions, MachineError> {
        let mut other = *hold;
        other[self.tilt] = -hold[self.tilt];
        other[self.pole] = hold[self.pole] + PI;
        let mut found: Vec<IkSolution> = Vec::with_capacity(2);
        let mut last_err = None;
        for seed in [*hold, other] {
            match self.ik_numeric(pose, &seed) {
                Ok(mut q) => {
                    q[3] = normalize_angle(q[3]);
                    q[4] = normalize_angle(q[4]);
                    let same = found.iter().any(|s| (s.joints - q).amax() < tol::SAME_JOINTS);
                    if !same {
                        let rho = (self.w0.rotation * pose.axis
                            - self.machine.axes[self.pole].direction
                                * (self.w0.rotation * pose.axis).dot(&self.machine.axes[self.pole].direction))
                        .norm();
                        found.push(IkSolution {
                            joints: q,
                            branch: Branch::of_tilt(q[self.tilt]),
                            at_pole: rho < self.machine.pole_eps,
                        });
                    }
                }
                Err(e) => last_err = Some(e),
            }
        }
        match found.as_slice() {
            [] => Err(last_err.unwrap_or(MachineError::NoConvergence { block: None, residual: f64::INFINITY })),
            [s] => Ok(IkSolutions { items: [*s, *s], len: 1 }),
            [s, t, ..] => {
                let (s, t) = if t.branch < s.branch { (*t, *s) } else { (*s, *t) };
                Ok(IkSolutions { items: [s, t], len: 2 })
            }
        }
    }

    /// Numeric inverse for any chain (spec 3.2 fallback), started at `seed`: the tool
    /// axis depends on the rotaries only and the tip is affine in the linear joints once
    /// the rotaries are fixed, so Levenberg-Marquardt runs on the two rotaries against
    /// the residual `O(q) - O` (analytic Jacobian columns `omega x O`), then the linear
    /// joints come from one exact 3x3 solve [DECISION: eliminating the linear joints
    /// avoids the curved valley of the 5-unknown form near the pole]. Accepted only if
    /// the forward kinematics reproduce the pose to 1e-9. Converges to the solution
    /// nearest the seed; rotary values are not reduced modulo 2 pi.
    ///
    /// ```
    /// use scallop_machine::{Kinematics, Machine, Joints};
    /// let k = Kinematics::new(&Machine::builtin("generic-hh-ca").unwrap(), 0.0);
    /// let q = Joints::new(10.0, -20.0, 30.0, 0.4, -0.7);
    /// let sol = k.ik_numeric(&k.fk(&q), &(q + Joints::repeat(0.05))).unwrap();
    /// assert!((sol - q).amax() < 1e-8);
    /// ```
    ///
    /// # Errors
    /// [`MachineError::NoConvergence`] with the final residual.
    pub fn ik_numeric(&self, pose: &Pose, seed: &Joints) -> Result<Joints, MachineError> {
        let rotaries = [self.primary, self.secondary];
        let residual = |q: &Joints| self.fk(q).axis - pose.axis;
        let mut q = *seed;
        let mut r = residual(&q);
        let mut cost = r.norm_squared();
        let mut lambda = tol::NUMERIC_INITIAL_DAMPING;
        for _ in 0..tol::NUMERIC_MAX_ITERATIONS {
            if r.norm() <= tol::NUMERIC_ACCEPT * tol::NUMERIC_ORIENTATION_MARGIN {
                break;
            }
            let jac6 = self.jacobian(&q);
            let o = self.fk(&q).axis;
            let mut jac = SMatrix::<f64, 3, 2>::zeros();
            for (c, &j) in rotaries.iter().enumerate() {
                let omega = Vec3::new(jac6[(0, j)], jac6[(1, j)], jac6[(2, j)]);
                jac.set_column(c, &omega.cross(&o));
            }
            let jtj = jac.transpose() * jac;
            let g = jac.transpose() * r;
            let scale = jtj[(0, 0)].max(jtj[(1, 1)]).max(f64::MIN_POSITIVE);
            let mut improved = false;
            while lambda < tol::NUMERIC_MAX_DAMPING {
                let mut a = jtj;
                for i in 0..2 {
                    a[(i, i)] += lambda * jtj[(i, i)].max(tol::NUMERIC_DIAGONAL_FLOOR * scale);
                }
                let Some(step) = a.cholesky().map(|ch| ch.solve(&(-g))) else {
                    lambda *= tol::NUMERIC_DAMPING_INCREASE;
                    continue;
                };
                let mut candidate = q;
                candidate[rotaries[0]] += step[0];
                candidate[rotaries[1]] += step[1];
                let rc = residual(&candidate);
                let cc = rc.norm_squared();
                if cc < cost {
                    q = candidate;
                    r = rc;
                    cost = cc;
                    lambda = (lambda * tol::NUMERIC_DAMPING_DECREASE).max(tol::NUMERIC_MIN_DAMPING);
                    improved = true;
                    break;
                }
                lambda *= tol::NUMERIC_DAMPING_INCREASE;
            }
            if !improved {
                break;
            }
        }
        self.solve_linear(&pose.tip, &mut q);
        let back = self.fk(&q);
        let (dp, da) = ((back.tip - pose.tip).norm(), (back.axis - pose.axis).norm());
        if dp <= tol::NUMERIC_ACCEPT && da <= tol::NUMERIC_ACCEPT {
            Ok(q)
        } else {
            Err(MachineError::NoConvergence { block: None, residual: dp + da })
        }
    }
}
