//! Entries (docs/rough5.md, "Entries"): a helix never leaves the pass's
//! loop, never goes below the level and descends at the ramp angle; it fits
//! a circular loop exactly when its circle does; a side entry starts outside
//! the stock at the pass start's height and never goes below the level; and
//! the programs entered this way prove themselves on a tri-dexel stock.

#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

mod common;

use proptest::prelude::*;
use scallop_geom::{Aabb3, Point3, Vec3};
use scallop_mesh::TriMesh;
use scallop_parts::{FaceTag, closed_pocket};
use scallop_rough5::{
    BodyCheck, EntryMode, HELIX_TANGENCY, HelixSettings, Placer, ProofSettings, Rough5Settings, helix_entry,
    plan_rough5, prove, side_entry, tool_frame,
};

/// A vertical wall x = `x` over y in [-100, 100], z in [-10, 60].
fn wall(x: f64) -> TriMesh {
    let p = Point3::new;
    let (m, _) = TriMesh::from_soup(&[
        [p(x, -100., -10.), p(x, 100., -10.), p(x, 100., 60.)],
        [p(x, -100., -10.), p(x, 100., 60.), p(x, -100., 60.)],
    ])
    .unwrap();
    m
}

/// The axis tilted by `tilt` towards the azimuth `azimuth` (rad).
fn axis(tilt: f64, azimuth: f64) -> Vec3 {
    Vec3::new(tilt.sin() * azimuth.cos(), tilt.sin() * azimuth.sin(), tilt.cos())
}

/// The tips of the tool placed along `u` on `placer`'s level under a loop
/// of guide points: a rounded rectangle `a` x `b` of corner radius `c`
/// centred on the origin at z = 20, counter-clockwise, points at most
/// 0.5 mm apart on the corners and 1 mm on the sides, closed (the last equal
/// to the first).
fn loop_tips(placer: &Placer, u: &Vec3, (a, b, c): (f64, f64, f64)) -> Vec<Point3> {
    let (hx, hy) = (a / 2.0 - c, b / 2.0 - c);
    let centres = [(hx, hy), (-hx, hy), (-hx, -hy), (hx, -hy)];
    let quarter = std::f64::consts::FRAC_PI_2;
    let on = |k: usize, t: f64| (centres[k].0 + c * t.cos(), centres[k].1 + c * t.sin());
    let mut guides = Vec::new();
    for k in 0..4 {
        let t0 = quarter * k as f64;
        let arc = (c * quarter / 0.5).ceil() as usize;
        guides.extend((0..arc).map(|j| on(k, t0 + quarter * j as f64 / arc as f64)));
        // The straight side to the next corner.
        let (from, to) = (on(k, t0 + quarter), on((k + 1) % 4, t0 + quarter));
        let m = (to.0 - from.0).hypot(to.1 - from.1).ceil().max(1.0) as usize;
        guides.extend((0..m).map(|j| {
            let w = j as f64 / m as f64;
            (from.0 + (to.0 - from.0) * w, from.1 + (to.1 - from.1) * w)
        }));
    }
    let mut tips: Vec<Point3> =
        guides.iter().map(|&(x, y)| placer.place(&Point3::new(x, y, 20.0), u).unwrap().tip).collect();
    tips.push(tips[0]);
    tips
}

