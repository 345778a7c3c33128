//! The fast parallel-planes planner of the specification (finishing.md 6.3 to
//! 6.5, 7, 12.2): passes are the intersections of vertical planes with the
//! **isoparametric network** of a parametric patch, spaced by the worst-point
//! rule, joined in zigzag by straight connections and timed by the jerk-limited
//! stop-to-stop model. This is the black box of the optimisation (issue 8): one
//! evaluation of an 80 x 80 labelling of the Choi surface at the 0.5 mm machining
//! mesh is about 15 to 35 million instructions, a few milliseconds (figures in
//! `docs/benchmarks.md`).
//!
//! Unlike [`scallop_strategy::plan_finishing`] it drops no cutter and writes no toolpath:
//! the passes are **contact** polylines on the network, lengths are measured
//! on them (6.5 \[DECISION\]), and the result is a [`ZonePlan`] with lengths and
//! times.
//!
//! ```
//! use scallop_analysis::{Cutter, MachineLimits};
//! use scallop_network::{Margins, Network, Transitions, ZoneParams, plan_zone, surface_time};
//!
//! let set = scallop_surface::builtin("choi").unwrap();
//! let network = Network::new(&set.patches()[0], 0.5).unwrap();   // 0.5 mm machining mesh
//! let params = ZoneParams {
//!     direction: 0.0,                                  // feed along X
//!     tool: Cutter::Toroidal { radius: 5.0, corner: 2.0 },
//!     scallop_height: 0.01,
//!     margins: Margins::HalfStep,
//!     sharp_corner: 30f64.to_radians(),
//!     machine: MachineLimits::default(),               // V 5 m/min, A 6 m/s^2, J 40 m/s^3
//! };
//! let plan = plan_zone(&network, None, 0, &params).unwrap();
//! assert!(plan.planes.len() > 20);
//! let total = surface_time(&[plan], &Transitions::default(), &params.machine);
//! assert!(total.total_s > 0.0 && total.transitions_s == 0.0);
//! ```
//!
//! # Method
//! - **Network** ([`Network::new`], 6.3 \[DECISION\]): `N_u = max(2, ceil(L_u / step))`
//!   with `L_u` the longest of the u-isolines at `v = 0, 1/4, 1/2, 3/4, 1` (200-segment
//!   polylines), likewise `N_v`; nodes `Q_ab = S(a / N_u, b / N_v)` with their exact unit
//!   normals, globally oriented so that their mean `n_z >= 0` (4.2). Evaluated once;
//!   3+2 orientations ([`Orientation`], 4.5) rotate the stored points and normals.
//! - **PLANE_PASSES** (6.3): the plane `m . P = d`, `m = (-sin t, cos t, 0)`, cuts the
//!   network edges whose node values `g = m . Q - d` change sign; crossing points
//!   (position, `(u, v)` and normal) are linear interpolations along the edge;
//!   marching squares joins them quad by quad, a saddle resolved by the sign at the
//!   quad centre. Only quads whose `[min, max]` of `m . Q` contains `d` are visited:
//!   they are bucketed by their minimum once per zone and direction, and each
//!   plane reads the buckets within the largest quad extent below `d`; curves are
//!   traced from quad to neighbouring quad, so no node is scanned per plane.
//! - **Zones** ([`CellLabels`], [`Zoning`]): a parameter point belongs to the label
//!   of the clustering cell containing it; segments are split at the exact
//!   crossing of the axis-aligned cell boundaries (the boundary point is
//!   inserted) and the passes are the maximal sub-polylines of the zone. Passes
//!   shorter than [`scallop_strategy::tol::MIN_PASS_LENGTH`] are dropped but their vertices
//!   still count for the spacing.
//! - **NEXT_SPACING** (6.4): the minimum over the vertices of the plane's passes of
//!   `sod_i |c_i . m| = sod_i sqrt(1 - (n_i . m)^2)` with `sod_i` the step-over of
//!   5.2 and 5.3 at the vertex's tilt and horizontal feed angle
//!   ([`scallop_analysis::Cutter`]'s Eq. 1.5, evaluated from the normal's
//!   components without trigonometry) and `n_i` the **exact** normal at the
//!   vertex's `(u, v)`: on a network edge one parameter is fixed, so the patch
//!   restricted to that isoline is tabulated once per network row and column and
//!   a crossing costs one degree-`p` Bernstein evaluation (`normals.rs`). The
//!   vertices carry `S_u x S_v` unnormalised; a conservative test without square
//!   root or division (`spacing.rs`, `ToolModel::exceeds`) rules out the
//!   vertices whose spacing is certainly above the plane's minimum so far, and
//!   only the others are normalised and evaluated exactly: the minimum and the
//!   vertex that sets it are those of the eager evaluation, bit for bit.
//! - **Look-ahead** \[DECISION\]: the next plane at `d + Delta` is accepted only if its
//!   own spacing is at least `Delta`; otherwise it moves to `d + Delta'` and is
//!   checked again. Every vertex of both planes of a gap then sees the gap within
//!   its own step-over, which is what the circle model needs where the
//!   effective radius shrinks from one plane to the next (the spec's rule
//!   looks at the current plane only). On a plane it never triggers.
//! - **Sweep** (6.5): [`Margins::HalfStep`] (default \[DECISION\]): the first plane
//!   half its own spacing inside the zone's extent, the last half its spacing
//!   from the far end, so a strip of constant spacing `Delta` and width `W`
//!   gets `ceil(W / Delta)` planes, the analytic count rounded up.
//!   [`Margins::Fixed`] is the spec's PLAN_ZONE with margins (`(0, 0)`: the
//!   spec's default, one pass more on most strips). Zigzag: odd planes run their
//!   passes backwards in reverse order; each pass end joins the next pass start
//!   by a straight 3D connection.
//! - **Time** (7, [`surface_time`]): each pass is cut into chains at sharp
//!   corners (direction change above [`ZoneParams::sharp_corner`]), each chain
//!   and each connection is one stop-to-stop move timed by
//!   [`scallop_analysis::MachineLimits::segment_time`] (full S-curve or the
//!   thesis's three cases); zones in label order joined by the
//!   [`TransitionModel`] (default RetractTraverse, clearance 5 mm, rapid at `V`,
//!   no reorientation time; 7.4, 13).
//!
//! # Invariants
//! - Never performs I/O, never reads clocks; deterministic (no threads, no hashing).
//! - Every pass vertex lies on the network (a node, an edge point or a point of a
//!   segment inside a quad), with `(u, v)` in `[0, 1]^2` (fractions of the patch
//!   domain); its normal for the spacing is the surface's exact normal there.
//! - Adjacent planes `d_k < d_{k+1}` satisfy `d_{k+1} - d_k <= Delta_i` for the
//!   NEXT_SPACING term `Delta_i` of every vertex of both planes.

