//! The guide-curve builder on the three test parts (Jousselin 2020: the
//! closed pocket with drafts and undercuts of Ch. 2 §4, the fitting's
//! non-convex pocket with ribs of Ch. 4 §3, the impeller channel, an open
//! pocket, of Ch. 4 §2) and on two synthetic pockets, one per mechanism: a
//! dumbbell whose offsets split into two degeneracy zones (Ch. 2 §3.3) and a
//! U channel open on one side, closed by a virtual flank (Ch. 4 §1.3.1).
//! Every level must have one closed limit loop, closed path curves that do
//! not cross themselves (in plan view, and in the plane across the curve's
//! mean normal), and every degeneracy zone of every level must be paired
//! with the level above.
#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

use std::f64::consts::PI;

use scallop_geom::{Point3, Vec3};
use scallop_guides::{Curve, GuideSet, GuideSettings, Support, bottom_level, build_guides, limit_curves};
use scallop_mesh::TriMesh;
use scallop_parts::{FaceTag, TestPart, closed_pocket, fitting_pocket, impeller_channel};

/// Whether two segments of the closed polygon `p` cross (brute force).
fn crosses_itself_2d(p: &[[f64; 2]]) -> bool {
    let n = p.len();
    let orient = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    for i in 0..n {
        for j in i + 2..n {
            if i == 0 && j == n - 1 {
                continue;
            }
            let (a, b, c, d) = (p[i], p[(i + 1) % n], p[j], p[(j + 1) % n]);
            let (o1, o2, o3, o4) = (orient(a, b, c), orient(a, b, d), orient(c, d, a), orient(c, d, b));
            if o1 * o2 < 0.0 && o3 * o4 < 0.0 {
                return true;
            }
        }
    }
    false
}

/// Whether a closed curve crosses itself in plan view or in the plane
/// across its mean normal (the level, locally).
fn crosses_itself(c: &Curve) -> bool {
    let plan: Vec<[f64; 2]> = c.line.points.iter().map(|q| [q.x, q.y]).collect();
    let n: Vec3 = c.normals.iter().sum::<Vec3>().normalize();
    let u = if n.x.abs() < 0.9 { Vec3::x() } else { Vec3::y() };
    let e1 = n.cross(&u).normalize();
    let e2 = n.cross(&e1);
    let local: Vec<[f64; 2]> = c.line.points.iter().map(|q| [q.coords.dot(&e1), q.coords.dot(&e2)]).collect();
    crosses_itself_2d(&plan) || crosses_itself_2d(&local)
}

/// The zones of a level, for failure messages: (parent, first step, offsets,
/// barycentre of the outer curve).
fn zones_of(level: &scallop_guides::GuideLevel) -> Vec<(Option<usize>, usize, usize, [i64; 3])> {
    level
        .zones
        .iter()
        .map(|z| {
            let b = z.outer.line.barycentre().unwrap();
            (z.parent, z.first_step, z.offsets.len(), [b.x as i64, b.y as i64, b.z as i64])
        })
        .collect()
}

