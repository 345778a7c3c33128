//! [`Patch`]: a validated rational Bezier or NURBS patch, and its exact evaluation.

use std::borrow::Cow;

use scallop_geom::{Aabb3, Point3, Vec3};

use crate::basis::{BasisDerivatives, bernstein, bspline, find_span};
use crate::error::{Direction, PatchLabel, SurfaceError};
use crate::tol;

/// The rectangular parameter domain `[u0, u1] x [v0, v1]` of a patch (`[0, 1]^2`
/// for Bezier patches, `[knot[p], knot[n]]` per direction for NURBS patches).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Domain {
    /// `[u0, u1]`, `u0 < u1`.
    pub u: [f64; 2],
    /// `[v0, v1]`, `v0 < v1`.
    pub v: [f64; 2],
}

impl Domain {
    /// The unit square `[0, 1]^2` of Bezier patches.
    pub const UNIT: Domain = Domain { u: [0.0, 1.0], v: [0.0, 1.0] };

    /// The interval of one direction.
    #[must_use]
    pub fn interval(&self, direction: Direction) -> [f64; 2] {
        match direction {
            Direction::U => self.u,
            Direction::V => self.v,
        }
    }

    /// `(u, v)` clamped into the domain; NaN is mapped to the lower end.
    ///
    /// ```
    /// use scallop_surface::Domain;
    /// assert_eq!(Domain::UNIT.clamp(1.5, f64::NAN), (1.0, 0.0));
    /// ```
    #[must_use]
    pub fn clamp(&self, u: f64, v: f64) -> (f64, f64) {
        let c = |t: f64, [lo, hi]: [f64; 2]| if t.is_nan() { lo } else { t.clamp(lo, hi) };
        (c(u, self.u), c(v, self.v))
    }

    /// Whether `(u, v)` lies in the closed domain.
    #[must_use]
    pub fn contains(&self, u: f64, v: f64) -> bool {
        (self.u[0]..=self.u[1]).contains(&u) && (self.v[0]..=self.v[1]).contains(&v)
    }

    /// The point at fractions `(s, t)` of the domain: `(u0 + s (u1 - u0), v0 + t (v1 - v0))`.
    #[must_use]
    pub fn lerp(&self, s: f64, t: f64) -> (f64, f64) {
        (self.u[0] + s * (self.u[1] - self.u[0]), self.v[0] + t * (self.v[1] - self.v[0]))
    }

    /// The centre of the domain.
    #[must_use]
    pub fn center(&self) -> (f64, f64) {
        self.lerp(0.5, 0.5)
    }
}

/// The surface point and its partial derivatives up to order 2 at one `(u, v)`,
/// exact up to rounding (rational quotient rule, no finite differences).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceDerivatives {
    /// `S(u, v)`.
    pub point: Point3,
    /// `dS/du`.
    pub du: Vec3,
    /// `dS/dv`.
    pub dv: Vec3,
    /// `d2S/du2`.
    pub duu: Vec3,
    /// `d2S/dudv`.
    pub duv: Vec3,
    /// `d2S/dv2`.
    pub dvv: Vec3,
}

/// A validated parametric patch in mm: a (rational) Bezier patch or a NURBS patch.
///
/// The control net is `P[i][j]`, `i = 0..rows` along u and `j = 0..columns` along v
/// (spec finishing.md 4.1: "index i goes with u, index j with v"). Weights, when
/// present, are one per control point, finite and > 0; without weights the patch is
/// polynomial. Bezier patches have domain `[0, 1]^2` and use Bernstein polynomials
/// directly (no knot search); NURBS patches use Cox-de Boor B-splines with half-open
/// spans, the last knot belonging to the last non-empty span.
#[derive(Clone, Debug, PartialEq)]
pub struct Patch {
    name: String,
    degree: [usize; 2],
    /// `[rows, columns]` of the control net.
    shape: [usize; 2],
    /// Row-major: `control[i * columns + j]`.
    control: Vec<Point3>,
    weights: Option<Vec<f64>>,
    /// `None` for a Bezier patch.
    knots: Option<[Vec<f64>; 2]>,
    domain: Domain,
}