mod normals;
mod passes;
mod spacing;
mod time;
mod toolpath;
mod zone;

use scallop_analysis::{Cutter, MachineLimits};
use scallop_geom::nalgebra::Matrix3;
use scallop_geom::{Point3, Vec3};
use scallop_surface::Patch;
use serde::{Deserialize, Serialize};

use scallop_strategy::{StrategyError, tol};

pub use time::{SurfaceTime, TransitionModel, Transitions, surface_time};
pub use toolpath::{NetworkToolpath, network_toolpath};
pub use zone::{ZoneWorkspace, plan_zone, plan_zone_with, plan_zones, plane_passes};

/// The isoparametric machining network of a patch (finishing.md 6.3): `(N_u + 1)
/// x (N_v + 1)` nodes `Q_ab = S(a / N_u, b / N_v)` with exact unit normals,
/// optionally rotated into a 3+2 machine frame ([`Network::oriented`]).
///
/// Node `(a, b)` has index `a * (N_v + 1) + b`; its parameters `(a / N_u, b / N_v)`
/// are fractions of the patch domain.
#[derive(Debug, Clone, PartialEq)]
pub struct Network {
    quads_u: usize,
    quads_v: usize,
    points: Vec<Point3>,
    normals: Vec<Vec3>,
    orientation: Option<Orientation>,
    /// The surface, for exact normals at pass vertices.
    patch: Patch,
    edge_normals: Option<normals::EdgeNormals>,
    /// The global orientation sign of the normals (4.2).
    normal_sign: f64,
}

impl Network {
    /// The network of `patch` at machining-mesh step `step_mm` (mm): `N = max(2,
    /// ceil(L / step))` quads per direction, `L` the longest of five isolines
    /// (finishing.md 6.3 \[DECISION\]).
    ///
    /// ```
    /// let set = scallop_surface::builtin("rubio").unwrap();
    /// let n = scallop_network::Network::new(&set.patches()[0], 5.0).unwrap();
    /// let (nu, nv) = n.resolution();
    /// assert!(nu >= 2 && nv >= 2);
    /// ```
    ///
    /// # Errors
    /// [`StrategyError::BadParameter`] (`step_mm`) when the step is not a positive
    /// number or makes more than [`tol::MAX_NETWORK_QUADS`] quads per direction.
    pub fn new(patch: &Patch, step_mm: f64) -> Result<Network, StrategyError> {
        if !(step_mm.is_finite() && step_mm > 0.0) {
            return Err(StrategyError::BadParameter {
                name: "step_mm",
                value: step_mm,
                fix: "give the machining-mesh step in mm, e.g. 0.5",
            });
        }
        let params = |n: usize| (0..=n).map(|k| k as f64 / n as f64).collect::<Vec<f64>>();
        let samples = params(tol::NETWORK_ISOLINE_SEGMENTS);
        let isolines = &tol::NETWORK_ISOLINE_PARAMETERS;
        let polyline = |points: &[Point3]| points.windows(2).map(|w| (w[1] - w[0]).norm()).sum::<f64>();
        // u-isolines: fixed v, row-major nodes a * 5 + b with a along u.
        let (along_u, _) = grid(patch, &samples, isolines, false);
        let (along_v, _) = grid(patch, isolines, &samples, false);
        let count = |along_u_direction: bool| -> Result<usize, StrategyError> {
            let lines = isolines.len();
            let samples_len = samples.len();
            let length = (0..lines)
                .map(|k| {
                    let line: Vec<Point3> = if along_u_direction {
                        (0..samples_len).map(|a| along_u[a * lines + k]).collect()
                    } else {
                        along_v[k * samples_len..(k + 1) * samples_len].to_vec()
                    };
                    polyline(&line)
                })
                .fold(0.0, f64::max);
            let n = (length / step_mm).ceil().max(2.0);
            if n > tol::MAX_NETWORK_QUADS as f64 {
                return Err(StrategyError::BadParameter {
                    name: "step_mm",
                    value: step_mm,
                    fix: "the machining mesh would be too fine for this surface; use a larger step",
                });
            }
            // INVARIANT: 2 <= n <= MAX_NETWORK_QUADS, an integer-valued float.
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
            Ok(n as usize)
        };
        let (nu, nv) = (count(true)?, count(false)?);
        Ok(Network::with_resolution(patch, nu, nv))
    }

