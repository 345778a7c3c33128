//! Tool-axis orientation by reparameterising the two guide curves of a pass
//! (Jousselin 2020, Ch. 3 §2; docs/rough5.md, "Optimised orientation").
//!
//! Each curve keeps its shape; its parameter becomes a cubic of the common
//! parameter s in [0, 1] (Eq. 3.11): s_T = g_T(s), s_D = g_D(s), with the
//! coefficients x = (c_T3, c_T2, c_T1, c_T0, c_D3, c_D2, c_D1, c_D0)
//! (Eq. 3.26); x0 = SPU = (0, 0, 1, 0, 0, 0, 1, 0) (Eq. 3.27). The pitch
//! angle theta_t(s) (Eq. 3.7) of the axis P_T(g_T(s)) -> P_D(g_D(s)) is
//! shaped by F = beta L_HL + phi E_f + tau E_t (Eq. 3.12-3.16), sampled at
//! regular s (the discrete sums of docs/rough5.md), under the constraints of
//! Eq. 3.17-3.19 as corrected there: at every sample g_T' >= 0, g_D' >= 0 and
//! g_T' + g_D' >= epsilon (the thesis's |g_T' + g_D'| >= 0 is vacuous);
//! g_T(1) - g_T(0) = 1 and g_D(1) - g_D(0) = 1 (each curve covered once; the
//! thesis's ">= 1", whose printed second row also wrongly includes c_D0, is
//! the option [`Coverage::AtLeast`]); g_T(0) = 0 when the entry point is
//! imposed (Eq. 3.29). The solver is the SQP of [`crate::sqp`].

use scallop_geom::Point3;
use scallop_guides::Curve;

use crate::sqp::{LinearConstraints, minimise};
use crate::sync::{PassCurves, SyncPoint};
use crate::{Rough5Error, pitch_angle, tol};

/// The weights (beta, phi, tau) of the bounds, fluidity and pitch-target
/// objectives (Eq. 3.16).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Weights {
    /// beta: theta_t kept in the interval (Eq. 3.12-3.13).
    pub bounds: f64,
    /// phi: fluidity, the integral of (d theta_t / ds)^2 (Eq. 3.14).
    pub fluidity: f64,
    /// tau: theta_t kept at the target (Eq. 3.15).
    pub pitch: f64,
}

/// The penalty of theta_t outside its interval [c - w, c + w].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BoundsPenalty {
    /// Eq. 3.12 as printed: |theta_t - c| where |theta_t - c| >= w, else 0
    /// (discontinuous at the bounds).
    Printed,
    /// max(0, |theta_t - c| - w)^2: continuous with its gradient.
    Smooth,
}

/// How much of each curve one pass covers (Eq. 3.18).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Coverage {
    /// g(1) - g(0) = 1 for both curves: each covered exactly once.
    Exact,
    /// g(1) - g(0) >= 1, the thesis's form.
    AtLeast,
}

/// The angle unit inside the objectives (not stated by the thesis; it sets
/// the relative scale of the terms, hence the meaning of the weights).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AngleUnit {
    /// Degrees (default).
    Degrees,
    /// Radians.
    Radians,
}

/// Settings of the orientation of one pass (angles in rad).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrientSettings {
    /// (beta, phi, tau).
    pub weights: Weights,
    /// [theta_tmin, theta_tmax] of the bounds objective (rad).
    pub interval: [f64; 2],
    /// theta_tobj of the pitch objective (rad).
    pub target: f64,
    /// Number of steps of the sampling of s (samples at k / steps).
    pub samples: usize,
    /// Unit of the angles inside the objectives.
    pub unit: AngleUnit,
    /// The bounds penalty.
    pub penalty: BoundsPenalty,
    /// Coverage of the curves.
    pub coverage: Coverage,
    /// g_T(0) = 0: the material entry point is imposed (Eq. 3.19).
    pub fixed_entry: bool,
    /// Most SQP iterations.
    pub max_iterations: usize,
}

impl OrientSettings {
    /// SPU weights (0, 0, 0) with the defaults: interval [0, 30 deg], target
    /// 10 deg, 100 samples, degrees, the printed bounds penalty, exact
    /// coverage, the entry imposed, 100 iterations.
    #[must_use]
    pub fn new(weights: Weights) -> OrientSettings {
        OrientSettings {
            weights,
            interval: [0.0, 30f64.to_radians()],
            target: 10f64.to_radians(),
            samples: 100,
            unit: AngleUnit::Degrees,
            penalty: BoundsPenalty::Printed,
            coverage: Coverage::Exact,
            fixed_entry: true,
            max_iterations: 100,
        }
    }
}