/// Reasons quoted in [`SurfaceError::ControlRows`] and [`SurfaceError::ControlColumns`].
const BEZIER_NET: &str = "a Bezier patch of degree p x q has (p + 1) x (q + 1) control points";
const NURBS_MIN_NET: &str = "a NURBS patch of degree p x q needs at least (p + 1) x (q + 1) control points";
const SAME_ROWS: &str = "every row of the control net has the same length";

impl Patch {
    /// A (rational) Bezier patch of degree `[p, q]` with a `(p + 1) x (q + 1)`
    /// control net given row by row (`control[i][j]`, `i` along u), and optional
    /// weights in the same shape.
    ///
    /// ```
    /// use scallop_geom::Point3;
    /// use scallop_surface::Patch;
    /// let p = |x, y, z| Point3::new(x, y, z);
    /// let flat = Patch::bezier("flat", [1, 1],
    ///     &[vec![p(0., 0., 0.), p(0., 1., 0.)], vec![p(1., 0., 0.), p(1., 1., 0.)]], None).unwrap();
    /// assert_eq!(flat.point(0.5, 0.25), p(0.5, 0.25, 0.0));
    /// ```
    ///
    /// # Errors
    /// [`SurfaceError::DegreeTooLow`], [`SurfaceError::ControlRows`],
    /// [`SurfaceError::ControlColumns`], [`SurfaceError::NonFiniteControlPoint`],
    /// [`SurfaceError::WeightsShape`] or [`SurfaceError::BadWeight`], naming this patch.
    pub fn bezier(
        name: &str,
        degree: [usize; 2],
        control: &[Vec<Point3>],
        weights: Option<&[Vec<f64>]>,
    ) -> Result<Patch, SurfaceError> {
        let label = PatchLabel::named(name);
        check_degrees(&label, degree)?;
        let shape = [degree[0] + 1, degree[1] + 1];
        let control = flatten_control(&label, control, shape, BEZIER_NET)?;
        let weights = flatten_weights(&label, weights, shape)?;
        Ok(Patch { name: name.to_owned(), degree, shape, control, weights, knots: None, domain: Domain::UNIT })
    }

    /// A NURBS patch of degree `[p, q]` with knot vectors `knots = [U, V]`, a control
    /// net of `n_u x n_v` points given row by row (`control[i][j]`, `i` along u) and
    /// optional weights in the same shape. Knots are non-decreasing with
    /// `len(U) = n_u + p + 1`, `len(V) = n_v + q + 1`; they need not be clamped. The
    /// domain is `[U[p], U[n_u]] x [V[q], V[n_v]]`.
    ///
    /// ```
    /// use scallop_geom::Point3;
    /// use scallop_surface::Patch;
    /// let p = |x, y, z| Point3::new(x, y, z);
    /// let control = vec![vec![p(0., 0., 0.), p(0., 1., 0.)], vec![p(1., 0., 1.), p(1., 1., 1.)],
    ///                    vec![p(2., 0., 0.), p(2., 1., 0.)]];
    /// let ridge = Patch::nurbs("ridge", [1, 1], [vec![0., 0., 1., 2., 2.], vec![0., 0., 1., 1.]], &control, None)
    ///     .unwrap();
    /// assert_eq!(ridge.domain().u, [0.0, 2.0]);
    /// assert_eq!(ridge.point(1.0, 0.0), p(1.0, 0.0, 1.0));
    /// ```
    ///
    /// # Errors
    /// As [`Patch::bezier`], plus [`SurfaceError::KnotCount`],
    /// [`SurfaceError::NonFiniteKnot`], [`SurfaceError::KnotsDecreasing`],
    /// [`SurfaceError::KnotMultiplicity`] and [`SurfaceError::EmptyDomain`].
    pub fn nurbs(
        name: &str,
        degree: [usize; 2],
        knots: [Vec<f64>; 2],
        control: &[Vec<Point3>],
        weights: Option<&[Vec<f64>]>,
    ) -> Result<Patch, SurfaceError> {
        let label = PatchLabel::named(name);
        check_degrees(&label, degree)?;
        let rows = control.len();
        if rows < degree[0] + 1 {
            return Err(SurfaceError::ControlRows {
                patch: label,
                found: rows,
                expected: degree[0] + 1,
                reason: NURBS_MIN_NET,
            });
        }
        let columns = control[0].len();
        if columns < degree[1] + 1 {
            return Err(SurfaceError::ControlColumns {
                patch: label,
                row: 0,
                found: columns,
                expected: degree[1] + 1,
                reason: NURBS_MIN_NET,
            });
        }
        let shape = [rows, columns];
        let control = flatten_control(&label, control, shape, SAME_ROWS)?;
        let mut domain = Domain::UNIT;
        for direction in Direction::BOTH {
            let d = direction.index();
            let interval = check_knots(&label, direction, &knots[d], degree[d], shape[d])?;
            match direction {
                Direction::U => domain.u = interval,
                Direction::V => domain.v = interval,
            }
        }
        let weights = flatten_weights(&label, weights, shape)?;
        Ok(Patch { name: name.to_owned(), degree, shape, control, weights, knots: Some(knots), domain })
    }

