//! Entries into the material (module J; Jousselin 2020, Ch. 4 §1.3.1 and
//! §2.1; docs/rough5.md, "Entries"): a closed pocket is entered by a helix
//! where its tool-centre circle fits inside a closed pass, else by a ramp
//! along the pass; an open pocket from its crossable side, the tool brought
//! down beside the stock and fed into the pass start at the level's depth.
//!
//! - [`helix_entry`]: a helix about the tool axis, tangent to the pass at its
//!   start (inside on the left), descending at the ramp angle above the tool
//!   placed on the level, then a full turn on the level; refused where its
//!   circle leaves the pass's loop, where the tool would come closer to a
//!   flank than the check allows;
//! - [`side_entry`]: a straight approach at the pass start's height from
//!   where the whole tool is outside the stock; refused where a point of it
//!   is below the tool placed on the level, off the level inside the stock,
//!   or too close to a flank.

use scallop_geom::{Point3, Vec3};

use crate::collide::BodyCheck;
use crate::place::{Placer, tool_frame};
use crate::tol;

/// How the runs of a roughing program are entered from above the level
/// cut before ([`crate::Rough5Settings::entry`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum EntryMode {
    /// A helix where one fits ([`helix_entry`]), else a side entry where the
    /// run starts within reach of the stock's side ([`side_entry`]), else a
    /// ramp along a closed run, else a plunge.
    #[default]
    Auto,
    /// A helix where one fits, else a ramp along a closed run, else a plunge.
    Helix,
    /// A ramp along a closed run, else a plunge (the program of 28 Nov 2026).
    Ramp,
    /// A side entry where one is found, else a ramp, else a plunge.
    Side,
}

/// How many runs were entered each way.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct EntryCount {
    /// Helices ([`helix_entry`]).
    pub helix: usize,
    /// Ramps along a closed run.
    pub ramp: usize,
    /// Side entries ([`side_entry`]).
    pub side: usize,
    /// Plunges along the tool axis into material (neither a helix, a side
    /// entry nor a ramp was found).
    pub plunge: usize,
}

/// Radii of the helix's tool-centre circle tried, in tool radii, largest
/// first: below one tool radius the tool covers the circle's centre at every
/// turn, so no core is left standing; the smallest is still a quarter of the
/// tool's width of travel, not a plunge.
pub const HELIX_RADII: [f64; 3] = [0.75, 0.5, 0.25];

/// Start points tried along a closed run for a helix (evenly spaced, the
/// run's own start first).
pub const HELIX_STARTS: usize = 24;

/// A side entry starts at most this many tool radii from the pass start.
pub const SIDE_REACH_RADII: f64 = 4.0;

/// Horizontal directions tried for a side entry besides the pass's own
/// backward direction.
pub const SIDE_DIRECTIONS: usize = 16;

/// How far (mm) a helix's circle may reach beyond the pass's edges: the
/// circle is tangent to the pass at a vertex of its polyline, where the two
/// edges turn by the step over the pass's radius of curvature, and a circle
/// of radius r tangent to their bisector crosses them by `r (1 - cos(turn /
/// 2))`: 0.01 mm for the 3.75 mm circle on a 7 mm loop at 1 mm steps. The
/// tool then stays within this of the region its pass sweeps (the proof's
/// 5-axis sweep tolerance is 0.05 mm).
pub const HELIX_TANGENCY: f64 = 0.05;

/// The geometry of a helix entry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HelixSettings {
    /// Radius of the tool-centre circle (mm).
    pub radius: f64,
    /// Descent angle above the level (rad).
    pub ramp_angle: f64,
    /// Largest chord between two points of the helix (mm); the chords also
    /// turn by at most [`tol::FILLET_TURN_SHARE`] of the machine time
    /// model's smooth junction.
    pub step: f64,
}

