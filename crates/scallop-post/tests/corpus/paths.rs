//! Generated 5-axis paths of issue 19 (part-frame CL records for the LinuxCNC
//! `xyzac-trt` trunnion), shared by `tests/five_axis_corpus.rs` and the
//! `post_corpus` example that `bench/linuxcnc/rs274.sh` feeds to LinuxCNC's `rs274`.

#![allow(dead_code, reason = "each user takes the paths it needs")]

use scallop_geom::{Point3, Vec3};
use scallop_machine::program::{ClRecord, Motion};
use scallop_machine::{Kinematics, Machine, Pose};

/// The trunnion with a C stroke of +-200 deg (instead of +-36000): every full circle of
/// [`windings`] needs its own winding.
#[must_use]
pub fn short_c_trunnion() -> Machine {
    let text = include_str!("../../../../machines/linuxcnc-xyzac-trt.toml")
        .replace("limits = [-36000, 36000]", "limits = [-200, 200]");
    Machine::from_toml_str(&text).expect("machine")
}

/// A named path generator.
pub type Case = (&'static str, fn() -> Vec<ClRecord>);

/// The minimal cases by name (the files of the issue, generated).
pub const CASES: [Case; 5] = [
    ("same-tip", same_tip),
    ("same-tip-feed", same_tip_feed),
    ("near-pole-cut", near_pole_cut),
    ("big-reorient-cut", big_reorient_cut),
    ("link-flip", link_flip),
];

/// Unit tool axis `tilt` degrees from +Z towards the azimuth `azimuth` (deg, from +X).
pub fn axis(tilt: f64, azimuth: f64) -> Vec3 {
    let (t, a) = (tilt.to_radians(), azimuth.to_radians());
    Vec3::new(t.sin() * a.cos(), t.sin() * a.sin(), t.cos())
}

pub fn rec(motion: Motion, tip: [f64; 3], axis: Vec3) -> ClRecord {
    ClRecord { pose: Pose::new(Point3::new(tip[0], tip[1], tip[2]), axis), motion, feed: 600.0 }
}

/// Two records with one tip on a rapid, then a plunge.
pub fn same_tip() -> Vec<ClRecord> {
    vec![
        rec(Motion::Rapid, [10.0, 0.0, 5.0], axis(30.0, -90.0)),
        rec(Motion::Rapid, [10.0, 0.0, 5.0], Vec3::z()),
        rec(Motion::Feed, [10.0, 0.0, 0.0], Vec3::z()),
    ]
}

/// A 7 degree reorientation in place while cutting.
pub fn same_tip_feed() -> Vec<ClRecord> {
    vec![
        rec(Motion::Rapid, [10.0, 0.0, 5.0], axis(30.0, -90.0)),
        rec(Motion::Feed, [10.0, 0.0, 0.0], axis(30.0, -90.0)),
        rec(Motion::Feed, [10.0, 0.0, 0.0], axis(37.0, -90.0)),
        rec(Motion::Feed, [12.0, 0.0, 0.0], axis(37.0, -90.0)),
    ]
}

/// Near the pole: the axis turns 7 deg over 0.5 mm, C about 40 deg.
pub fn near_pole_cut() -> Vec<ClRecord> {
    vec![
        rec(Motion::Rapid, [0.0, 0.0, 5.0], axis(5.0, -65.0)),
        rec(Motion::Feed, [0.0, 0.0, 0.0], axis(5.0, -65.0)),
        rec(Motion::Feed, [0.5, 0.0, 0.0], axis(10.0, -105.0)),
    ]
}

/// A genuine reorientation of 47 deg over 10 mm while cutting (C turns 50 deg).
pub fn big_reorient_cut() -> Vec<ClRecord> {
    vec![
        rec(Motion::Rapid, [0.0, 0.0, 5.0], axis(69.0, -53.0)),
        rec(Motion::Feed, [0.0, 0.0, 0.0], axis(69.0, -53.0)),
        rec(Motion::Feed, [6.0, -8.0, 0.0], axis(72.0, -3.0)),
    ]
}

/// A link on which the best way on changes branch.
pub fn link_flip() -> Vec<ClRecord> {
    vec![
        rec(Motion::Rapid, [0.0, 0.0, 10.0], Vec3::z()),
        rec(Motion::Rapid, [0.0, 0.0, 5.0], axis(5.0, 90.0)),
        rec(Motion::Feed, [0.0, 0.0, 0.0], axis(5.0, 90.0)),
        rec(Motion::Feed, [10.0, 0.0, 0.0], axis(5.0, 90.0)),
        rec(Motion::Link, [10.0, 0.0, 1.0], axis(45.0, 90.0)),
        rec(Motion::Feed, [10.0, 0.0, 0.0], axis(60.0, 90.0)),
        rec(Motion::Feed, [0.0, 0.0, 0.0], axis(60.0, 90.0)),
    ]
}

/// A swarf-cut impeller-like channel: five blades around the C axis, each cut along its
/// hub line with the tool leaning 40 to 55 deg against the blade and twisting, retracted
/// along the tool axis, reoriented in place to the next blade's axis, and approached.
pub fn impeller() -> Vec<ClRecord> {
    let blades = 5;
    let clearance = 15.0;
    let mut r = Vec::new();
    for k in 0..blades {
        let theta = 72.0 * f64::from(k);
        let at = |s: f64| {
            let radius = 12.0 + 18.0 * s;
            let (c, sn) = (theta.to_radians().cos(), theta.to_radians().sin());
            let tip = Point3::new(radius * c, radius * sn, 8.0 - 6.0 * s);
            (tip, axis(40.0 + 15.0 * s, theta + 90.0 - 10.0 + 25.0 * s))
        };
        let (start, a0) = at(0.0);
        let above = start + a0 * clearance;
        if let Some(last) = r.last().copied() {
            let last: ClRecord = last;
            // In place: the previous retract point, the next blade's axis.
            r.push(ClRecord { pose: Pose::new(last.pose.tip, a0), motion: Motion::Rapid, feed: 600.0 });
        }
        r.push(rec(Motion::Rapid, [above.x, above.y, above.z], a0));
        r.push(rec(Motion::Plunge, [start.x, start.y, start.z], a0));
        for i in 1..=20 {
            let (tip, a) = at(f64::from(i) / 20.0);
            r.push(rec(Motion::Feed, [tip.x, tip.y, tip.z], a));
        }
        let (end, a1) = at(1.0);
        let up = end + a1 * clearance;
        r.push(rec(Motion::Rapid, [up.x, up.y, up.z], a1));
    }
    r
}

/// A hull-like surface `z = 5 + 0.01 x^2 - 0.006 y^2` finished in zigzag rows along X with
/// the tool along the surface normal: the row y = 0 crosses the pole, the rows y = +-3 pass
/// 2 deg from it (C turns half a turn in a few mm).
pub fn hull() -> Vec<ClRecord> {
    let surface = |x: f64, y: f64| {
        let n = Vec3::new(-0.02 * x, 0.012 * y, 1.0).normalize();
        (Point3::new(x, y, 5.0 + 0.01 * x * x - 0.006 * y * y), n)
    };
    let mut r = Vec::new();
    for (row, y) in [-6.0, -3.0, 0.0, 3.0, 6.0].into_iter().enumerate() {
        let xs: Vec<f64> = (-30..=30).map(f64::from).collect();
        let xs: Vec<f64> = if row % 2 == 0 { xs } else { xs.into_iter().rev().collect() };
        for (i, x) in xs.iter().enumerate() {
            let (tip, n) = surface(*x, y);
            let motion = match (row, i) {
                (0, 0) => {
                    let above = tip + n * 10.0;
                    r.push(rec(Motion::Rapid, [above.x, above.y, above.z], n));
                    Motion::Plunge
                }
                (_, 0) => Motion::Link,
                _ => Motion::Feed,
            };
            r.push(rec(motion, [tip.x, tip.y, tip.z], n));
        }
    }
    r
}

/// `passes` full circles of the tip (radius 20) with the tool tilted 20 deg outwards, all
/// turning the same way, each left and re-entered by rapids along the tool axis.
/// The circles start where C is at half a turn, so that one turn fits a stroke of +-200 deg.
pub fn windings(kin: &Kinematics, passes: usize) -> Vec<ClRecord> {
    // C as a function of the azimuth of the tool axis: C(az) = C(0) + sign az.
    let c_at = |az: f64| {
        let pose = Pose::new(Point3::new(0.0, 0.0, 5.0), axis(20.0, az));
        let sols = kin.ik(&pose, &scallop_machine::Joints::zeros()).expect("reachable");
        let q = sols.as_slice().iter().find(|s| s.joints[kin.tilt_axis()] < 0.0).expect("A < 0").joints;
        q[kin.pole_axis()].to_degrees()
    };
    let c0 = c_at(0.0);
    let sign = ((c_at(10.0) - c0 + 540.0).rem_euclid(360.0) - 180.0).signum();
    let start = (180.0 - c0) * sign;
    let mut r = Vec::new();
    for _ in 0..passes {
        let at = |deg: f64| {
            let t = (start + deg).to_radians();
            (Point3::new(20.0 * t.cos(), 20.0 * t.sin(), 5.0), axis(20.0, start + deg))
        };
        let (start, a0) = at(0.0);
        let above = start + a0 * 10.0;
        r.push(rec(Motion::Rapid, [above.x, above.y, above.z], a0));
        r.push(rec(Motion::Plunge, [start.x, start.y, start.z], a0));
        for i in 1..=72 {
            let (tip, a) = at(5.0 * f64::from(i));
            r.push(rec(Motion::Feed, [tip.x, tip.y, tip.z], a));
        }
        r.push(rec(Motion::Rapid, [above.x, above.y, above.z], a0));
    }
    r
}

/// Passes along X alternately leaning 70 deg towards +Y and -Y: A reaches 70 deg only on
/// its negative side, so C must turn half a turn between passes, on the links.
pub fn alternating(passes: usize) -> Vec<ClRecord> {
    let mut r = vec![rec(Motion::Rapid, [-10.0, 0.0, 15.0], axis(70.0, 90.0))];
    for p in 0..passes {
        let a = axis(70.0, if p % 2 == 0 { 90.0 } else { -90.0 });
        let y = 4.0 * f64::from(u32::try_from(p).unwrap_or(0));
        r.push(rec(if p == 0 { Motion::Plunge } else { Motion::Link }, [-10.0, y, 2.0], a));
        for i in 1..=10 {
            r.push(rec(Motion::Feed, [-10.0 + 2.0 * f64::from(i), y, 2.0], a));
        }
        r.push(rec(Motion::Link, [10.0, y, 4.0], a));
    }
    r
}