    /// The patch name.
    #[must_use]
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Degrees `[p, q]` in u and v.
    #[must_use]
    pub fn degree(&self) -> [usize; 2] {
        self.degree
    }

    /// Control-net size `[rows, columns]` (`rows` along u).
    #[must_use]
    pub fn control_shape(&self) -> [usize; 2] {
        self.shape
    }

    /// Control point `P[i][j]`.
    ///
    /// # Panics
    /// If `(i, j)` is outside [`Patch::control_shape`] (a bug in the caller).
    #[must_use]
    pub fn control_point(&self, i: usize, j: usize) -> Point3 {
        assert!(i < self.shape[0] && j < self.shape[1], "control point ({i}, {j}) outside {:?}", self.shape);
        self.control[i * self.shape[1] + j]
    }

    /// All control points, row-major (`[i * columns + j]`).
    #[must_use]
    pub fn control_points(&self) -> &[Point3] {
        &self.control
    }

    /// The weights, row-major like [`Patch::control_points`]; `None` for a polynomial patch.
    #[must_use]
    pub fn weights(&self) -> Option<&[f64]> {
        self.weights.as_deref()
    }

    /// Whether the patch has weights (is rational).
    #[must_use]
    pub fn is_rational(&self) -> bool {
        self.weights.is_some()
    }

    /// Whether this is a Bezier patch (no knot vectors).
    #[must_use]
    pub fn is_bezier(&self) -> bool {
        self.knots.is_none()
    }

    /// The knot vector of a direction; `None` for a Bezier patch.
    #[must_use]
    pub fn knots(&self, direction: Direction) -> Option<&[f64]> {
        self.knots.as_ref().map(|k| k[direction.index()].as_slice())
    }