/// The two cubics g_T and g_D (Eq. 3.11) by their coefficients x (Eq. 3.26).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reparam {
    /// (c_T3, c_T2, c_T1, c_T0, c_D3, c_D2, c_D1, c_D0).
    pub x: [f64; 8],
}

impl Reparam {
    /// SPU: s_T = s_D = s (Eq. 3.27).
    pub const SPU: Reparam = Reparam { x: [0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] };

    fn cubic(c: &[f64], s: f64) -> f64 {
        ((c[0] * s + c[1]) * s + c[2]) * s + c[3]
    }

    fn rate(c: &[f64], s: f64) -> f64 {
        (3.0 * c[0] * s + 2.0 * c[1]) * s + c[2]
    }

    /// s_T = g_T(s).
    #[must_use]
    pub fn path(&self, s: f64) -> f64 {
        Reparam::cubic(&self.x[..4], s)
    }

    /// s_D = g_D(s).
    #[must_use]
    pub fn tilt(&self, s: f64) -> f64 {
        Reparam::cubic(&self.x[4..], s)
    }

    /// g_T'(s).
    #[must_use]
    pub fn path_rate(&self, s: f64) -> f64 {
        Reparam::rate(&self.x[..4], s)
    }

    /// g_D'(s).
    #[must_use]
    pub fn tilt_rate(&self, s: f64) -> f64 {
        Reparam::rate(&self.x[4..], s)
    }
}

/// The linear constraints of Eq. 3.17-3.19 as corrected (module docs) on the
/// samples of `settings`, as `rows x <= rhs` and equalities.
#[must_use]
pub fn constraints(settings: &OrientSettings) -> LinearConstraints<8> {
    let mut c = LinearConstraints { eq_rows: Vec::new(), eq_rhs: Vec::new(), rows: Vec::new(), rhs: Vec::new() };
    let covered_t = [1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    let covered_d = [0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 0.0];
    match settings.coverage {
        Coverage::Exact => {
            c.eq_rows.extend([covered_t, covered_d]);
            c.eq_rhs.extend([1.0, 1.0]);
        }
        Coverage::AtLeast => {
            c.rows.extend([covered_t.map(|v| -v), covered_d.map(|v| -v)]);
            c.rhs.extend([-1.0, -1.0]);
        }
    }
    if settings.fixed_entry {
        c.eq_rows.push([0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0]);
        c.eq_rhs.push(0.0);
    }
    for s in samples(settings.samples) {
        let d = [-3.0 * s * s, -2.0 * s, -1.0, 0.0];
        let t = [d[0], d[1], d[2], 0.0, 0.0, 0.0, 0.0, 0.0];
        let u = [0.0, 0.0, 0.0, 0.0, d[0], d[1], d[2], 0.0];
        let both = [d[0], d[1], d[2], 0.0, d[0], d[1], d[2], 0.0];
        c.rows.extend([t, u, both]);
        c.rhs.extend([0.0, 0.0, -tol::MIN_PROGRESS]);
    }
    c
}

/// The sample values of s: k / steps for k = 0..=steps.
fn samples(steps: usize) -> impl Iterator<Item = f64> {
    let steps = steps.max(1);
    (0..=steps).map(move |k| k as f64 / steps as f64)
}

/// The objective terms (L_HL, E_f, E_t) of the pitch angles `theta` sampled
/// at regular s from 0 to 1, in the unit of `settings` (the discrete sums of
/// docs/rough5.md: rectangles on the first samples, forward differences).
#[must_use]
pub fn objective_terms(theta: &[f64], settings: &OrientSettings) -> [f64; 3] {
    let scale = match settings.unit {
        AngleUnit::Degrees => 180.0 / std::f64::consts::PI,
        AngleUnit::Radians => 1.0,
    };
    let [lo, hi] = settings.interval.map(|a| a * scale);
    let (centre, half) = ((hi + lo) / 2.0, (hi - lo) / 2.0);
    let target = settings.target * scale;
    let n = theta.len().saturating_sub(1).max(1);
    let ds = 1.0 / n as f64;
    let mut terms = [0.0; 3];
    for k in 0..n.min(theta.len()) {
        let th = theta[k] * scale;
        let off = (th - centre).abs();
        terms[0] += ds
            * match settings.penalty {
                BoundsPenalty::Printed if off >= half => off,
                BoundsPenalty::Printed => 0.0,
                BoundsPenalty::Smooth => (off - half).max(0.0).powi(2),
            };
        if let Some(next) = theta.get(k + 1) {
            terms[1] += ((next * scale - th) / ds).powi(2) * ds;
        }
        terms[2] += (target - th).powi(2) * ds;
    }
    terms
}

/// The pitch angles theta_t (rad) of the pass at the samples of s.
fn pitches(curves: &PassCurves, r: &Reparam, steps: usize) -> Vec<f64> {
    samples(steps)
        .map(|s| {
            let p = curves.pair(r.path(s), r.tilt(s));
            pitch_angle(&p.axis, &p.tangent, &p.normal)
        })
        .collect()
}

/// The orientation found for one pass.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Orientation {
    /// The reparameterisation.
    pub reparam: Reparam,
    /// F at the solution and at SPU.
    pub objective: f64,
    /// F at the start x0 = SPU.
    pub spu_objective: f64,
    /// SQP iterations.
    pub iterations: usize,
    /// Largest constraint violation at the solution (<= 0 when feasible).
    pub violation: f64,
}

