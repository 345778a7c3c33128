//! Machining time of a toolpath: the specification's stop-to-stop model and a
//! look-ahead feed profile.
//!
//! Moves fall in three classes, each with its own speed limit and the machine's
//! `A` and `J`: **cutting** (`Feed` and `Link` moves, at the feed `V`),
//! **plunge** (`Plunge`, at the plunge feed) and **rapid** (`Rapid` and
//! `Retract`, at the rapid rate). The tool stops wherever the class changes.
//!
//! # (a) Stop-to-stop model (finishing.md 7.1, 7.2)
//! Consecutive moves of one class form a chain until a **sharp corner**, a
//! direction change larger than [`crate::FinishingParams::sharp_corner`]; every
//! chain is one stop-to-stop move of its total length `L`, timed by
//! [`scallop_analysis::MachineLimits::segment_time`] (the 3-case jerk-limited
//! model, full S-curve by default). Direction changes below the angle are
//! taken at full speed (the model of the thesis: a pass is a portion without
//! sharp angles).
//!
//! An XY arc move ([`Toolpath::arc`], a helix when z changes along it) is
//! one segment of its own length, met at its junctions along its end
//! tangents; in model (b) its speed is also capped by its curvature: the
//! centripetal acceleration `v^2 / rho <= A` and its rate `v^3 / rho^2 <= J`,
//! with `rho` no less than the radius of the blend of a corner of the same
//! deflection (below): a small arc of a small sweep (a fillet of a tenth of
//! a millimetre turning a degree) is taken as that corner, and as `rho` goes
//! to 0 an arc's cap becomes the corner's junction speed. Every other move is
//! a line between its ends.
//!
//! # (b) Look-ahead model
//! Every move is a segment with a speed limit; junction speeds are bounded by
//! - 0 at the start, the end and wherever the class changes;
//! - corner blending with tolerance `delta` (the "junction deviation" of grbl
//!   and LinuxCNC's blending): a corner of deflection `phi` is rounded by a
//!   circular arc whose distance to the corner is `delta`; the arc of radius
//!   `rho = delta cos(phi/2) / (1 - cos(phi/2))` is taken at the speed of
//!   centripetal acceleration `A`: `v^2 = A rho`;
//! - the speed limits of both segments.
//!
//! A forward pass then a backward pass lower each junction speed to what the
//! segment before (after) it can reach with a **jerk-limited transition**:
//! changing speed by `dv` from rest acceleration to rest acceleration takes
//! `T = 2 sqrt(dv/J)` when `dv <= A^2/J`, else `T = dv/A + A/J`, and covers
//! `(v0 + v1) T / 2` (the profile is symmetric). Each segment is then timed as
//! transition up to a peak speed, cruise, transition down, with the highest
//! peak that fits. Acceleration returns to 0 at every junction (conservative:
//! real controllers blend transitions across junctions). With every junction
//! speed 0 this reproduces model (a) exactly: the four cases of finishing.md 7.2.

use scallop_analysis::MachineLimits;
use scallop_geom::Vec3;
use scallop_toolpath::{MoveKind, Toolpath};
use serde::{Deserialize, Serialize};

use crate::{FinishingParams, tol};

/// Time (s) per class of move.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct ClassTimes {
    /// `Feed` and `Link` moves.
    pub cutting: f64,
    /// `Plunge` moves.
    pub plunge: f64,
    /// `Rapid` and `Retract` moves.
    pub rapid: f64,
}

impl ClassTimes {
    /// Sum of the classes.
    #[must_use]
    pub fn total(&self) -> f64 {
        self.cutting + self.plunge + self.rapid
    }