    /// The knot vector of a direction, with the implicit clamped vector
    /// `[0; p + 1] ++ [1; p + 1]` of Bezier patches.
    pub(crate) fn knot_vector(&self, direction: Direction) -> Cow<'_, [f64]> {
        match &self.knots {
            Some(k) => Cow::Borrowed(&k[direction.index()]),
            None => {
                let p = self.degree[direction.index()];
                let mut k = vec![0.0; p + 1];
                k.extend(std::iter::repeat_n(1.0, p + 1));
                Cow::Owned(k)
            }
        }
    }

    /// The distinct knot values inside the domain, both ends included (the span
    /// boundaries; `[0, 1]` for a Bezier patch).
    #[must_use]
    pub fn span_breaks(&self, direction: Direction) -> Vec<f64> {
        let [lo, hi] = self.domain.interval(direction);
        let mut breaks = vec![lo];
        if let Some(k) = self.knots(direction) {
            for &t in k {
                if t > lo && t < hi && breaks.last().is_some_and(|&b| t > b) {
                    breaks.push(t);
                }
            }
        }
        breaks.push(hi);
        breaks
    }

    /// The parameter domain.
    #[must_use]
    pub fn domain(&self) -> Domain {
        self.domain
    }

    /// A box around all control points. It encloses the surface (convex-hull
    /// property, which holds because weights are positive).
    #[must_use]
    pub fn control_bounds(&self) -> Aabb3 {
        // INVARIANT: a validated patch has at least (1 + 1) x (1 + 1) control points.
        Aabb3::from_points(self.control.iter().copied())
            .unwrap_or(Aabb3 { min: Point3::origin(), max: Point3::origin() })
    }

    fn weight(&self, index: usize) -> f64 {
        self.weights.as_ref().map_or(1.0, |w| w[index])
    }

    fn basis(&self, direction: Direction, t: f64) -> BasisDerivatives {
        let d = direction.index();
        match &self.knots {
            None => bernstein(self.degree[d], t),
            Some(knots) => {
                let knots = &knots[d];
                let span = find_span(knots, self.degree[d], self.shape[d] - 1, t);
                bspline(knots, self.degree[d], span, t)
            }
        }
    }

    /// The surface point `S(u, v)`; `(u, v)` is first clamped into the domain.
    #[must_use]
    pub fn point(&self, u: f64, v: f64) -> Point3 {
        self.derivatives(u, v).point
    }

    /// `S` and its partial derivatives up to order 2 at `(u, v)` (clamped into the
    /// domain; at a knot the derivatives are those of the span to the right, and of
    /// the last span at the domain end).
    ///
    /// With `A(u, v) = sum N_i(u) N_j(v) w_ij P_ij` and `W = sum N_i(u) N_j(v) w_ij`,
    /// `S = A / W` and (quotient rule, The NURBS Book eq. 4.20):
    ///
    /// ```text
    /// Su  = (Au  - Wu S) / W                    Sv  = (Av - Wv S) / W
    /// Suu = (Auu - 2 Wu Su - Wuu S) / W         Svv = (Avv - 2 Wv Sv - Wvv S) / W
    /// Suv = (Auv - Wu Sv - Wv Su - Wuv S) / W
    /// ```
    ///
    /// ```
    /// let set = scallop_surface::builtin("rubio").unwrap();
    /// let rubio = &set.patches()[0];
    /// let d = rubio.derivatives(0.5, 0.5);
    /// assert!(d.du.norm() > 0.0 && d.duu.x.abs() < 1e-9); // x is linear in u
    /// ```
    #[must_use]
    pub fn derivatives(&self, u: f64, v: f64) -> SurfaceDerivatives {
        let (u, v) = self.domain.clamp(u, v);
        let basis_u = self.basis(Direction::U, u);
        let basis_v = self.basis(Direction::V, v);
        let columns = self.shape[1];
        // Homogeneous sums of the derivatives of orders (in u, in v), in this order.
        const ORDERS: [(usize, usize); 6] = [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)];
        let mut a = [Vec3::zeros(); 6];
        let mut w = [0.0; 6];
        let count_u = basis_u.values[0].len();
        let count_v = basis_v.values[0].len();
        for r in 0..count_u {
            let i = basis_u.first + r;
            let mut along_v = [Vec3::zeros(); 3];
            let mut weight_v = [0.0; 3];
            for s in 0..count_v {
                let index = i * columns + basis_v.first + s;
                let weight = self.weight(index);
                let weighted = self.control[index].coords * weight;
                for l in 0..3 {
                    along_v[l] += weighted * basis_v.values[l][s];
                    weight_v[l] += weight * basis_v.values[l][s];
                }
            }
            let n = [basis_u.values[0][r], basis_u.values[1][r], basis_u.values[2][r]];
            for (k, &(du, dv)) in ORDERS.iter().enumerate() {
                a[k] += along_v[dv] * n[du];
                w[k] += weight_v[dv] * n[du];
            }
        }
        if self.weights.is_none() {
            // Polynomial: W = 1 exactly (partition of unity), all its derivatives 0.
            return SurfaceDerivatives {
                point: Point3::from(a[0]),
                du: a[1],
                dv: a[2],
                duu: a[3],
                duv: a[4],
                dvv: a[5],
            };
        }
        let s = a[0] / w[0];
        let su = (a[1] - s * w[1]) / w[0];
        let sv = (a[2] - s * w[2]) / w[0];
        let suu = (a[3] - su * (2.0 * w[1]) - s * w[3]) / w[0];
        let suv = (a[4] - sv * w[1] - su * w[2] - s * w[4]) / w[0];
        let svv = (a[5] - sv * (2.0 * w[2]) - s * w[5]) / w[0];
        SurfaceDerivatives { point: Point3::from(s), du: su, dv: sv, duu: suu, duv: suv, dvv: svv }
    }

    /// The unit normal `Su x Sv / |Su x Sv|` at `(u, v)` (clamped into the domain).
    /// Its orientation follows the parametrisation; callers that need "material
    /// side up" flip it themselves (spec finishing.md 4.2).
    ///
    /// Fallback at degenerate points (a collapsed edge or corner, a pole), where
    /// `|Su x Sv| <= NORMAL_DEGENERATE_REL * (|Su|^2 + |Sv|^2)` (see [`tol`]):
    /// 1. the limit of the normal when approaching the point from inside the domain
    ///    along the diagonal: `N = Su x Sv` vanishes, so its first-order change
    ///    `su * dN/du + sv * dN/dv` is used, with `dN/du = Suu x Sv + Su x Suv`,
    ///    `dN/dv = Suv x Sv + Su x Svv` and `su, sv = +1` (or -1 at the upper end of
    ///    the domain, pointing inside);
    /// 2. if that vanishes too, `Su x Sv` at the first non-degenerate point on the
    ///    segment towards the domain centre, trying steps
    ///    `tol::NORMAL_FALLBACK_FIRST_STEP * 2^k` of the way;
    /// 3. if the whole patch is degenerate there (a curve or a point), `+Z`.
    ///
    /// ```
    /// use scallop_geom::Point3;
    /// use scallop_surface::Patch;
    /// let p = |x, y, z| Point3::new(x, y, z);
    /// // A triangle: the edge u = 0 collapses to the origin.
    /// let tri = Patch::bezier("tri", [1, 1],
    ///     &[vec![p(0., 0., 0.), p(0., 0., 0.)], vec![p(1., 0., 0.), p(1., 1., 0.)]], None).unwrap();
    /// assert_eq!(tri.normal(0.0, 0.5), scallop_geom::Vec3::z());
    /// ```
    #[must_use]
    pub fn normal(&self, u: f64, v: f64) -> Vec3 {
        let (u, v) = self.domain.clamp(u, v);
        let d = self.derivatives(u, v);
        if let Some(n) = regular_normal(&d) {
            return n;
        }
        // 1. First-order limit from inside the domain.
        let sign_u = if u >= self.domain.u[1] { -1.0 } else { 1.0 };
        let sign_v = if v >= self.domain.v[1] { -1.0 } else { 1.0 };
        let change_u = d.duu.cross(&d.dv) + d.du.cross(&d.duv);
        let change_v = d.duv.cross(&d.dv) + d.du.cross(&d.dvv);
        let limit = change_u * sign_u + change_v * sign_v;
        let scale = (d.duu.norm() + 2.0 * d.duv.norm() + d.dvv.norm()) * (d.du.norm() + d.dv.norm());
        let limit_norm = limit.norm();
        if limit_norm > tol::NORMAL_DEGENERATE_REL * scale {
            return limit / limit_norm;
        }
        // 2. The nearest regular point towards the centre.
        let (uc, vc) = self.domain.center();
        let mut fraction = tol::NORMAL_FALLBACK_FIRST_STEP;
        for _ in 0..tol::NORMAL_FALLBACK_STEPS {
            let probe = self.derivatives(u + fraction * (uc - u), v + fraction * (vc - v));
            if let Some(n) = regular_normal(&probe) {
                return n;
            }
            fraction = (2.0 * fraction).min(1.0);
        }
        // 3. A degenerate surface.
        Vec3::z()
    }
}