/// The helix entry into the closed pass `pass` (tool tips, the last equal to
/// the first, inside on the left about `axis`) at its point `start`, from
/// `lift` mm above it along `axis`: the tool tips of the helix, from its top
/// to the pass's point `start`, the axis fixed.
///
/// The circle of the tool centre lies in the plane through the start point
/// normal to the axis, tangent to the pass there and on its inside, of
/// radius `h.radius`; every point of it must be inside the pass's loop
/// projected on that plane (within [`HELIX_TANGENCY`]): the tool never
/// leaves the region the level cuts. Each point is the tool placed on the
/// level along the axis (`placer`) lifted by the helix's height there, which
/// falls by `tan(ramp_angle)` per mm of the circle from `lift` to zero at
/// the start point; none may come closer to a flank than `body`
/// allows. `None` where the circle does not fit, a point cannot be placed
/// or collides.
#[must_use]
pub fn helix_entry(
    placer: &Placer,
    body: &BodyCheck,
    (pass, start): (&[Point3], usize),
    axis: &Vec3,
    lift: f64,
    h: &HelixSettings,
) -> Option<Vec<Point3>> {
    let n = pass.len().checked_sub(1)?;
    let angle_ok = h.ramp_angle > 0.0 && h.ramp_angle < std::f64::consts::FRAC_PI_2;
    let ok = n >= 3 && start < n && lift > 0.0 && h.radius > 0.0 && h.step > 0.0 && angle_ok;
    if !ok {
        return None;
    }
    let u = axis.normalize();
    let (e1, e2) = tool_frame(&u);
    let origin = pass[start];
    let flat = |p: &Point3| {
        let d = p - origin;
        [d.dot(&e1), d.dot(&e2)]
    };
    let poly: Vec<[f64; 2]> = pass[..n].iter().map(flat).collect();
    // The pass's direction at its start (the bisector of the edges in and
    // out of it), and its left in the plane.
    let unit = |q: [f64; 2]| {
        let l = q[0].hypot(q[1]);
        (l > 1e-9).then(|| [q[0] / l, q[1] / l])
    };
    let next = (1..n).find_map(|k| unit(poly[(start + k) % n]))?;
    let prev = (1..n).find_map(|k| unit(poly[(start + n - k) % n]))?;
    let t = unit([next[0] - prev[0], next[1] - prev[1]])?;
    let left = u.cross(&(e1 * t[0] + e2 * t[1]));
    let inward = [left.dot(&e1), left.dot(&e2)];
    let r = h.radius;
    let centre = [r * inward[0], r * inward[1]];
    if !circle_inside(&poly, centre, r - HELIX_TANGENCY) {
        return None;
    }
    // The angle the circle turns through while the tool descends.
    let descent = lift / h.ramp_angle.tan() / r;
    // Chords of at most the step, turning by at most the fillets' share of
    // the time model's smooth junction: a sharper junction is timed as a
    // corner, near a stop on short blocks (docs/rough5.md, "Entries").
    let turn = tol::FILLET_TURN_SHARE * scallop_geom::tol::machine::SMOOTH_JUNCTION;
    let count = ((descent * r / h.step).ceil().max((descent / turn).ceil()) as usize).max(16);
    let mut tips = Vec::with_capacity(count + 1);
    for k in 0..=count {
        let phi = -descent * (1.0 - k as f64 / count as f64);
        let height = lift * (-phi / descent).clamp(0.0, 1.0);
        let (c, s) = (phi.cos(), phi.sin());
        let x = centre[0] - r * c * inward[0] + r * s * t[0];
        let y = centre[1] - r * c * inward[1] + r * s * t[1];
        let on_plane = origin + e1 * x + e2 * y;
        let floor = if k == count { origin } else { placer.place(&on_plane, &u)?.tip };
        let tip = floor + u * height;
        if body.collides(&tip, &u) {
            return None;
        }
        tips.push(tip);
    }
    Some(tips)
}