/// The checks of the module documentation, on `set` built with `a_e`; with
/// `spacing`, also the largest distance between consecutive paired curves,
/// both ways (a_e plus two voxels). That distance is not the engagement in a
/// tongue of the pocket narrower than 2 a_e, where the inner curves stop
/// short of the tongue's end (the impeller's inlet).
fn check_guides(set: &GuideSet, a_e: f64, voxel: f64, spacing: bool) {
    assert!(!set.levels.is_empty());
    for (k, level) in set.levels.iter().enumerate() {
        assert!(level.closing.is_none(), "level {k}: {:?}", level.closing);
        assert_eq!(level.limit.loops.len(), 1, "level {k}: limit loops");
        assert!(level.limit.loops[0].line.closed && !crosses_itself(&level.limit.loops[0]), "level {k}: limit");
        for step in &level.offsets {
            for c in &step.curves {
                assert!(c.line.closed && !crosses_itself(c), "level {k}: path curve");
            }
        }
        assert!(!level.zones.is_empty(), "level {k}: no zone");
        let in_zones: usize = level.zones.iter().map(|z| 1 + z.offsets.len()).sum();
        let curves: usize = 1 + level.offsets.iter().map(|s| s.curves.len()).sum::<usize>();
        assert_eq!(in_zones, curves, "level {k}: every curve in one zone");
    }
    assert_eq!(set.pairs.len(), set.pair_zones.len());
    for (k, pair) in &set.pairs {
        let zones = || format!("{:?} / {:?}", zones_of(&set.levels[*k]), zones_of(&set.levels[*k + 1]));
        let pair = pair.as_ref().unwrap_or_else(|e| panic!("levels {k} and {}: {e}; zones {}", k + 1, zones()));
        assert_eq!(pair.path.len(), pair.tilt.len(), "levels {k} and {}", k + 1);
        for c in pair.path.iter().chain(&pair.tilt) {
            assert!(c.line.closed && !crosses_itself(c), "levels {k} and {}: paired curve", k + 1);
        }
        assert!(
            !spacing || (pair.path_spacing <= a_e + 2.0 * voxel && pair.tilt_spacing <= a_e + 2.0 * voxel),
            "levels {k} and {}: spacing {} / {}, {} steps, morphed {} / {}; zones {}",
            k + 1,
            pair.path_spacing,
            pair.tilt_spacing,
            pair.steps,
            pair.path_morphed,
            pair.tilt_morphed,
            zones()
        );
    }
    for k in 0..set.levels.len() - 1 {
        let of = |side: usize, zone: usize| {
            set.pairs.iter().zip(&set.pair_zones).any(|((n, _), z)| *n == k && z[side] == Some(zone))
        };
        for z in 0..set.levels[k].zones.len() {
            assert!(of(0, z), "level {k}: zone {z} not paired with the level above");
        }
        for z in 0..set.levels[k + 1].zones.len() {
            assert!(of(1, z), "level {}: zone {z} not paired with the level below", k + 1);
        }
    }
}

fn part_guides(part: &TestPart, settings: &GuideSettings) -> GuideSet {
    let bottom = part.faces(&[FaceTag::Bottom]).unwrap();
    let flanks = part.faces(&[FaceTag::Flank]).unwrap();
    build_guides(&bottom, &flanks, settings).unwrap()
}

/// The guides of `part` for a tool of radius 5 from the stock top down to the
/// bottom face's top.
fn guides_to_the_floor(part: &TestPart) -> GuideSet {
    let depth = part.stock.max.z - part.faces(&[FaceTag::Bottom]).unwrap().bounds().max.z;
    part_guides(part, &settings(5.0, depth))
}

fn settings(tool_radius: f64, depth: f64) -> GuideSettings {
    GuideSettings { tool_radius, flank_allowance: 0.5, axial_step: 4.0, radial_step: 4.5, voxel: 1.0, depth }
}

#[test]
fn the_closed_pocket_has_closed_guide_curves_on_every_level() {
    let set = guides_to_the_floor(&closed_pocket(&Default::default()).unwrap());
    assert!(set.levels.len() >= 4, "{} levels", set.levels.len());
    for level in &set.levels {
        assert_eq!((level.limit.open.len(), level.limit.closed_by_virtual_flanks), (0, 0));
        assert!(!level.offsets.is_empty());
    }
    check_guides(&set, 4.5, 1.0, true);
}

#[test]
fn the_fitting_splits_into_paired_degeneracy_zones_on_every_level() {
    let set = guides_to_the_floor(&fitting_pocket(&Default::default()).unwrap());
    assert!(set.levels.len() >= 4, "{} levels", set.levels.len());
    assert!(set.levels.iter().all(|l| l.zones.len() > 1), "the ribs split the offsets");
    assert!(set.levels.iter().all(|l| !l.offsets.is_empty()));
    check_guides(&set, 4.5, 1.0, true);
}

#[test]
fn the_impeller_channel_is_closed_by_virtual_flanks_on_every_level() {
    let part = impeller_channel(&Default::default()).unwrap();
    // Levels up to the lowest blade tip: the channel is a pocket there.
    let set = part_guides(&part, &settings(3.0, 14.0));
    assert!(set.levels.len() >= 3, "{} levels", set.levels.len());
    for level in &set.levels {
        assert!(!level.limit.open.is_empty() && level.limit.closed_by_virtual_flanks == 1);
    }
    check_guides(&set, 4.5, 1.0, false);
}