/// Whether `p` lies inside the polygon of `loop_` (closed) projected on the
/// plane normal to `u`, or within `tol` of its edges.
fn inside_projected(loop_: &[Point3], u: &Vec3, p: &Point3, tol: f64) -> bool {
    let (e1, e2) = tool_frame(u);
    let flat = |q: &Point3| (q.coords.dot(&e1), q.coords.dot(&e2));
    let (x, y) = flat(p);
    let mut inside = false;
    let mut near = f64::INFINITY;
    for w in loop_.windows(2) {
        let (a, b) = (flat(&w[0]), flat(&w[1]));
        if (a.1 > y) != (b.1 > y) && a.0 + (y - a.1) / (b.1 - a.1) * (b.0 - a.0) > x {
            inside = !inside;
        }
        let d = (b.0 - a.0, b.1 - a.1);
        let l2 = d.0 * d.0 + d.1 * d.1;
        let t = if l2 > 0.0 { (((x - a.0) * d.0 + (y - a.1) * d.1) / l2).clamp(0.0, 1.0) } else { 0.0 };
        near = near.min((x - a.0 - t * d.0).hypot(y - a.1 - t * d.1));
    }
    inside || near <= tol
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// On a plane, along any axis up to 15 deg: the helix's tool-centre
    /// circle stays inside the pass's loop, its tool never goes below the
    /// tool placed on the level, it ends on the pass start, starts `lift`
    /// above the level and descends by exactly tan(ramp) per mm of its
    /// circle (the level is a plane: its height above the level is linear in
    /// the angle).
    #[test]
    fn a_helix_stays_in_its_loop_and_holds_its_ramp_angle(
        a in 16.0..60.0f64, b in 16.0..60.0f64, c in 2.0..7.9f64,
        tilt in 0.0..0.26f64, azimuth in 0.0..std::f64::consts::TAU,
        start_at in 0.0..1.0f64, lift in 0.5..9.0f64, which in 0usize..3, ramp_deg in 2.0..10.0f64,
    ) {
        let tool = common::torus(30.0, 100.0);
        let placer = Placer::new(&common::floor(), &tool, 0.0).unwrap();
        let body = BodyCheck::new(&wall(500.0), &tool, 0.0);
        let u = axis(tilt, azimuth);
        let tips = loop_tips(&placer, &u, (a, b, c));
        let start = ((tips.len() - 1) as f64 * start_at) as usize;
        let radius = scallop_rough5::HELIX_RADII[which] * 5.0;
        let h = HelixSettings { radius, ramp_angle: ramp_deg.to_radians(), step: 1.0 };
        let helix = helix_entry(&placer, &body, (&tips, start), &u, lift, &h);
        // The loop's corners, seen along an axis tilted by at most 15 deg,
        // curve by at most 1 / (c cos^2 15 deg): a helix of a smaller radius
        // fits wherever it starts.
        if radius <= 0.9 * c - 0.3 {
            prop_assert!(helix.is_some(), "no helix of radius {radius} in a loop with corners of {c}");
        }
        let Some(helix) = helix else { return Ok(()) };
        prop_assert!((helix[helix.len() - 1] - tips[start]).norm() < 1e-9);
        let height = |p: &Point3| (p - placer.place(p, &u).unwrap().tip).dot(&u);
        prop_assert!((height(&helix[0]) - lift).abs() < 1e-6, "starts {} above the level", height(&helix[0]));
        let (e1, e2) = tool_frame(&u);
        let mut arc = 0.0;
        for (k, p) in helix.iter().enumerate() {
            prop_assert!(height(p) >= -1e-9, "point {k} is {} below the level", -height(p));
            prop_assert!(inside_projected(&tips, &u, p, HELIX_TANGENCY + 1e-9), "point {k} leaves the loop");
            prop_assert!(!body.collides(p, &u));
            if k > 0 {
                let d = p - helix[k - 1];
                let chord = (d.dot(&e1)).hypot(d.dot(&e2));
                // The chord of an arc of the circle: at most the arc.
                let fall = height(&helix[k - 1]) - height(p);
                prop_assert!(fall >= -1e-9, "point {k} climbs");
                let step_angle = 2.0 * (chord / (2.0 * radius)).min(1.0).asin();
                arc += step_angle * radius;
                prop_assert!((fall - step_angle * radius * h.ramp_angle.tan()).abs() < 1e-6, "point {k}: falls {fall}");
            }
        }
        prop_assert!((arc * h.ramp_angle.tan() - lift).abs() < 1e-6);
    }

    /// A helix fits a circular pass of radius rho (tool tips on a plane,
    /// axis +Z) exactly when its own radius is at most rho (within the
    /// tangency tolerance and the polygon's sagitta).
    #[test]
    fn a_helix_fits_a_circle_when_its_radius_does(rho in 2.0..12.0f64, radius in 0.5..12.0f64) {
        let tool = common::torus(30.0, 100.0);
        let placer = Placer::new(&common::floor(), &tool, 0.0).unwrap();
        let body = BodyCheck::new(&wall(500.0), &tool, 0.0);
        let n = 720;
        let mut tips: Vec<Point3> = (0..n).map(|k| {
            let t = std::f64::consts::TAU * k as f64 / n as f64;
            Point3::new(rho * t.cos(), rho * t.sin(), 0.0)
        }).collect();
        tips.push(tips[0]);
        let h = HelixSettings { radius, ramp_angle: 5f64.to_radians(), step: 1.0 };
        let helix = helix_entry(&placer, &body, (&tips, 0), &Vec3::z(), 2.0, &h);
        let sagitta = rho * (1.0 - (std::f64::consts::PI / n as f64).cos());
        if radius < rho - sagitta {
            prop_assert!(helix.is_some());
        } else if radius > rho + HELIX_TANGENCY + 1e-9 {
            prop_assert!(helix.is_none());
        }
    }

    /// A side entry from a pass start inside a box, within reach of its side:
    /// it starts where the whole tool is at least 1 mm outside the box, at
    /// the pass start's height, and the approach never goes below the level.
    #[test]
    fn a_side_entry_starts_outside_the_stock_at_the_level(
        half in 20.0..40.0f64, into in 0.5..12.0f64, y in -0.9..0.9f64, side in 0usize..4,
    ) {
        let tool = common::torus(30.0, 100.0);
        let placer = Placer::new(&common::floor(), &tool, 0.0).unwrap();
        let body = BodyCheck::new(&wall(500.0), &tool, 0.0);
        let stock = Aabb3 { min: Point3::new(-half, -half, -10.0), max: Point3::new(half, half, 10.0) };
        // `into` mm inside one side, `y` of the way along it.
        let (along, across) = (half - into, y * half);
        let start = match side {
            0 => Point3::new(along, across, 0.0),
            1 => Point3::new(-along, across, 0.0),
            2 => Point3::new(across, along, 0.0),
            _ => Point3::new(across, -along, 0.0),
        };
        let start = placer.place(&Point3::new(start.x, start.y, 20.0), &Vec3::z()).unwrap().tip;
        let outside = |p: &Point3, _: &Vec3| {
            let dx = (stock.min.x - p.x).max(p.x - stock.max.x).max(0.0);
            let dy = (stock.min.y - p.y).max(p.y - stock.max.y).max(0.0);
            dx.hypot(dy) >= 5.0 + 1.0
        };
        let from = side_entry(&placer, &body, &outside, (&start, &Vec3::z()), None, 1.0, 20.0, 30.0);
        let from = from.unwrap();
        prop_assert!(outside(&from, &Vec3::z()));
        prop_assert!((from.z - start.z).abs() < 1e-12);
        // The nearest side: within half a step of the shortest approach.
        prop_assert!((from - start).norm() <= into + 6.0 + 0.5 + 1e-9, "{from:?} from {start:?}");
        for k in 0..=100 {
            let p = start + (from - start) * (k as f64 / 100.0);
            let floor = placer.place(&p, &Vec3::z()).unwrap().tip;
            prop_assert!(p.z >= floor.z - 1e-9);
        }
    }
}