/// `Su x Sv` normalised, or `None` at a degenerate point.
fn regular_normal(d: &SurfaceDerivatives) -> Option<Vec3> {
    let n = d.du.cross(&d.dv);
    let norm = n.norm();
    let scale = d.du.norm_squared() + d.dv.norm_squared();
    (norm > tol::NORMAL_DEGENERATE_REL * scale && norm.is_finite()).then(|| n / norm)
}

fn check_degrees(label: &PatchLabel, degree: [usize; 2]) -> Result<(), SurfaceError> {
    for direction in Direction::BOTH {
        let d = degree[direction.index()];
        if d < 1 {
            return Err(SurfaceError::DegreeTooLow { patch: label.clone(), direction, degree: d });
        }
        if d > tol::MAX_DEGREE {
            return Err(SurfaceError::DegreeTooHigh {
                patch: label.clone(),
                direction,
                degree: d,
                max: tol::MAX_DEGREE,
            });
        }
    }
    Ok(())
}

/// Checks the net has `shape` and finite points; returns it row-major.
fn flatten_control(
    label: &PatchLabel,
    control: &[Vec<Point3>],
    shape: [usize; 2],
    reason: &'static str,
) -> Result<Vec<Point3>, SurfaceError> {
    if control.len() != shape[0] {
        return Err(SurfaceError::ControlRows {
            patch: label.clone(),
            found: control.len(),
            expected: shape[0],
            reason,
        });
    }
    // The capacity comes from what was given (its rows already checked), never from a
    // degree alone: a huge degree must fail on the shape, not on an allocation.
    let mut flat = Vec::with_capacity(control.iter().map(Vec::len).sum());
    for (i, row) in control.iter().enumerate() {
        if row.len() != shape[1] {
            return Err(SurfaceError::ControlColumns {
                patch: label.clone(),
                row: i,
                found: row.len(),
                expected: shape[1],
                reason,
            });
        }
        for (j, p) in row.iter().enumerate() {
            if !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()) {
                return Err(SurfaceError::NonFiniteControlPoint { patch: label.clone(), i, j, point: [p.x, p.y, p.z] });
            }
            flat.push(*p);
        }
    }
    Ok(flat)
}