    /// The network of `patch` with `quads_u x quads_v` quads (each at least 1).
    #[must_use]
    pub fn with_resolution(patch: &Patch, quads_u: usize, quads_v: usize) -> Network {
        let (nu, nv) = (quads_u.max(1), quads_v.max(1));
        let fractions = |n: usize| (0..=n).map(|k| k as f64 / n as f64).collect::<Vec<f64>>();
        let (points, mut normals) = grid(patch, &fractions(nu), &fractions(nv), true);
        // Global orientation (4.2): the mean n_z is made non-negative.
        let mean_z: f64 = normals.iter().map(|n| n.z).sum();
        let normal_sign = if mean_z < 0.0 { -1.0 } else { 1.0 };
        for n in &mut normals {
            *n *= normal_sign;
        }
        Network {
            quads_u: nu,
            quads_v: nv,
            points,
            normals,
            orientation: None,
            patch: patch.clone(),
            edge_normals: normals::EdgeNormals::new(patch, [nu, nv]),
            normal_sign,
        }
    }

    /// `(N_u, N_v)`: quads along u and v.
    #[must_use]
    pub fn resolution(&self) -> (usize, usize) {
        (self.quads_u, self.quads_v)
    }

    /// Node positions (in the machine frame when oriented), index `a * (N_v + 1) + b`.
    #[must_use]
    pub fn points(&self) -> &[Point3] {
        &self.points
    }

    /// Unit node normals (machine frame when oriented), same indexing.
    #[must_use]
    pub fn normals(&self) -> &[Vec3] {
        &self.normals
    }

    /// The orientation applied, if any.
    #[must_use]
    pub fn orientation(&self) -> Option<&Orientation> {
        self.orientation.as_ref()
    }

    /// The network seen from a 3+2 setup (finishing.md 4.5): points and normals
    /// rotated by `orientation` (about its centre) so that its tool axis becomes
    /// +Z. Orientations do not compose: an oriented network is first brought back
    /// to the part frame.
    #[must_use]
    pub fn oriented(&self, orientation: &Orientation) -> Network {
        let back = |p: &Point3| self.orientation.as_ref().map_or(*p, |o| o.to_part(p));
        let back_n = |n: &Vec3| self.orientation.as_ref().map_or(*n, |o| o.matrix.transpose() * n);
        Network {
            quads_u: self.quads_u,
            quads_v: self.quads_v,
            points: self.points.iter().map(|p| orientation.to_machine(&back(p))).collect(),
            normals: self.normals.iter().map(|n| orientation.matrix * back_n(n)).collect(),
            orientation: Some(*orientation),
            patch: self.patch.clone(),
            edge_normals: self.edge_normals.clone(),
            normal_sign: self.normal_sign,
        }
    }

    /// [`Network::oriented`] for planning `zones` of `zoning` only: the points and
    /// normals of the nodes of those zones' quads are rotated (the same
    /// operations as `oriented`, so the same bits), every other node is NaN. A
    /// 3+2 evaluation orients one network per cluster; rotating only the
    /// cluster's nodes makes that one network's worth of work in all, not K.
    /// Plan only the given zones on the result ([`plan_zone`] reads no node
    /// outside its zone's quads); [`Network::is_accessible`] is false on it.
    #[must_use]
    pub fn oriented_for(&self, orientation: &Orientation, zoning: &Zoning, zones: &[u32]) -> Network {
        let nan = f64::NAN;
        let mut out = Network {
            points: vec![Point3::new(nan, nan, nan); self.points.len()],
            normals: vec![Vec3::new(nan, nan, nan); self.normals.len()],
            ..self.clone()
        };
        self.orient_into(orientation, zoning, zones, &mut out);
        out
    }

    /// [`Network::oriented_for`] into `out`, a clone of this network or the
    /// result of an earlier call (a network of another surface or resolution is
    /// first replaced by a clone): the nodes of `zones` are rotated, the others
    /// keep what they held. One buffer serves the clusters of an evaluation one
    /// after another, without allocating per cluster.
    pub fn orient_into(&self, orientation: &Orientation, zoning: &Zoning, zones: &[u32], out: &mut Network) {
        let same = (out.quads_u, out.quads_v) == (self.quads_u, self.quads_v)
            && out.points.len() == self.points.len()
            && out.normals.len() == self.normals.len()
            && out.normal_sign.to_bits() == self.normal_sign.to_bits()
            && out.patch == self.patch; // the edge normals follow from patch and resolution
        if !same {
            *out = self.clone();
        }
        let back = |p: &Point3| self.orientation.as_ref().map_or(*p, |o| o.to_part(p));
        let back_n = |n: &Vec3| self.orientation.as_ref().map_or(*n, |o| o.matrix.transpose() * n);
        for zone in zones {
            let Ok(k) = zoning.zones.binary_search(zone) else { continue };
            for &[a, b] in &zoning.quads[k] {
                let (a, b) = (a as usize, b as usize);
                for (i, j) in [(a, b), (a + 1, b), (a, b + 1), (a + 1, b + 1)] {
                    let n = self.node(i, j);
                    out.points[n] = orientation.to_machine(&back(&self.points[n]));
                    out.normals[n] = orientation.matrix * back_n(&self.normals[n]);
                }
            }
        }
        out.orientation = Some(*orientation);
    }

    /// Whether every node normal satisfies `n . Z >= 0` in this frame (the 3+2
    /// accessibility constraint 4.1 on the network nodes).
    #[must_use]
    pub fn is_accessible(&self) -> bool {
        self.normals.iter().all(|n| n.z >= 0.0)
    }

