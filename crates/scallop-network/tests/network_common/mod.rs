//! Shared fixtures of the network-planner tests.
#![allow(dead_code, clippy::unwrap_used)]

use scallop_analysis::{Cutter, MachineLimits};
use scallop_geom::{Point3, Vec3};
use scallop_network::{Margins, ZoneParams, ZonePlan};
use scallop_surface::Patch;

/// The spec's fixture (finishing.md 14.1) generalised: a `width` (along Y, u) x
/// `height` (along the slope in XZ, v) rectangle tilted `slope` rad, centred at
/// the origin, as a degree-1 Bezier patch.
pub fn inclined_plane(width: f64, height: f64, slope: f64) -> Patch {
    let (c, s) = (slope.cos(), slope.sin());
    let p = |u: f64, v: f64| Point3::new((v - 0.5) * height * c, (u - 0.5) * width, (v - 0.5) * height * s);
    Patch::bezier("plane", [1, 1], &[vec![p(0., 0.), p(0., 1.)], vec![p(1., 0.), p(1., 1.)]], None).unwrap()
}

/// Zone settings with the spec's machine.
pub fn params(direction: f64, tool: Cutter, scallop_height: f64) -> ZoneParams {
    ZoneParams {
        direction,
        tool,
        scallop_height,
        margins: Margins::HalfStep,
        sharp_corner: 30f64.to_radians(),
        machine: MachineLimits::default(),
    }
}

pub fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// The horizontal spacing a point of unit normal `n` allows (finishing.md 6.4),
/// computed the long way: tilt and horizontal feed angle by trigonometry, the
/// step-over from `scallop_analysis`, the cross-feed direction by cross products.
/// A flat end (`Toroidal { corner: 0 }`) is at least its saw tooth `sh / sin s`,
/// at most its diameter.
pub fn spacing_at(n: &Vec3, theta: f64, tool: &Cutter, sh: f64) -> f64 {
    let (sod, factor) = step_over_and_factor(n, theta, tool, sh);
    sod * factor
}

/// The step-over `sod` at a point of unit normal `n` and the factor `|c . m|`
/// turning it into a horizontal plane spacing (see [`spacing_at`]).
pub fn step_over_and_factor(n: &Vec3, theta: f64, tool: &Cutter, sh: f64) -> (f64, f64) {
    let slope = n.z.abs().min(1.0).acos();
    let alpha = if n.x.hypot(n.y) < 1e-12 { 0.0 } else { n.y.atan2(n.x) - theta };
    let mut sod = tool.step_over(sh, slope, alpha);
    if let Cutter::Toroidal { radius, corner } = *tool
        && corner <= 0.0
    {
        sod = sod.max(sh / slope.sin()).min(2.0 * radius);
    }
    let m = Vec3::new(-theta.sin(), theta.cos(), 0.0);
    let tau = m.cross(n);
    if tau.norm() <= 0.0 {
        return (sod, 0.0);
    }
    let c = n.cross(&(tau / tau.norm()));
    (sod, (c / c.norm()).dot(&m).abs())
}

/// Every point of every pass, with its plane index.
pub fn vertices(plan: &ZonePlan) -> Vec<(usize, Point3, [f64; 2])> {
    let mut out = Vec::new();
    for (i, plane) in plan.planes.iter().enumerate() {
        for pass in &plane.passes {
            for (p, uv) in pass.points.iter().zip(&pass.params) {
                out.push((i, *p, *uv));
            }
        }
    }
    out
}