/// Whether the disc of radius `r` about `centre` lies inside the polygon
/// `poly`: its centre inside (even-odd rule) and no edge nearer than `r`.
fn circle_inside(poly: &[[f64; 2]], centre: [f64; 2], r: f64) -> bool {
    let n = poly.len();
    let mut inside = false;
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        if (a[1] > centre[1]) != (b[1] > centre[1]) {
            let x = a[0] + (centre[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if x > centre[0] {
                inside = !inside;
            }
        }
        if segment_distance(centre, a, b) < r {
            return false;
        }
    }
    inside
}

/// Distance from `p` to the segment `[a, b]` in the plane.
fn segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let d = [b[0] - a[0], b[1] - a[1]];
    let l2 = d[0] * d[0] + d[1] * d[1];
    let w = if l2 > 0.0 { (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / l2).clamp(0.0, 1.0) } else { 0.0 };
    (p[0] - a[0] - w * d[0]).hypot(p[1] - a[1] - w * d[1])
}

/// Where a side entry of the tool at `start` (a pass's first tip, its axis
/// `axis`) begins: the nearest point, on a horizontal line through `start`
/// at most `reach` mm long, where `outside(tip, axis)` holds (the whole tool
/// is outside the stock) and from which the tool can be brought down along
/// its axis by `rise` mm in the air (`outside` every `step` mm up to there).
/// Every `step / 2` mm between it and `start` the tool must be at or above
/// the tool placed on the level (`placer`) and clear of the flanks (`body`).
/// The directions tried are `back` (the pass's own backward direction, for
/// an entry continuous with the pass) and [`SIDE_DIRECTIONS`] evenly spaced
/// ones; the shortest approach wins, the earlier direction on a tie.
#[must_use]
#[allow(clippy::too_many_arguments, reason = "the entry's geometry, each argument documented")]
pub fn side_entry(
    placer: &Placer,
    body: &BodyCheck,
    outside: &dyn Fn(&Point3, &Vec3) -> bool,
    (start, axis): (&Point3, &Vec3),
    back: Option<Vec3>,
    step: f64,
    reach: f64,
    rise: f64,
) -> Option<Point3> {
    if !(step > 0.0 && reach > 0.0) {
        return None;
    }
    let u = axis.normalize();
    let horizontal = |v: Vec3| {
        let v = Vec3::new(v.x, v.y, 0.0);
        let l = v.norm();
        (l > 1e-9).then(|| v / l)
    };
    let spaced = (0..SIDE_DIRECTIONS).map(|k| {
        let a = std::f64::consts::TAU * k as f64 / SIDE_DIRECTIONS as f64;
        Vec3::new(a.cos(), a.sin(), 0.0)
    });
    let directions: Vec<Vec3> = back.and_then(horizontal).into_iter().chain(spaced).collect();
    let ds = 0.5 * step;
    let steps = (reach / ds).ceil() as usize;
    let mut best: Option<(f64, Point3)> = None;
    for d in directions {
        for k in 1..=steps {
            let along = ds * k as f64;
            if best.is_some_and(|b| along >= b.0) {
                break;
            }
            let p = start + d * along;
            if outside(&p, &u) {
                let ups = (rise / step).ceil().max(0.0) as usize;
                let clear = (1..=ups).all(|j| outside(&(p + u * (rise * j as f64 / ups as f64)), &u));
                if clear {
                    best = Some((along, p));
                }
                break;
            }
            let placed = placer.place(&p, &u);
            let above = placed.is_some_and(|f| (p - f.tip).dot(&u) >= -1e-9);
            if !above || body.collides(&p, &u) {
                break;
            }
        }
    }
    best.map(|b| b.1)
}

/// The tool tip's dynamics along a path whose tool axis stays fixed (a
/// helix, a ramp): the machine's linear axes alone carry it, so the slowest
/// linear axis's acceleration and jerk bound it, with the controller's corner
/// tolerance (the machine time model of spec 8, `scallop_machine::time`).
/// [`crate::Rough5Settings::entry_dynamics`] chooses the entries by it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathDynamics {
    /// Acceleration (mm/s²).
    pub acceleration: f64,
    /// Jerk (mm/s³).
    pub jerk: f64,
    /// The controller's corner tolerance (mm): a junction sharper than the
    /// smooth junction is blended within it.
    pub corner_tolerance: f64,
}