    /// Node index of `(a, b)`.
    pub(crate) fn node(&self, a: usize, b: usize) -> usize {
        a * (self.quads_v + 1) + b
    }

    /// The exact unit normal (oriented, in this frame) of `raw` at domain
    /// fractions `(u, v)` (the patch's own normal where `raw` is degenerate).
    #[inline]
    pub(crate) fn unit_normal(&self, raw: &RawNormal, u: f64, v: f64) -> Vec3 {
        let norm = raw.cross.norm();
        let n = if norm > raw.degenerate {
            raw.cross / norm
        } else {
            let (pu, pv) = self.patch.domain().lerp(u, v);
            self.patch.normal(pu, pv)
        } * self.normal_sign;
        self.orientation.as_ref().map_or(n, |o| o.matrix * n)
    }

    /// The direction of [`Network::unit_normal`] (any length, equal to it up to
    /// rounding) without a square root or a division; `None` near the
    /// degenerate test, where the unit normal may be the patch's fallback.
    #[inline]
    pub(crate) fn normal_direction(&self, raw: &RawNormal) -> Option<Vec3> {
        // |cross| > degenerate for certain (the margin dwarfs the rounding of
        // the square root).
        let clear = raw.cross.norm_squared() > raw.degenerate * raw.degenerate * (1.0 + 1e-6);
        if !clear {
            return None;
        }
        let w = raw.cross * self.normal_sign;
        Some(self.orientation.as_ref().map_or(w, |o| o.matrix * w))
    }

    /// Exact normal at domain fractions `(u, v)`.
    pub(crate) fn normal_at(&self, u: f64, v: f64) -> Vec3 {
        self.unit_normal(&self.raw_normal_at(u, v), u, v)
    }

    /// [`Network::normal_at`] before its normalisation.
    pub(crate) fn raw_normal_at(&self, u: f64, v: f64) -> RawNormal {
        match &self.edge_normals {
            Some(e) => RawNormal::new(e.at(u, v)),
            None => {
                let (pu, pv) = self.patch.domain().lerp(u, v);
                let d = self.patch.derivatives(pu, pv);
                RawNormal::new((d.du, d.dv))
            }
        }
    }

    /// The normal on the u-edge row `b` (`v = b / N_v`) at `u`, before its
    /// normalisation.
    #[inline]
    pub(crate) fn raw_normal_on_row(&self, b: usize, u: f64) -> RawNormal {
        match &self.edge_normals {
            Some(e) => RawNormal::new(e.on_row(b, u)),
            None => self.raw_normal_at(u, b as f64 / self.quads_v as f64),
        }
    }

    /// The normal on the v-edge column `a` (`u = a / N_u`) at `v`, before its
    /// normalisation.
    #[inline]
    pub(crate) fn raw_normal_on_column(&self, a: usize, v: f64) -> RawNormal {
        match &self.edge_normals {
            Some(e) => RawNormal::new(e.on_column(a, v)),
            None => self.raw_normal_at(a as f64 / self.quads_u as f64, v),
        }
    }

    /// A point of this frame back in the part frame.
    pub(crate) fn to_part(&self, p: &Point3) -> Point3 {
        self.orientation.as_ref().map_or(*p, |o| o.to_part(p))
    }
}

/// A surface normal before its normalisation: `S_u x S_v` (up to a positive
/// factor) and the bound of its degenerate test. [`Network::unit_normal`]
/// finishes it as an eager evaluation would, bit for bit; the planner finishes
/// only the normals whose spacing it needs (6.4).
#[derive(Debug, Clone, Copy)]
pub(crate) struct RawNormal {
    cross: Vec3,
    /// `NORMAL_DEGENERATE_REL (|S_u|^2 + |S_v|^2)`: a `|cross|` at or below it
    /// takes the patch's own (fallback) normal.
    degenerate: f64,
}

impl RawNormal {
    #[inline]
    fn new((su, sv): (Vec3, Vec3)) -> RawNormal {
        RawNormal {
            cross: su.cross(&sv),
            degenerate: scallop_surface::tol::NORMAL_DEGENERATE_REL * (su.norm_squared() + sv.norm_squared()),
        }
    }
}

