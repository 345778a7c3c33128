//! Properties of the test part generators: closed and consistently oriented
//! where they should be, every triangle tagged, every tag used, dimensions
//! from the parameters, deterministic.

use proptest::prelude::*;
use scallop_mesh::{FastMap, TriMesh};
use scallop_parts::{
    FaceTag, FittingParams, ImpellerParams, PartError, PocketParams, TestPart, closed_pocket, fitting_pocket,
    impeller_channel,
};

/// Directed edge counts: (undirected edges used once, edges used other than
/// once in each direction).
fn edge_report(mesh: &TriMesh) -> (Vec<(u32, u32)>, usize) {
    let mut directed: FastMap<(u32, u32), usize> = FastMap::default();
    for t in mesh.triangles() {
        for k in 0..3 {
            *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    let mut open = Vec::new();
    let mut bad = 0;
    for (&(a, b), &c) in &directed {
        let back = directed.get(&(b, a)).copied().unwrap_or(0);
        if c != 1 || back > 1 {
            bad += 1;
        }
        if back == 0 {
            open.push((a, b));
        }
    }
    (open, bad)
}

fn signed_volume(mesh: &TriMesh) -> f64 {
    (0..mesh.triangles().len())
        .map(|t| {
            let [a, b, c] = mesh.triangle(t);
            a.coords.dot(&b.coords.cross(&c.coords)) / 6.0
        })
        .sum()
}

/// Every triangle tagged, every tag used, the mesh inside the stock.
fn check_tags_and_stock(part: &TestPart) {
    assert_eq!(part.tags.len(), part.mesh.triangles().len());
    for tag in [FaceTag::Bottom, FaceTag::Flank, FaceTag::Top] {
        assert!(part.tags.contains(&tag), "{tag:?} missing");
        assert!(part.faces(&[tag]).is_ok());
    }
    let (b, s) = (part.mesh.bounds(), part.stock);
    for k in 0..3 {
        assert!(b.min[k] >= s.min[k] - 1e-9 && b.max[k] <= s.max[k] + 1e-9, "axis {k}: {b:?} outside {s:?}");
    }
}

fn check_closed(part: &TestPart) {
    let (open, bad) = edge_report(&part.mesh);
    assert!(open.is_empty() && bad == 0, "open {} bad {bad}", open.len());
    assert!(signed_volume(&part.mesh) > 0.0, "normals point inwards");
}

#[test]
fn default_pocket_is_closed_tagged_and_fills_the_stock_top() {
    let params = PocketParams::default();
    let part = closed_pocket(&params).unwrap();
    check_tags_and_stock(&part);
    check_closed(&part);
    assert!((part.mesh.bounds().max.z - params.stock[2]).abs() < 1e-9);
    assert_eq!(part.stock.max.coords, scallop_geom::Vec3::from(params.stock));
    // Undercut on +x: the bottom reaches farther out than the opening; draft on -x.
    let top = part.faces(&[FaceTag::Top]).unwrap().bounds();
    let bottom = part.faces(&[FaceTag::Bottom]).unwrap().bounds();
    assert!(bottom.max.x > top.max.x + 1.0 && bottom.min.x > top.min.x + 1.0);
    // The bottom's normals point down, out of the volume to remove.
    for (t, tag) in part.tags.iter().enumerate() {
        let [a, b, c] = part.mesh.triangle(t);
        let nz = (b - a).cross(&(c - a)).z;
        match tag {
            FaceTag::Bottom => assert!(nz < 0.0),
            FaceTag::Top => assert!(nz > 0.0),
            FaceTag::Flank => {}
        }
    }
}

#[test]
fn default_fitting_is_closed_non_convex_and_tagged() {
    let part = fitting_pocket(&FittingParams::default()).unwrap();
    check_tags_and_stock(&part);
    check_closed(&part);
    // Non-convex: the volume is well below its convex box's.
    let b = part.mesh.bounds();
    let s = b.size();
    assert!(signed_volume(&part.mesh) < 0.99 * s.x * s.y * s.z);
}

/// The channel's volume by its sections: at radius r the section on the
/// cylinder is a parallelogram (the blades' twist shears it) of width
/// `r (2 pi / blades) - thickness` and height the span, so the volume is the
/// integral of that area over r (midpoint rule).
fn channel_volume(p: &ImpellerParams) -> f64 {
    let [r0, r1] = p.radii;
    let n = 10_000;
    let dr = (r1 - r0) / n as f64;
    (0..n)
        .map(|k| {
            let r = r0 + (k as f64 + 0.5) * dr;
            let u = (r - r0) / (r1 - r0);
            (r * std::f64::consts::TAU / p.blades as f64 - p.thickness) * (p.span[0] + u * (p.span[1] - p.span[0])) * dr
        })
        .sum()
}

/// The channel is a closed solid (its inlet and outlet sections tagged top,
/// crossable) of the sections' volume; its hub and blades (the pocket's
/// bottom and flanks) are open at the inlet and the outlet and along the tips.
#[test]
fn impeller_channel_is_closed_by_its_inlet_and_outlet_sections() {
    let params = ImpellerParams::default();
    let part = impeller_channel(&params).unwrap();
    check_tags_and_stock(&part);
    check_closed(&part);
    let (v, expected) = (signed_volume(&part.mesh), channel_volume(&params));
    assert!((v - expected).abs() < 0.01 * expected, "volume {v} against {expected}");
    let [r0, r1] = params.radii;
    let tip_at = |r: f64| {
        let u = (r - r0) / (r1 - r0);
        let hub = params.hub_z[1] + (params.hub_z[0] - params.hub_z[1]) * (1.0 - u) * (1.0 - u);
        hub + params.span[0] + u * (params.span[1] - params.span[0])
    };
    let pocket = part.faces(&[FaceTag::Bottom, FaceTag::Flank]).unwrap();
    let (open, bad) = edge_report(&pocket);
    assert_eq!(bad, 0);
    assert!(!open.is_empty());
    for (a, b) in open {
        for v in [a, b] {
            let p = pocket.vertices()[v as usize];
            let r = p.x.hypot(p.y);
            let at_end = (r - r0).abs() < 1e-9 || (r - r1).abs() < 1e-9;
            assert!(at_end || (p.z - tip_at(r)).abs() < 1e-9, "open edge at r = {r}, z = {}", p.z);
        }
    }
    // The hub faces down, out of the channel.
    let hub = part.faces(&[FaceTag::Bottom]).unwrap();
    let [a, b, c] = hub.triangle(0);
    assert!((b - a).cross(&(c - a)).z < 0.0);
}

/// The impeller's turned blank is a closed, outward solid inside the stock
/// box, turned to the blade tips: its vertices lie on or under the tips'
/// profile (the nose at the hub's inlet height), the channel's vertices under
/// it and inside its outer radius; the other parts have no blank (the box is
/// their stock).
#[test]
fn the_impeller_blank_holds_the_channel() {
    let params = ImpellerParams::default();
    let part = impeller_channel(&params).unwrap();
    let blank = part.blank.as_ref().unwrap();
    let (open, bad) = edge_report(blank);
    assert!(open.is_empty() && bad == 0, "open {} bad {bad}", open.len());
    assert!(signed_volume(blank) > 0.0);
    let b = blank.bounds();
    assert!(part.stock.min.x <= b.min.x && b.max.x <= part.stock.max.x + 1e-9);
    assert!(part.stock.min.z <= b.min.z && b.max.z <= part.stock.max.z + 1e-9);
    let [r0, r1] = params.radii;
    let top_at = |r: f64| {
        let u = ((r - r0) / (r1 - r0)).clamp(0.0, 1.0);
        let hub = params.hub_z[1] + (params.hub_z[0] - params.hub_z[1]) * (1.0 - u) * (1.0 - u);
        hub + params.span[0] + u * (params.span[1] - params.span[0])
    };
    // The blank's vertices lie on or under that profile, and on the nose (the hub's inlet height)
    // inside the inlet radius.
    for p in blank.vertices() {
        let r = p.x.hypot(p.y);
        let top = if r < r0 - 1e-9 { params.hub_z[0] } else { top_at(r) };
        assert!(r <= r1 + 1e-9 && p.z <= top + 1e-9, "blank vertex {p:?}");
    }
    for p in part.mesh.vertices() {
        let r = p.x.hypot(p.y);
        assert!(r <= r1 + 1e-9 && p.z <= top_at(r) + 1e-9, "channel vertex {p:?} outside the blank");
    }
    assert!(closed_pocket(&PocketParams::default()).unwrap().blank.is_none());
    assert!(fitting_pocket(&FittingParams::default()).unwrap().blank.is_none());
}

#[test]
fn bad_parameters_name_themselves() {
    let err = closed_pocket(&PocketParams { wall: -1.0, ..PocketParams::default() }).unwrap_err();
    assert!(matches!(err, PartError::BadParameter { name: "wall", .. }));
    let err = impeller_channel(&ImpellerParams { blades: 1, ..ImpellerParams::default() }).unwrap_err();
    assert!(matches!(err, PartError::BadParameter { name: "blades", .. }));
    let err = fitting_pocket(&FittingParams { step: f64::NAN, ..FittingParams::default() }).unwrap_err();
    assert!(err.to_string().contains("step"));
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn pockets_stay_closed_and_deterministic(
        walls in prop::array::uniform4(-0.2f64..0.15),
        tilt in -0.08f64..0.08,
        dome in -3.0f64..3.0,
        rings in 1usize..8,
        side_points in 1usize..6,
        corner_points in 1usize..6,
    ) {
        let params = PocketParams { walls, tilt, dome, rings, side_points, corner_points, ..PocketParams::default() };
        let part = closed_pocket(&params).unwrap();
        check_tags_and_stock(&part);
        check_closed(&part);
        let again = closed_pocket(&params).unwrap();
        prop_assert_eq!(part.mesh.triangles(), again.mesh.triangles());
        prop_assert_eq!(part.mesh.vertices(), again.mesh.vertices());
    }

    #[test]
    fn fittings_stay_closed(rib in 1.0f64..8.0, reach in 0.2f64..0.8, draft in 0.0f64..0.1, rings in 1usize..6, step in 3.0f64..30.0) {
        let params = FittingParams { rib, rib_reach: reach, draft, rings, step, ..FittingParams::default() };
        let part = fitting_pocket(&params).unwrap();
        check_tags_and_stock(&part);
        check_closed(&part);
    }

    #[test]
    fn impellers_stay_closed(blades in 5usize..20, wrap in -1.0f64..1.0, twist in -0.3f64..0.3) {
        let params = ImpellerParams { blades, wrap, twist, ..ImpellerParams::default() };
        let part = impeller_channel(&params).unwrap();
        check_tags_and_stock(&part);
        check_closed(&part);
        let (v, expected) = (signed_volume(&part.mesh), channel_volume(&params));
        prop_assert!((v - expected).abs() < 0.02 * expected, "volume {} against {}", v, expected);
    }
}