/// Time (s) of a velocity change `dv` with zero acceleration at both ends
/// (spec 8.2, as `scallop_machine::time::t_acc`).
fn t_acc(dv: f64, a: f64, j: f64) -> f64 {
    let dv = dv.abs();
    if dv <= a * a / j { 2.0 * (dv / j).sqrt() } else { dv / a + a / j }
}

/// Distance (mm) a velocity change from `va` to `vb` takes (spec 8.2).
fn change_distance(va: f64, vb: f64, a: f64, j: f64) -> f64 {
    (va + vb) / 2.0 * t_acc(vb - va, a, j)
}

/// The velocity `vb >= va` reachable within `s`, at most `v` (bisection).
fn reach(va: f64, s: f64, (v, a, j): (f64, f64, f64)) -> f64 {
    if va >= v || change_distance(va, v, a, j) <= s {
        return v.max(va);
    }
    let (mut lo, mut hi) = (va, v);
    for _ in 0..scallop_geom::tol::machine::TIME_BISECTION_ITERATIONS {
        let mid = 0.5 * (lo + hi);
        if change_distance(va, mid, a, j) <= s { lo = mid } else { hi = mid }
    }
    lo
}

/// Time (s) of a chord of length `s` entered at `v0` and left at `v1` (spec
/// 8.5): cruise at the peak `v` if there is room, else the peak that fits.
fn chord_time(v0: f64, v1: f64, s: f64, (v, a, j): (f64, f64, f64)) -> f64 {
    let used = |vp: f64| change_distance(v0, vp, a, j) + change_distance(vp, v1, a, j);
    let vp = if used(v) <= s {
        v
    } else {
        let (mut lo, mut hi) = (v0.max(v1), v);
        for _ in 0..scallop_geom::tol::machine::TIME_BISECTION_ITERATIONS {
            let mid = 0.5 * (lo + hi);
            if used(mid) <= s { lo = mid } else { hi = mid }
        }
        lo
    };
    let cruise = if vp > 0.0 { (s - used(vp)).max(0.0) / vp } else { 0.0 };
    t_acc(vp - v0, a, j) + t_acc(vp - v1, a, j) + cruise
}