/// Points (and unit normals when asked) of `patch` on the tensor grid of domain
/// fractions `us x vs`, index `a * vs.len() + b`. Bezier patches are evaluated
/// from per-row Bernstein tables (no allocation per point); NURBS patches point
/// by point. Normals are `Su x Sv` normalised, or `Patch::normal`'s fallback at
/// degenerate points.
fn grid(patch: &Patch, us: &[f64], vs: &[f64], with_normals: bool) -> (Vec<Point3>, Vec<Vec3>) {
    let domain = patch.domain();
    let size = us.len() * vs.len();
    let mut points = Vec::with_capacity(size);
    let mut normals = Vec::with_capacity(if with_normals { size } else { 0 });
    let normal_of = |du: &Vec3, dv: &Vec3, u: f64, v: f64| {
        let n = du.cross(dv);
        let norm = n.norm();
        if norm > scallop_surface::tol::NORMAL_DEGENERATE_REL * (du.norm_squared() + dv.norm_squared()) {
            n / norm
        } else {
            patch.normal(u, v)
        }
    };
    let [p, q] = patch.degree();
    if !patch.is_bezier() || p > normals::MAX_DEGREE || q > normals::MAX_DEGREE {
        for &s in us {
            for &t in vs {
                let (u, v) = domain.lerp(s, t);
                let d = patch.derivatives(u, v);
                points.push(d.point);
                if with_normals {
                    normals.push(normal_of(&d.du, &d.dv, u, v));
                }
            }
        }
        return (points, normals);
    }
    let weight = |i: usize, j: usize| patch.weights().map_or(1.0, |w| w[i * (q + 1) + j]);
    let table = |n: usize, t: f64| {
        let (mut values, mut derivatives) = ([0.0; normals::MAX_DEGREE + 1], [0.0; normals::MAX_DEGREE + 1]);
        normals::bernstein(n, t, &mut values, &mut derivatives);
        [values, derivatives]
    };
    let table_v: Vec<[[f64; normals::MAX_DEGREE + 1]; 2]> = vs.iter().map(|&t| table(q, t)).collect();
    // Per u: the homogeneous row curves H_j = sum_i B_i(u) w_ij [P_ij, 1] and H'_j.
    let mut rows = vec![[0.0; 4]; q + 1];
    let mut rows_du = vec![[0.0; 4]; q + 1];
    for &s in us {
        let [bu, dbu] = table(p, s);
        for j in 0..=q {
            rows[j] = [0.0; 4];
            rows_du[j] = [0.0; 4];
            for i in 0..=p {
                let w = weight(i, j);
                let c = patch.control_point(i, j);
                let h = [c.x * w, c.y * w, c.z * w, w];
                for k in 0..4 {
                    rows[j][k] += bu[i] * h[k];
                    rows_du[j][k] += dbu[i] * h[k];
                }
            }
        }
        for (&t, [bv, dbv]) in vs.iter().zip(&table_v) {
            let (mut a, mut a_u, mut a_v) = ([0.0; 4], [0.0; 4], [0.0; 4]);
            for j in 0..=q {
                for k in 0..4 {
                    a[k] += bv[j] * rows[j][k];
                    a_u[k] += bv[j] * rows_du[j][k];
                    a_v[k] += dbv[j] * rows[j][k];
                }
            }
            let point = Point3::new(a[0] / a[3], a[1] / a[3], a[2] / a[3]);
            points.push(point);
            if with_normals {
                let du = (Vec3::new(a_u[0], a_u[1], a_u[2]) - point.coords * a_u[3]) / a[3];
                let dv = (Vec3::new(a_v[0], a_v[1], a_v[2]) - point.coords * a_v[3]) / a[3];
                let (u, v) = domain.lerp(s, t);
                normals.push(normal_of(&du, &dv, u, v));
            }
        }
    }
    (points, normals)
}

/// A 3+2 orientation (finishing.md 4.5): tool axis `a = (sin tilt cos azimuth,
/// sin tilt sin azimuth, cos tilt)`, and the rotation `Q` about `centre` that maps
/// `a` onto +Z (Rodrigues, axis `a x Z`, angle `|tilt|`; identity for tilt 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Orientation {
    /// `Phi` in `[-pi/2, pi/2]`: angle between the tool axis and Z (rad).
    pub tilt: f64,
    /// `Psi` in `[0, pi]`: angle from X of the tool axis's XY projection (rad).
    pub azimuth: f64,
    /// Rotation centre (the zone's mean point, 4.5 \[DECISION\]); times do not depend on it.
    pub centre: Point3,
    matrix: Matrix3<f64>,
}

impl Orientation {
    /// The orientation of tool axis `(tilt, azimuth)` about `centre`.
    ///
    /// ```
    /// use scallop_geom::{Point3, Vec3};
    /// use scallop_network::Orientation;
    /// let o = Orientation::new(0.3, 1.0, Point3::origin());
    /// let z = o.rotate(&o.tool_axis());
    /// assert!((z - Vec3::z()).norm() < 1e-12);
    /// ```
    #[must_use]
    pub fn new(tilt: f64, azimuth: f64, centre: Point3) -> Orientation {
        let axis = Vec3::new(tilt.sin() * azimuth.cos(), tilt.sin() * azimuth.sin(), tilt.cos());
        let k = axis.cross(&Vec3::z());
        let sin = k.norm();
        let cos = axis.z;
        let matrix = if sin <= 0.0 {
            if cos >= 0.0 { Matrix3::identity() } else { Matrix3::from_diagonal(&Vec3::new(1.0, -1.0, -1.0)) }
        } else {
            // Rodrigues: R = I + sin K + (1 - cos) K^2 with K the cross matrix of the unit axis.
            let k = k / sin;
            let cross = Matrix3::new(0.0, -k.z, k.y, k.z, 0.0, -k.x, -k.y, k.x, 0.0);
            Matrix3::identity() + cross * sin + cross * cross * (1.0 - cos)
        };
        Orientation { tilt, azimuth, centre, matrix }
    }

    /// The tool axis `a` in the part frame.
    #[must_use]
    pub fn tool_axis(&self) -> Vec3 {
        Vec3::new(self.tilt.sin() * self.azimuth.cos(), self.tilt.sin() * self.azimuth.sin(), self.tilt.cos())
    }

    /// `Q v`: a part-frame vector in the machine frame.
    #[must_use]
    pub fn rotate(&self, v: &Vec3) -> Vec3 {
        self.matrix * v
    }

    /// A part-frame point in the machine frame: `c + Q (p - c)`.
    #[must_use]
    pub fn to_machine(&self, p: &Point3) -> Point3 {
        self.centre + self.matrix * (p - self.centre)
    }

    /// A machine-frame point back in the part frame: `c + Q^T (p - c)`.
    #[must_use]
    pub fn to_part(&self, p: &Point3) -> Point3 {
        self.centre + self.matrix.transpose() * (p - self.centre)
    }
}