/// A flank between the pass start and the stock's side stops the side entry
/// that way; none is left within reach, so there is none.
#[test]
fn a_flank_in_the_way_stops_a_side_entry() {
    let tool = common::torus(30.0, 100.0);
    let placer = Placer::new(&common::floor(), &tool, 0.0).unwrap();
    let stock = Aabb3 { min: Point3::new(-30.0, -30.0, -10.0), max: Point3::new(30.0, 30.0, 10.0) };
    let outside = |p: &Point3, _: &Vec3| {
        let dx = (stock.min.x - p.x).max(p.x - stock.max.x).max(0.0);
        let dy = (stock.min.y - p.y).max(p.y - stock.max.y).max(0.0);
        dx.hypot(dy) >= 6.0
    };
    let start = Point3::new(25.0, 0.0, 0.0);
    let free = BodyCheck::new(&wall(500.0), &tool, 0.0);
    let from = side_entry(&placer, &free, &outside, (&start, &Vec3::z()), None, 1.0, 20.0, 30.0).unwrap();
    assert!((from.x - 36.0).abs() <= 0.5 + 1e-9 && from.y.abs() < 1e-9, "{from:?}");
    let walled = BodyCheck::new(&wall(32.0), &tool, 0.0);
    assert_eq!(side_entry(&placer, &walled, &outside, (&start, &Vec3::z()), None, 1.0, 20.0, 30.0), None);
}

/// The closed pocket entered by helices (`EntryMode::Auto`): helices where
/// they fit, ramps elsewhere, no plunge, and the program proven on the
/// tri-dexel stock (no rapid into stock, no shank or holder collision:
/// errors of `prove`) with no gouge.
#[test]
fn the_closed_pocket_is_entered_by_helices_and_proves_itself() {
    let part = closed_pocket(&Default::default()).unwrap();
    let bottom = part.faces(&[FaceTag::Bottom]).unwrap();
    let flanks = part.faces(&[FaceTag::Flank]).unwrap();
    let (_, _, depth) = common::bottom_flanks(&part);
    let tool = common::torus(30.0, 100.0);
    let proof_settings = ProofSettings { resolution: 1.0, axis_tolerance: 0.05 };
    let s = Rough5Settings { entry: EntryMode::Auto, ..common::settings(depth) };
    let plan = plan_rough5(&bottom, &flanks, &part.stock, &tool, &s, &|_, _| {}).unwrap();
    let e = plan.entries;
    assert!(e.helix > 0 && e.side == 0, "{e:?}");
    assert_eq!(e.plunge, 0, "{e:?} at {:?}", plan.plunged_at);
    assert_eq!(e.ramp, plan.ramps);
    let proof = prove(&plan.toolpath, &tool, &part.stock, &part.mesh, &proof_settings, &|_, _| {}).unwrap();
    assert!(proof.gouge_depth <= proof_settings.axis_tolerance, "{proof:?}");
    assert!(proof.remaining_percent < 10.0, "{proof:?}");
}