/// The impeller's hub itself (the bottom level) is an open pocket too: on
/// the hub alone its limit curves are chains that end on the hub's inlet and
/// outlet edges; extended across those edges, the hub holds one closed loop,
/// closed by the virtual flanks, that reaches both ends of the channel, with
/// offsets inside it. A closed pocket's bottom is not extended.
#[test]
fn the_impeller_hub_is_closed_by_virtual_flanks() {
    let part = impeller_channel(&Default::default()).unwrap();
    let (bottom, flanks) = (part.faces(&[FaceTag::Bottom]).unwrap(), part.faces(&[FaceTag::Flank]).unwrap());
    let s = settings(5.0, 14.0);
    let set = build_guides(&bottom, &flanks, &s).unwrap();
    let own = limit_curves(&Support::new(bottom.clone()), &set.flank_offset);
    assert!(own.loops.is_empty() && !own.open.is_empty());
    let level = bottom_level(&bottom, &flanks, &set.flank_offset, &s).unwrap();
    assert!(level.closing.is_none());
    assert_eq!((level.limit.loops.len(), level.limit.closed_by_virtual_flanks), (1, 1));
    assert!(!level.offsets.is_empty());
    let radii: Vec<f64> = level.limit.loops[0].line.points.iter().map(|p| p.x.hypot(p.y)).collect();
    let (lo, hi) = radii.iter().fold((f64::INFINITY, 0.0f64), |(a, b), &r| (a.min(r), b.max(r)));
    assert!(lo < 25.0 + 1.0 && hi > 75.0 - 1.0, "the loop spans r {lo:.2} to {hi:.2}");
    for p in level.support.mesh().vertices() {
        assert!(p.z >= bottom.bounds().min.z - 1e-9, "the extended hub dips to {p:?}");
    }
    let pocket = closed_pocket(&Default::default()).unwrap();
    let (bottom, flanks) = (pocket.faces(&[FaceTag::Bottom]).unwrap(), pocket.faces(&[FaceTag::Flank]).unwrap());
    let set = build_guides(&bottom, &flanks, &settings(5.0, 4.0)).unwrap();
    let level = bottom_level(&bottom, &flanks, &set.flank_offset, &settings(5.0, 4.0)).unwrap();
    assert_eq!(level.support.mesh().triangles().len(), bottom.triangles().len());
    assert_eq!((level.limit.loops.len(), level.limit.closed_by_virtual_flanks), (1, 0));
}

/// The closed polygon of a dumbbell: lobes of radius `r` centred at
/// `(+-c, 0)` joined by a neck of half-width `w`, counter-clockwise, points
/// about `step` apart.
fn dumbbell(r: f64, c: f64, w: f64, step: f64) -> Vec<[f64; 2]> {
    let a = (w / r).asin();
    let mut out = Vec::new();
    let mut arc = |cx: f64, from: f64, to: f64| {
        let n = ((to - from) * r / step).ceil() as usize;
        for i in 0..n {
            let t = from + (to - from) * i as f64 / n as f64;
            out.push([cx + r * t.cos(), r * t.sin()]);
        }
    };
    arc(c, -PI + a, PI - a);
    arc(-c, a, 2.0 * PI - a);
    out
}

/// Vertical walls over polygon `outline` (closed or not) from `z0` to `z1`,
/// normals on the right of the outline's direction (out of a
/// counter-clockwise pocket), edges split into pieces of about `step`.
fn walls(outline: &[[f64; 2]], closed: bool, z0: f64, z1: f64, step: f64) -> TriMesh {
    let mut pts: Vec<[f64; 2]> = Vec::new();
    let segs = if closed { outline.len() } else { outline.len() - 1 };
    for i in 0..segs {
        let (a, b) = (outline[i], outline[(i + 1) % outline.len()]);
        let n = ((b[0] - a[0]).hypot(b[1] - a[1]) / step).ceil().max(1.0) as usize;
        for k in 0..n {
            let t = k as f64 / n as f64;
            pts.push([a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t]);
        }
    }
    if !closed {
        pts.push(*outline.last().unwrap());
    }
    let rows = ((z1 - z0) / step).ceil() as usize;
    let m = pts.len();
    let v: Vec<Point3> = (0..=rows)
        .flat_map(|j| pts.iter().map(move |q| Point3::new(q[0], q[1], z0 + (z1 - z0) * j as f64 / rows as f64)))
        .collect();
    let cols = if closed { m } else { m - 1 };
    let mut t = Vec::new();
    for j in 0..rows {
        for i in 0..cols {
            let (a, b) = (j * m + i, j * m + (i + 1) % m);
            t.push([a, b, b + m]);
            t.push([a, b + m, a + m]);
        }
    }
    TriMesh::from_indexed(&v, &t).unwrap().0
}