/// Labels of a clustering grid over the parameter square `[0, 1]^2` (fractions of
/// the patch domain): `cells_u x cells_v` cells, cell `(a, b)` covers
/// `[a / cells_u, (a + 1) / cells_u] x [b / cells_v, (b + 1) / cells_v]`, label at
/// index `a * cells_v + b` (the order of `scallop_analysis::sample_patch`).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct CellLabels {
    /// Cells along u.
    pub cells_u: usize,
    /// Cells along v.
    pub cells_v: usize,
    /// One label per cell, index `a * cells_v + b`.
    pub labels: Vec<u32>,
}

impl CellLabels {
    /// The label of the cell containing `(u, v)` (clamped into `[0, 1]^2`; a point
    /// on a cell boundary belongs to the cell above it).
    #[must_use]
    pub fn label_at(&self, u: f64, v: f64) -> u32 {
        self.labels[self.cell(u, v)]
    }

    #[inline]
    pub(crate) fn cell_index(t: f64, cells: usize) -> usize {
        // INVARIANT: the index is clamped into [0, cells - 1]: `as` saturates a
        // negative (or NaN) product to 0, `min` caps t >= 1 (the same cells as
        // clamping t into [0, 1] first).
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        // Truncation is the floor of a non-negative value (and avoids a libm call).
        let i = (t * cells as f64) as usize;
        i.min(cells - 1)
    }

    pub(crate) fn cell(&self, u: f64, v: f64) -> usize {
        Self::cell_index(u, self.cells_u) * self.cells_v + Self::cell_index(v, self.cells_v)
    }

    fn validate(&self) -> Result<(), StrategyError> {
        if self.cells_u == 0 || self.cells_v == 0 || self.labels.len() != self.cells_u * self.cells_v {
            return Err(StrategyError::BadLabels {
                cells_u: self.cells_u,
                cells_v: self.cells_v,
                found: self.labels.len(),
            });
        }
        Ok(())
    }
}

/// A labelling prepared for one network resolution: the zones (distinct labels,
/// increasing) and, per zone, the network quads that overlap one of its cells.
/// Build it once per labelling and plan every zone from it.
#[derive(Debug, Clone, PartialEq)]
pub struct Zoning {
    labels: CellLabels,
    quads_u: usize,
    quads_v: usize,
    zones: Vec<u32>,
    /// Per zone (index into `zones`), the quads `[a, b]` overlapping it, in
    /// increasing index `a N_v + b` (pairs: no division per quad and zone).
    quads: Vec<Vec<[u32; 2]>>,
    /// Per quad: the label of its cells when they all agree, else `MIXED`.
    quad_label: Vec<u32>,
    /// Cells `[first, last]` overlapped by each network column `a` and row `b`.
    ranges_u: Vec<(usize, usize)>,
    ranges_v: Vec<(usize, usize)>,
}

/// Marks a quad whose cells carry several labels.
const MIXED: u32 = u32::MAX;

impl Zoning {
    /// Prepares `labels` for networks of `network`'s resolution.
    ///
    /// # Errors
    /// [`StrategyError::BadLabels`] when the labels do not fill the grid, or a
    /// label is `u32::MAX` (reserved).
    pub fn new(network: &Network, labels: &CellLabels) -> Result<Zoning, StrategyError> {
        labels.validate()?;
        if labels.labels.contains(&MIXED) {
            return Err(StrategyError::BadLabels {
                cells_u: labels.cells_u,
                cells_v: labels.cells_v,
                found: labels.labels.len(),
            });
        }
        let (nu, nv) = network.resolution();
        let (zones, index) = distinct_labels(&labels.labels);
        // INVARIANT: every label is in `zones`.
        let zone_index = |l: u32| match &index {
            Some(index) => index[l as usize] as usize,
            None => zones.binary_search(&l).unwrap_or(0),
        };
        let mut quads = vec![Vec::new(); zones.len()];
        let mut quad_label = Vec::with_capacity(nu * nv);
        let ranges_u: Vec<(usize, usize)> = (0..nu).map(|a| cell_range(a, nu, labels.cells_u)).collect();
        let ranges_v: Vec<(usize, usize)> = (0..nv).map(|b| cell_range(b, nv, labels.cells_v)).collect();
        let mut seen: Vec<u32> = Vec::new();
        for (a, &(i0, i1)) in ranges_u.iter().enumerate() {
            for (b, &(j0, j1)) in ranges_v.iter().enumerate() {
                let q = [u32::try_from(a).unwrap_or(u32::MAX), u32::try_from(b).unwrap_or(u32::MAX)];
                let first = labels.labels[i0 * labels.cells_v + j0];
                if i1 - i0 <= 1 && j1 - j0 <= 1 {
                    // At most 2 x 2 cells (a network finer than the grid, the
                    // usual case): the four corner cells' labels (repeated where
                    // the quad has one row or column of cells) compared without
                    // loops, their distinct labels pushed in the same sets.
                    let at = |i: usize, j: usize| labels.labels[i * labels.cells_v + j];
                    let (l01, l10, l11) = (at(i0, j1), at(i1, j0), at(i1, j1));
                    if (first == l01) & (first == l10) & (first == l11) {
                        quads[zone_index(first)].push(q);
                        quad_label.push(first);
                        continue;
                    }
                    quads[zone_index(first)].push(q);
                    if l01 != first {
                        quads[zone_index(l01)].push(q);
                    }
                    if l10 != first && l10 != l01 {
                        quads[zone_index(l10)].push(q);
                    }
                    if l11 != first && l11 != l01 && l11 != l10 {
                        quads[zone_index(l11)].push(q);
                    }
                    quad_label.push(MIXED);
                    continue;
                }
                let uniform = (i0..=i1).all(|i| {
                    labels.labels[i * labels.cells_v + j0..=i * labels.cells_v + j1].iter().all(|&l| l == first)
                });
                if uniform {
                    quads[zone_index(first)].push(q);
                    quad_label.push(first);
                    continue;
                }
                seen.clear();
                for i in i0..=i1 {
                    for &l in &labels.labels[i * labels.cells_v + j0..=i * labels.cells_v + j1] {
                        if !seen.contains(&l) {
                            seen.push(l);
                        }
                    }
                }
                for &l in &seen {
                    quads[zone_index(l)].push(q);
                }
                quad_label.push(MIXED);
            }
        }
        Ok(Zoning { labels: labels.clone(), quads_u: nu, quads_v: nv, zones, quads, quad_label, ranges_u, ranges_v })
    }