/// An estimate (s) of the time the tool tip takes along the polyline `tips`
/// at `feed` (mm/min) under `dynamics`, from a stop to a stop, as the
/// machine time model of spec 8 (`scallop_machine::time::path_time`) takes
/// a path whose tool axis stays fixed, with every linear axis at the
/// slowest one's limits: the speed at each junction is capped (spec 8.3)
/// below the smooth junction ([`scallop_geom::tol::machine::SMOOTH_JUNCTION`])
/// by the acceleration, `v² |Δe| / s <= a`, and the jerk,
/// `v³ |Δ²e| / s² <= j` (e the unit direction, s the mean chord: on a circle
/// of radius ρ, `v <= (j ρ²)^(1/3)`), above it by a blend within the corner
/// tolerance; a look-ahead then accelerates and decelerates between the caps
/// within the acceleration and jerk (spec 8.5). At the first and last
/// junctions the jerk term takes the direction's first difference (the
/// model takes a one-sided second difference there), so a path is estimated
/// a little slower at its ends than by the model.
///
/// ```
/// use scallop_geom::Point3;
/// use scallop_rough5::{PathDynamics, path_time_estimate};
/// let d = PathDynamics { acceleration: 2100.0, jerk: 5000.0, corner_tolerance: 0.1 };
/// // Five turns of a circle of radius 1.25 mm in 0.2 mm chords: the jerk
/// // holds the speed to (5000 x 1.25²)^(1/3) = 19.8 mm/s, under the
/// // 40 mm/s feed.
/// let circle = |r: f64, turns: f64| -> Vec<Point3> {
///     let n = (5.0 * turns * std::f64::consts::TAU * r).ceil() as usize;
///     (0..=n).map(|k| { let a = turns * std::f64::consts::TAU * k as f64 / n as f64; Point3::new(r * a.cos(), r * a.sin(), 0.0) }).collect()
/// };
/// // (Plus the start and the stop: at the first and last junctions the jerk
/// // term takes the direction's first difference, the turn from a line into
/// // the circle, about 0.5 s here.)
/// let t = path_time_estimate(&circle(1.25, 5.0), 2400.0, &d);
/// let length = 5.0 * std::f64::consts::TAU * 1.25;
/// assert!(t > length / 19.9 && t < length / 19.9 + 0.6, "{t} s for {length} mm");
/// // A straight 40 mm from a stop to a stop: the feed, 1 s, plus the jerk-limited
/// // start and stop, 2 sqrt(40 / 5000) = 0.179 s.
/// let line = [Point3::new(0.0, 0.0, 0.0), Point3::new(40.0, 0.0, 0.0)];
/// assert!((path_time_estimate(&line, 2400.0, &d) - 1.179).abs() < 1e-3);
/// ```
#[must_use]
pub fn path_time_estimate(tips: &[Point3], feed: f64, dynamics: &PathDynamics) -> f64 {
    let f = feed / 60.0;
    let chords: Vec<(f64, Vec3)> =
        tips.windows(2).map(|w| w[1] - w[0]).filter(|d| d.norm() > 1e-9).map(|d| (d.norm(), d / d.norm())).collect();
    let n = chords.len();
    if n == 0 || f.is_nan() || f <= 0.0 {
        return 0.0;
    }
    let PathDynamics { acceleration: a, jerk: j, corner_tolerance } = *dynamics;
    let limits = (f, a, j);
    // v[k]: the speed at the junction before chord k (a stop at 0 and n).
    let mut v = vec![f; n + 1];
    (v[0], v[n]) = (0.0, 0.0);
    for k in 1..n {
        let (s1, u1) = chords[k - 1];
        let (s2, u2) = chords[k];
        let de = u2 - u1;
        let theta = u1.cross(&u2).norm().atan2(u1.dot(&u2));
        let mean = 0.5 * (s1 + s2);
        let cap = if theta <= scallop_geom::tol::machine::SMOOTH_JUNCTION {
            let d2e = if k >= 2 && k + 1 < n { ((chords[k + 1].1 - u2) - (u1 - chords[k - 2].1)) / 2.0 } else { de };
            let by_a = if de.norm() > 1e-12 { (a * mean / de.norm()).sqrt() } else { f };
            let by_j = if d2e.norm() > 1e-12 { (j * mean * mean / d2e.norm()).cbrt() } else { f };
            by_a.min(by_j)
        } else {
            let blend = (4.0 * corner_tolerance / (theta / 2.0).sin()).min(s1 / 2.0).min(s2 / 2.0);
            let fits = |v: f64| v * t_acc(v * de.norm(), a, j) <= blend;
            if fits(f) {
                f
            } else {
                let (mut lo, mut hi) = (0.0, f);
                for _ in 0..scallop_geom::tol::machine::TIME_BISECTION_ITERATIONS {
                    let mid = 0.5 * (lo + hi);
                    if fits(mid) { lo = mid } else { hi = mid }
                }
                lo
            }
        };
        v[k] = cap.min(f);
    }
    for k in (0..n).rev() {
        v[k] = v[k].min(reach(v[k + 1], chords[k].0, limits));
    }
    for k in 0..n {
        v[k + 1] = v[k + 1].min(reach(v[k], chords[k].0, limits));
    }
    (0..n).map(|k| chord_time(v[k], v[k + 1], chords[k].0, limits)).sum()
}