/// The plane z = 0 over `[x0, x1] x [y0, y1]`, normals down (into the part).
fn floor(x0: f64, x1: f64, y0: f64, y1: f64, step: f64) -> TriMesh {
    let (nx, ny) = (((x1 - x0) / step).ceil() as usize, ((y1 - y0) / step).ceil() as usize);
    let v: Vec<Point3> = (0..=ny)
        .flat_map(|j| {
            (0..=nx).map(move |i| {
                Point3::new(x0 + (x1 - x0) * i as f64 / nx as f64, y0 + (y1 - y0) * j as f64 / ny as f64, 0.0)
            })
        })
        .collect();
    let mut t = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let a = j * (nx + 1) + i;
            t.push([a, a + nx + 2, a + 1]);
            t.push([a, a + nx + 1, a + nx + 2]);
        }
    }
    TriMesh::from_indexed(&v, &t).unwrap().0
}

/// The guides of a synthetic pocket: clearance 3 mm (R 2.5, s_f 0.5), a_p 4,
/// a_e 4.5, voxel 0.5, levels at 4, 8 mm.
fn synthetic_guides(bottom: &TriMesh, flanks: &TriMesh) -> GuideSet {
    let s = GuideSettings { voxel: 0.5, depth: 12.0, ..settings(2.5, 0.0) };
    build_guides(bottom, flanks, &s).unwrap()
}

#[test]
fn a_dumbbell_pocket_splits_into_two_paired_zones() {
    // Clearance 3 mm: the limit's neck is 7 mm wide each side of the axis,
    // the first offset's 2.5 mm, the second vanishes there: two branches.
    let outline = dumbbell(20.0, 28.0, 10.0, 1.0);
    let flanks = walls(&outline, true, -1.0, 20.0, 1.0);
    let bottom = floor(-55.0, 55.0, -25.0, 25.0, 2.0);
    let set = synthetic_guides(&bottom, &flanks);
    for (k, level) in set.levels.iter().enumerate() {
        assert_eq!(level.zones.len(), 3, "level {k}: the neck zone and two lobes: {:?}", zones_of(level));
        let lobes: Vec<f64> = level.zones[1..].iter().map(|z| z.outer.line.barycentre().unwrap().x).collect();
        assert!(lobes.iter().any(|&x| x > 20.0) && lobes.iter().any(|&x| x < -20.0), "{lobes:?}");
        assert!(level.zones[1..].iter().all(|z| z.parent == Some(0)));
    }
    assert_eq!(set.pairs.len(), 3 * (set.levels.len() - 1));
    check_guides(&set, 4.5, 0.5, true);
}

#[test]
fn a_u_channel_open_on_one_side_is_closed_by_a_virtual_flank() {
    // Walls at y = +-20 and x = 60; the bottom stops at x = 0, the open side.
    let u = [[0.0, -20.0], [60.0, -20.0], [60.0, 20.0], [0.0, 20.0]];
    let flanks = walls(&u, false, -1.0, 20.0, 1.0);
    let bottom = floor(0.0, 70.0, -30.0, 30.0, 2.0);
    let set = synthetic_guides(&bottom, &flanks);
    for (k, level) in set.levels.iter().enumerate() {
        assert_eq!(level.limit.closed_by_virtual_flanks, 1, "level {k}");
        let b = level.limit.loops[0].line.bounds().unwrap();
        // The virtual flank is crossable: not offset; the walls are, by 3 mm.
        let h = level.support.facet_size();
        assert!(b.min.x.abs() <= h && (b.max.x - 57.0).abs() <= h, "level {k}: {b:?}");
        assert!((b.min.y + 17.0).abs() <= h && (b.max.y - 17.0).abs() <= h, "level {k}: {b:?}");
    }
    check_guides(&set, 4.5, 0.5, true);
}