    /// The zones (distinct labels), increasing.
    #[must_use]
    pub fn zones(&self) -> &[u32] {
        &self.zones
    }

    /// The labelling.
    #[must_use]
    pub fn labels(&self) -> &CellLabels {
        &self.labels
    }

    /// Whether quad `q` overlaps a cell of label `zone`.
    #[inline]
    pub(crate) fn quad_in_zone(&self, q: usize, zone: u32) -> bool {
        let l = self.quad_label[q];
        if l != MIXED {
            return l == zone;
        }
        self.mixed_quad_in_zone(q, zone)
    }

    /// [`Zoning::quad_in_zone`] of a quad over several labels.
    fn mixed_quad_in_zone(&self, q: usize, zone: u32) -> bool {
        let (a, b) = (q / self.quads_v, q % self.quads_v);
        let ((i0, i1), (j0, j1)) = (self.ranges_u[a], self.ranges_v[b]);
        (i0..=i1).any(|i| (j0..=j1).any(|j| self.labels.labels[i * self.labels.cells_v + j] == zone))
    }
}

/// The distinct labels, increasing, and when they are small enough for a table
/// (below twice the number of cells, the usual dense zone numbering) the index
/// of every label in that list.
fn distinct_labels(labels: &[u32]) -> (Vec<u32>, Option<Vec<u32>>) {
    let top = labels.iter().copied().max().unwrap_or(0) as usize;
    if top >= 2 * labels.len().max(1) {
        let mut zones = labels.to_vec();
        zones.sort_unstable();
        zones.dedup();
        return (zones, None);
    }
    let mut index = vec![u32::MAX; top + 1];
    for &l in labels {
        index[l as usize] = 0;
    }
    let mut zones = Vec::new();
    for (l, slot) in index.iter_mut().enumerate() {
        if *slot == 0 {
            // INVARIANT: l <= top < 2 * cells < u32::MAX (CellLabels are u32-indexed).
            *slot = u32::try_from(zones.len()).unwrap_or(u32::MAX);
            zones.push(u32::try_from(l).unwrap_or(u32::MAX));
        }
    }
    (zones, Some(index))
}

/// Cells `[first, last]` overlapped (with positive area) by network interval
/// `[k / n, (k + 1) / n]` on a grid of `cells` cells.
fn cell_range(k: usize, n: usize, cells: usize) -> (usize, usize) {
    let lo = k as f64 / n as f64;
    let hi = (k + 1) as f64 / n as f64;
    let first = CellLabels::cell_index(lo, cells);
    // The last cell whose lower edge is below hi.
    // INVARIANT: hi in (0, 1]; the product is in (0, cells].
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let last = ((hi * cells as f64).ceil() as usize).clamp(1, cells) - 1;
    (first, last.max(first))
}

/// Plane margins of the sweep (finishing.md 6.5).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Margins {
    /// \[DECISION, default\] the first plane half its own spacing inside the zone's
    /// extent along `m`, the last within half its spacing of the far end
    /// (`ceil(W / Delta)` planes on a strip of width `W`).
    HalfStep,
    /// The spec's PLAN_ZONE: first plane at `d_min + start`, planes while
    /// `d <= d_max - end`, and a final plane at `d_max - end` when the residual
    /// gap exceeds half the last spacing (mm). `(0, 0)` is the spec's default.
    Fixed {
        /// `m_start` (mm).
        start: f64,
        /// `m_end` (mm).
        end: f64,
    },
}

/// Machining decisions for one zone (mm, rad, s).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ZoneParams {
    /// Feed direction `Theta` (rad from +X, in the network's frame).
    pub direction: f64,
    /// The cutter: ball, toroidal, or a flat end as `Toroidal { corner: 0 }` (whose
    /// step-over is at least its saw tooth `sh / sin s`). `Cutter::Flat` is refused.
    pub tool: Cutter,
    /// Maximum scallop height `sh` (mm), below the (corner) radius.
    pub scallop_height: f64,
    /// Plane margins.
    pub margins: Margins,
    /// Direction change (rad) above which a pass is cut into two stop-to-stop moves.
    pub sharp_corner: f64,
    /// Machine kinematics.
    pub machine: MachineLimits,
}

/// One pass: a contact polyline on the network, run in the direction stored.
#[derive(Debug, Clone, PartialEq)]
pub struct Pass {
    /// Contact points (network frame).
    pub points: Vec<Point3>,
    /// Their parameters `(u, v)` in `[0, 1]^2` (fractions of the patch domain).
    pub params: Vec<[f64; 2]>,
    /// Length (mm).
    pub length: f64,
    /// Stop-to-stop time of its chains between sharp corners (s).
    pub time: f64,
}