    fn add(&mut self, class: Class, t: f64) {
        match class {
            Class::Cutting => self.cutting += t,
            Class::Plunge => self.plunge += t,
            Class::Rapid => self.rapid += t,
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Class {
    Cutting,
    Plunge,
    Rapid,
}

fn class(kind: MoveKind) -> Class {
    match kind {
        MoveKind::Feed | MoveKind::Link => Class::Cutting,
        MoveKind::Plunge => Class::Plunge,
        MoveKind::Rapid | MoveKind::Retract => Class::Rapid,
    }
}

fn limits(params: &FinishingParams, class: Class) -> MachineLimits {
    let feed = match class {
        Class::Cutting => params.machine.feed,
        Class::Plunge => params.plunge_feed,
        Class::Rapid => params.rapid_rate,
    };
    MachineLimits { feed, ..params.machine }
}

struct Segment {
    class: Class,
    length: f64,
    /// Direction at the start and at the end (equal on a line).
    dir_in: Vec3,
    dir_out: Vec3,
    /// Highest speed the segment's curvature allows (an arc), mm/s.
    cap: f64,
}

/// Move `k` of `path` (from move `k - 1`'s end) as a segment: a line, or an
/// XY arc with a linear z (a helix) whose length, end tangents and speed cap
/// are the arc's: the centripetal acceleration `v^2 / rho` within `A` and
/// its jerk `v^3 / rho^2` within `J` (the trochoid's limits, docs/machine.md).
fn segment(path: &Toolpath, k: usize, params: &FinishingParams) -> Option<Segment> {
    let moves = path.moves();
    let (from, to) = (moves[k - 1].to, moves[k].to);
    let chord = to - from;
    let line = |length: f64| {
        let dir = chord / length;
        Segment { class: class(moves[k].kind), length, dir_in: dir, dir_out: dir, cap: f64::INFINITY }
    };
    if let Some(arc) = path.arc(k) {
        let r0 = scallop_geom::Vec2::new(from.x - arc.center.x, from.y - arc.center.y);
        let r1 = scallop_geom::Vec2::new(to.x - arc.center.x, to.y - arc.center.y);
        let rho = r0.norm();
        let xy = rho * arc.sweep.abs();
        if rho > tol::ZERO_LENGTH && xy > tol::ZERO_LENGTH {
            let dz = to.z - from.z;
            let length = xy.hypot(dz);
            let turn = arc.sweep.signum();
            let tangent = |r: scallop_geom::Vec2| {
                let t = scallop_geom::Vec2::new(-r.y, r.x) * (turn / r.norm().max(tol::ZERO_LENGTH));
                Vec3::new(t.x * xy, t.y * xy, dz) / length
            };
            // The controller may leave the arc by the blend tolerance, as at a
            // corner: an arc whose sweep a blended corner of the same
            // deflection would round more gently is taken as that corner.
            let m = &params.machine;
            let cos_half = (0.5 * arc.sweep.abs().min(std::f64::consts::PI)).cos();
            let blend =
                if cos_half < 1.0 { params.blend_tolerance * cos_half / (1.0 - cos_half) } else { f64::INFINITY };
            let rho = rho.max(blend);
            let cap = (m.acceleration * rho).sqrt().min((m.jerk * rho * rho).cbrt());
            return Some(Segment {
                class: class(moves[k].kind),
                length,
                dir_in: tangent(r0),
                dir_out: tangent(r1),
                cap,
            });
        }
    }
    let length = chord.norm();
    (length > tol::ZERO_LENGTH).then(|| line(length))
}

fn segments(path: &Toolpath, params: &FinishingParams) -> Vec<(usize, Segment)> {
    (1..path.moves().len()).filter_map(|k| segment(path, k, params).map(|s| (k, s))).collect()
}

/// Model (a): stop-to-stop jerk-limited time of every chain between sharp
/// corners (see the module docs).
///
/// ```
/// # use scallop_strategy::{stop_to_stop_time, FinishingParams, Pattern, Boundary};
/// # use scallop_toolpath::{Move, MoveKind, Toolpath};
/// # use scallop_geom::Point3;
/// # use scallop_analysis::MachineLimits;
/// # let params = FinishingParams { direction: 0.0, pattern: Pattern::Zigzag, scallop_height: 0.01,
/// #     boundary: Boundary::ContactInside, max_step: 0.5, clearance: 5.0, machine: MachineLimits::default(),
/// #     plunge_feed: 20.0, rapid_rate: 500.0, sharp_corner: 0.5, blend_tolerance: 0.01 };
/// let mut path = Toolpath::new(5000.0);
/// path.push(Move::new(MoveKind::Feed, Point3::new(0.0, 0.0, 0.0)));
/// path.push(Move::new(MoveKind::Feed, Point3::new(28.0, 0.0, 0.0)));
/// let t = stop_to_stop_time(&path, &params);
/// assert!((t.cutting - params.machine.segment_time(28.0)).abs() < 1e-12);
/// ```
#[must_use]
pub fn stop_to_stop_time(path: &Toolpath, params: &FinishingParams) -> ClassTimes {
    let cos_sharp = params.sharp_corner.cos();
    let mut times = ClassTimes::default();
    let mut chain: Option<(Class, f64, Vec3)> = None;
    for (_, s) in segments(path, params) {
        chain = match chain {
            Some((c, len, dir)) if c == s.class && dir.dot(&s.dir_in) >= cos_sharp => {
                Some((c, len + s.length, s.dir_out))
            }
            Some((c, len, _)) => {
                times.add(c, limits(params, c).segment_time(len));
                Some((s.class, s.length, s.dir_out))
            }
            None => Some((s.class, s.length, s.dir_out)),
        };
    }
    if let Some((c, len, _)) = chain {
        times.add(c, limits(params, c).segment_time(len));
    }
    times
}

/// Duration and distance of a jerk-limited speed change between `v0` and `v1`.
fn transition(v0: f64, v1: f64, m: &MachineLimits) -> (f64, f64) {
    let dv = (v1 - v0).abs();
    let t = if dv * m.jerk <= m.acceleration * m.acceleration {
        2.0 * (dv / m.jerk).sqrt()
    } else {
        dv / m.acceleration + m.acceleration / m.jerk
    };
    (t, 0.5 * (v0 + v1) * t)
}

/// The highest speed `<= vmax` reachable from `v0` within `length`.
fn reach(v0: f64, length: f64, vmax: f64, m: &MachineLimits) -> f64 {
    if v0 >= vmax || transition(v0, vmax, m).1 <= length {
        return vmax.max(v0).min(vmax);
    }
    let (mut lo, mut hi) = (v0, vmax);
    for _ in 0..tol::VELOCITY_ITERATIONS {
        let mid = 0.5 * (lo + hi);
        if transition(v0, mid, m).1 <= length {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// Time of one segment entered at `v0`, left at `v1`, with speed limit `vmax`.
#[cfg(test)]
fn segment_time(v0: f64, v1: f64, length: f64, vmax: f64, m: &MachineLimits) -> f64 {
    segment_profile(v0, v1, length, vmax, m).0
}

/// Time and peak speed of one segment entered at `v0`, left at `v1`, with speed limit `vmax`.
fn segment_profile(v0: f64, v1: f64, length: f64, vmax: f64, m: &MachineLimits) -> (f64, f64) {
    let used = |vp: f64| transition(v0, vp, m).1 + transition(vp, v1, m).1;
    let base = v0.max(v1);
    let peak = if used(vmax) <= length {
        vmax
    } else {
        let (mut lo, mut hi) = (base, vmax);
        for _ in 0..tol::VELOCITY_ITERATIONS {
            let mid = 0.5 * (lo + hi);
            if used(mid) <= length {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    };
    if peak <= 0.0 {
        return (0.0, 0.0);
    }
    let cruise = (length - used(peak)).max(0.0) / peak;
    (transition(v0, peak, m).0 + transition(peak, v1, m).0 + cruise, peak)
}

/// Model (b): look-ahead jerk-limited feed profile with corner blending
/// tolerance [`FinishingParams::blend_tolerance`] (see the module docs).
///
/// ```
/// # use scallop_strategy::{lookahead_time, stop_to_stop_time, FinishingParams, Pattern, Boundary};
/// # use scallop_toolpath::{Move, MoveKind, Toolpath};
/// # use scallop_geom::Point3;
/// # use scallop_analysis::MachineLimits;
/// # let params = FinishingParams { direction: 0.0, pattern: Pattern::Zigzag, scallop_height: 0.01,
/// #     boundary: Boundary::ContactInside, max_step: 0.5, clearance: 5.0, machine: MachineLimits::default(),
/// #     plunge_feed: 20.0, rapid_rate: 500.0, sharp_corner: 0.5, blend_tolerance: 0.01 };
/// let mut path = Toolpath::new(5000.0);
/// for (x, y) in [(0.0, 0.0), (20.0, 0.0), (20.0, 1.0), (0.0, 1.0)] {
///     path.push(Move::new(MoveKind::Feed, Point3::new(x, y, 0.0)));
/// }
/// let (a, b) = (stop_to_stop_time(&path, &params), lookahead_time(&path, &params));
/// assert!(b.cutting < a.cutting); // blended corners need no full stop
/// ```
#[must_use]
pub fn lookahead_time(path: &Toolpath, params: &FinishingParams) -> ClassTimes {
    let mut times = ClassTimes::default();
    for (m, p) in path.moves().iter().zip(lookahead_profile(path, params)) {
        times.add(class(m.kind), p.duration);
    }
    times
}

/// The feed of one move in the look-ahead model (b): entry, exit and peak
/// speed and the move's duration (mm/s, s).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct MoveFeed {
    /// Speed entering the move (mm/s).
    pub entry: f64,
    /// Speed leaving the move (mm/s).
    pub exit: f64,
    /// Highest speed reached on the move (mm/s).
    pub peak: f64,
    /// Duration of the move (s); 0 for the first move and for moves without length.
    pub duration: f64,
}

/// Model (b) move by move: one [`MoveFeed`] per move of `path` (the first move,
/// which has no start, and moves without length get zeros). The durations sum,
/// per class, to [`lookahead_time`]; a report plots the achieved feed from it.
#[must_use]
pub fn lookahead_profile(path: &Toolpath, params: &FinishingParams) -> Vec<MoveFeed> {
    let moves = path.moves();
    let mut out = vec![MoveFeed::default(); moves.len()];
    // (move index, segment) for the moves with a length.
    let segs = segments(path, params);
    let n = segs.len();
    if n == 0 {
        return out;
    }
    let lims: Vec<MachineLimits> = segs
        .iter()
        .map(|(_, s)| {
            let l = limits(params, s.class);
            MachineLimits { feed: l.feed.min(s.cap), ..l }
        })
        .collect();
    let a_max = params.machine.acceleration;
    let mut v = vec![0.0f64; n + 1];
    for i in 1..n {
        let (p, q) = (&segs[i - 1].1, &segs[i].1);
        if p.class != q.class {
            continue;
        }
        let cos_phi = p.dir_out.dot(&q.dir_in).clamp(-1.0, 1.0);
        let cos_half = (0.5 * (1.0 + cos_phi)).sqrt(); // cos(phi / 2)
        let cap = lims[i - 1].feed.min(lims[i].feed);
        v[i] = if 1.0 - cos_half <= 0.0 {
            cap
        } else {
            (a_max * params.blend_tolerance * cos_half / (1.0 - cos_half)).sqrt().min(cap)
        };
    }
    for i in 0..n {
        v[i + 1] = v[i + 1].min(reach(v[i], segs[i].1.length, lims[i].feed, &lims[i]));
    }
    for i in (0..n).rev() {
        v[i] = v[i].min(reach(v[i + 1], segs[i].1.length, lims[i].feed, &lims[i]));
    }
    for (i, (k, s)) in segs.iter().enumerate() {
        let (duration, peak) = segment_profile(v[i], v[i + 1], s.length, lims[i].feed, &lims[i]);
        out[*k] = MoveFeed { entry: v[i], exit: v[i + 1], peak, duration };
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Boundary, Pattern};
    use scallop_geom::{Point2, Point3};
    use scallop_toolpath::{ArcXY, Move};

    fn params() -> FinishingParams {
        FinishingParams {
            direction: 0.0,
            pattern: Pattern::Zigzag,
            scallop_height: 0.01,
            boundary: Boundary::ContactInside,
            max_step: 0.5,
            clearance: 5.0,
            machine: MachineLimits::default(),
            plunge_feed: 20.0,
            rapid_rate: 500.0,
            sharp_corner: 0.5,
            blend_tolerance: 0.01,
        }
    }

    /// A circle of radius `rho` about the origin from (rho, 0): `quarters`
    /// quarter arcs, or (`arcs` false) `chords` equal chords per quarter.
    fn circle(rho: f64, arcs: bool, chords: usize) -> Toolpath {
        let mut path = Toolpath::new(5000.0);
        path.push(Move::new(MoveKind::Feed, Point3::new(rho, 0.0, 0.0)));
        let at = |a: f64| Point3::new(rho * a.cos(), rho * a.sin(), 0.0);
        for q in 1..=4 {
            let a = std::f64::consts::FRAC_PI_2 * f64::from(q);
            if arcs {
                let arc = ArcXY { center: Point2::origin(), sweep: std::f64::consts::FRAC_PI_2 };
                path.push_arc(Move::new(MoveKind::Feed, at(a)), arc);
            } else {
                for c in 1..=chords {
                    #[allow(clippy::cast_precision_loss, reason = "a small count")]
                    let t = a - std::f64::consts::FRAC_PI_2 * (1.0 - c as f64 / chords as f64);
                    path.push(Move::new(MoveKind::Feed, at(t)));
                }
            }
        }
        path
    }

    /// Analytic: four quarter arcs of a circle whose curvature allows the
    /// feed take the time of one straight move of the circle's length (the
    /// tangents agree at every junction, the speed changes fit in the first
    /// and last quarters); the same circle as short chords takes longer; on a
    /// circle too tight for the feed the tool runs at `sqrt(A rho)` at most.
    #[test]
    fn arcs_are_timed_by_their_length_tangents_and_curvature() {
        let p = params();
        let rho = 10.0;
        let length = std::f64::consts::TAU * rho;
        let arcs = lookahead_time(&circle(rho, true, 0), &p).cutting;
        let line = p.machine.segment_time(length);
        assert!((arcs - line).abs() <= 1e-9 * line, "{arcs} s for four arcs, {line} s for a line");
        let chords = lookahead_time(&circle(rho, false, 80), &p).cutting;
        assert!(chords > arcs * 1.05, "{chords} s for chords against {arcs} s");
        assert!((stop_to_stop_time(&circle(rho, true, 0), &p).cutting - line).abs() <= 1e-9 * line);
        let tight = 0.5;
        let cap = (p.machine.acceleration * tight).sqrt();
        assert!(cap < p.machine.feed);
        let t = lookahead_time(&circle(tight, true, 0), &p).cutting;
        assert!(t >= std::f64::consts::TAU * tight / cap, "{t} s on a circle of {tight} mm");
        // A fillet of 0.1 mm turning 1.4 degrees between two straight moves
        // is timed as the corner it rounds (blended at full feed), not at
        // the speed a whole circle of 0.1 mm would allow.
        let turn = 1.4f64.to_radians();
        let mut filleted = Toolpath::new(5000.0);
        filleted.push(Move::new(MoveKind::Feed, Point3::new(-30.0, 0.1, 0.0)));
        filleted.push(Move::new(MoveKind::Feed, Point3::new(0.0, 0.1, 0.0)));
        let end = Point3::new(0.1 * turn.sin(), 0.1 * turn.cos(), 0.0);
        filleted.push_arc(Move::new(MoveKind::Feed, end), ArcXY { center: Point2::origin(), sweep: -turn });
        filleted
            .push(Move::new(MoveKind::Feed, end + scallop_geom::Vec3::new(30.0 * turn.cos(), -30.0 * turn.sin(), 0.0)));
        let corner = lookahead_time(&filleted, &p).cutting;
        let straight = p.machine.segment_time(60.0);
        assert!(corner <= straight * 1.001, "{corner} s for a filleted corner, {straight} s straight");
    }

    /// With zero entry and exit speeds the look-ahead segment time equals the
    /// spec's stop-to-stop S-curve in all four cases.
    #[test]
    fn stopped_segment_matches_s_curve() {
        for m in [MachineLimits::default(), MachineLimits::from_thesis_units(30.0, 2.0, 40.0)] {
            for length in [0.01, 0.5, 3.0, 7.0, 7.7, 20.0, 200.0, 2000.0] {
                let a = m.segment_time(length);
                let b = segment_time(0.0, 0.0, length, m.feed, &m);
                assert!((a - b).abs() <= 1e-9 * a, "{length}: {a} vs {b}");
            }
        }
    }
}