/// Checks the weights have `shape` and are finite and positive; returns them row-major.
fn flatten_weights(
    label: &PatchLabel,
    weights: Option<&[Vec<f64>]>,
    shape: [usize; 2],
) -> Result<Option<Vec<f64>>, SurfaceError> {
    let Some(weights) = weights else { return Ok(None) };
    if weights.len() != shape[0] {
        return Err(SurfaceError::WeightsShape {
            patch: label.clone(),
            place: "rows (index i)".to_owned(),
            found: weights.len(),
            expected: shape[0],
        });
    }
    let mut flat = Vec::with_capacity(weights.iter().map(Vec::len).sum());
    for (i, row) in weights.iter().enumerate() {
        if row.len() != shape[1] {
            return Err(SurfaceError::WeightsShape {
                patch: label.clone(),
                place: format!("row i = {i}"),
                found: row.len(),
                expected: shape[1],
            });
        }
        for (j, &w) in row.iter().enumerate() {
            if !(w.is_finite() && w > 0.0) {
                return Err(SurfaceError::BadWeight { patch: label.clone(), i, j, weight: w });
            }
            flat.push(w);
        }
    }
    Ok(Some(flat))
}

/// Checks one knot vector against its degree and control-point count; returns the domain.
fn check_knots(
    label: &PatchLabel,
    direction: Direction,
    knots: &[f64],
    degree: usize,
    control_points: usize,
) -> Result<[f64; 2], SurfaceError> {
    let expected = control_points + degree + 1;
    if knots.len() != expected {
        return Err(SurfaceError::KnotCount {
            patch: label.clone(),
            direction,
            found: knots.len(),
            expected,
            control_points,
            degree,
        });
    }
    for (index, &value) in knots.iter().enumerate() {
        if !value.is_finite() {
            return Err(SurfaceError::NonFiniteKnot { patch: label.clone(), direction, index, value });
        }
        if index > 0 && value < knots[index - 1] {
            return Err(SurfaceError::KnotsDecreasing {
                patch: label.clone(),
                direction,
                index,
                value,
                previous: knots[index - 1],
            });
        }
    }
    let (start, end) = (knots[degree], knots[control_points]);
    if start >= end {
        return Err(SurfaceError::EmptyDomain {
            patch: label.clone(),
            direction,
            start,
            end,
            p: degree,
            n: control_points,
        });
    }
    // Runs of equal knots: at most degree + 1 anywhere, at most degree strictly inside the domain.
    let mut index = 0;
    while index < knots.len() {
        let value = knots[index];
        let multiplicity = knots[index..].iter().take_while(|&&k| k <= value).count();
        let max = if value > start && value < end { degree } else { degree + 1 };
        if multiplicity > max {
            return Err(SurfaceError::KnotMultiplicity {
                patch: label.clone(),
                direction,
                index,
                value,
                multiplicity,
                max,
                degree,
            });
        }
        index += multiplicity;
    }
    Ok([start, end])
}