/// One plane of the sweep, passes in increasing feed coordinate `f . P`
/// (the zigzag order runs odd planes backwards).
#[derive(Debug, Clone, PartialEq)]
pub struct NetworkPlane {
    /// Offset `d = m . P` (mm).
    pub offset: f64,
    /// NEXT_SPACING of the plane (mm; `+inf` without vertices).
    pub spacing: f64,
    /// The zone's passes on this plane, oriented along `+f`.
    pub passes: Vec<Pass>,
}

/// The plan of one zone (finishing.md 6.5, 7.4).
#[derive(Debug, Clone, PartialEq)]
pub struct ZonePlan {
    /// The zone's label (0 for a whole surface).
    pub zone: u32,
    /// Feed direction (rad, network frame).
    pub direction: f64,
    /// The orientation of the network planned on, if any.
    pub orientation: Option<Orientation>,
    /// Planes in increasing offset (the sweep order).
    pub planes: Vec<NetworkPlane>,
    /// Connections in machining order: straight segments from each pass end to
    /// the next pass start (network frame).
    pub connections: Vec<[Point3; 2]>,
    /// Number of passes.
    pub passes: usize,
    /// `L_cut`: passes (mm).
    pub cut_length_mm: f64,
    /// `L_link`: connections (mm).
    pub link_length_mm: f64,
    /// Zone time: passes plus connections (s).
    pub time_s: f64,
    /// First contact point of the zone, in the part frame.
    pub start: Point3,
    /// Last contact point of the zone, in the part frame.
    pub end: Point3,
}

impl ZonePlan {
    /// The passes in machining (zigzag) order, each with `true` when it is run
    /// backwards (from its last point to its first).
    pub fn machining_order(&self) -> impl Iterator<Item = (&Pass, bool)> {
        self.planes.iter().enumerate().flat_map(|(i, plane)| {
            let backwards = i % 2 == 1;
            let passes: Box<dyn Iterator<Item = &Pass>> =
                if backwards { Box::new(plane.passes.iter().rev()) } else { Box::new(plane.passes.iter()) };
            passes.map(move |p| (p, backwards))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tabulated grid equals point-by-point evaluation, rational patches included.
    #[test]
    fn grid_matches_the_patch() {
        let p = |x, y, z| Point3::new(x, y, z);
        let control = [
            vec![p(0., 0., 0.), p(0., 5., 2.), p(0., 10., 0.)],
            vec![p(5., 0., 1.), p(5., 5., 6.), p(5., 10., 1.)],
            vec![p(10., 0., 0.), p(10., 5., -2.), p(10., 10., 3.)],
        ];
        let weights = [vec![1.0, 2.0, 1.0], vec![0.5, 1.0, 3.0], vec![1.0, 1.5, 1.0]];
        let choi = scallop_surface::builtin("choi").unwrap_or_else(|| unreachable!()).patches()[0].clone();
        for patch in
            [choi, Patch::bezier("rational", [2, 2], &control, Some(&weights)).unwrap_or_else(|e| panic!("{e}"))]
        {
            let us = [0.0, 0.13, 0.5, 0.77, 1.0];
            let vs = [0.0, 0.31, 0.9, 1.0];
            let (points, normals) = grid(&patch, &us, &vs, true);
            for (a, &u) in us.iter().enumerate() {
                for (b, &v) in vs.iter().enumerate() {
                    let k = a * vs.len() + b;
                    assert!((points[k] - patch.point(u, v)).norm() < 1e-12, "{u} {v}");
                    assert!((normals[k] - patch.normal(u, v)).norm() < 1e-12, "{u} {v}");
                }
            }
        }
    }

    /// The distinct-label table equals sort + dedup, for dense and sparse labels.
    #[test]
    fn distinct_labels_equal_sorted_dedup() {
        let mut seed = 7u64;
        for case in 0..60u32 {
            let len = 1 + (case as usize * 13) % 97;
            let spread = if case % 3 == 0 { 1u64 << 31 } else { u64::from(case % 11 + 1) };
            let labels: Vec<u32> = (0..len)
                .map(|_| {
                    seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
                    u32::try_from((seed >> 33) % spread).unwrap()
                })
                .collect();
            let mut expected = labels.clone();
            expected.sort_unstable();
            expected.dedup();
            let (zones, index) = distinct_labels(&labels);
            assert_eq!(zones, expected, "case {case}");
            if let Some(index) = index {
                for (i, &z) in zones.iter().enumerate() {
                    assert_eq!(index[z as usize] as usize, i, "case {case}");
                }
            }
        }
    }

    /// `cell_index` equals the clamp-first form on and outside [0, 1].
    #[test]
    fn cell_index_equals_clamped_form() {
        for cells in [1usize, 7, 80] {
            for k in -300..=1300 {
                let t = f64::from(k) * 1e-3 + if k % 3 == 0 { 1e-17 } else { 0.0 };
                #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
                let clamped = ((t.clamp(0.0, 1.0) * cells as f64) as usize).min(cells - 1);
                assert_eq!(CellLabels::cell_index(t, cells), clamped, "t {t} cells {cells}");
            }
            assert_eq!(CellLabels::cell_index(f64::NAN, cells), 0);
            assert_eq!(CellLabels::cell_index(f64::INFINITY, cells), cells - 1);
            assert_eq!(CellLabels::cell_index(f64::NEG_INFINITY, cells), 0);
        }
    }
}