/// Optimises the reparameterisation of the pass `path` (started at its
/// vertex closest to `start`) with its tilt curve `tilt`, from SPU.
///
/// # Errors
/// [`Rough5Error::BadSetting`] for non-finite or negative weights, no
/// samples, or a path with fewer than two points.
pub fn optimise_pass(
    path: &Curve,
    tilt: &Curve,
    start: &Point3,
    settings: &OrientSettings,
) -> Result<Orientation, Rough5Error> {
    let w = settings.weights;
    for (name, value) in [("beta", w.bounds), ("phi", w.fluidity), ("tau", w.pitch)] {
        if !(value.is_finite() && value >= 0.0) {
            return Err(Rough5Error::BadSetting { name, value });
        }
    }
    if settings.samples < 2 {
        return Err(Rough5Error::BadSetting { name: "samples", value: settings.samples as f64 });
    }
    let curves = PassCurves::new(path, Some(tilt), start)
        .ok_or(Rough5Error::BadSetting { name: "path points", value: path.line.points.len() as f64 })?;
    let f = |x: &[f64; 8]| {
        let t = objective_terms(&pitches(&curves, &Reparam { x: *x }, settings.samples), settings);
        w.bounds * t[0] + w.fluidity * t[1] + w.pitch * t[2]
    };
    let cons = constraints(settings);
    let r = minimise(&f, &Reparam::SPU.x, &cons, settings.max_iterations)
        .ok_or(Rough5Error::BadSetting { name: "x0 (SPU) infeasible: samples", value: settings.samples as f64 })?;
    Ok(Orientation {
        reparam: Reparam { x: r.x },
        objective: r.value,
        spu_objective: r.start_value,
        iterations: r.iterations,
        violation: cons.violation(&r.x),
    })
}

/// The pitch trace of the pass under `reparam`: (s, theta_t in rad) at
/// `steps + 1` regular values of s.
#[must_use]
pub fn pitch_trace(path: &Curve, tilt: &Curve, start: &Point3, reparam: &Reparam, steps: usize) -> Vec<(f64, f64)> {
    let Some(curves) = PassCurves::new(path, Some(tilt), start) else { return Vec::new() };
    samples(steps).zip(pitches(&curves, reparam, steps)).collect()
}

/// The synchronised pairs of the pass under `reparam`, at a constant step
/// of about `step` mm along the path curve (Fig. 3.15 step 5: the values of
/// s giving equally spaced s_T, by bisection on the non-decreasing g_T).
#[must_use]
pub fn synchronise_with(path: &Curve, tilt: &Curve, start: &Point3, step: f64, reparam: &Reparam) -> Vec<SyncPoint> {
    let Some(curves) = PassCurves::new(path, Some(tilt), start) else { return Vec::new() };
    let (t0, t1) = (reparam.path(0.0), reparam.path(1.0));
    let count = ((curves.path_length() * (t1 - t0).abs() / step).ceil() as usize).clamp(2, tol::MAX_PASS_POINTS);
    (0..=count)
        .map(|k| {
            let target = t0 + (t1 - t0) * k as f64 / count as f64;
            let (mut lo, mut hi) = (0.0, 1.0);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if reparam.path(mid) < target {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            let s = if k == count { 1.0 } else { 0.5 * (lo + hi) };
            curves.pair(target, reparam.tilt(s))
        })
        .collect()
}
