//! The refinements of the guide-curve program (docs/rough5.md, "Where the
//! remaining volume was"): the intrusion the axis translation reads is that
//! of the flank (a planar wall: its normal, and moving the tool by it clears
//! it); on a small closed pocket the refined program leaves less of the volume
//! to remove than the plain one, is proven (no gouge, no shank or holder
//! collision), keeps every CL point clear of the flanks, keeps the angular
//! step, never leaves the pole in another azimuth than the one held, and
//! does not depend on the thread count; the bottom's centre offsets leave no
//! island wider than the tool inside the innermost pass.
#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

mod common;

use proptest::prelude::*;
use scallop_cutter::Cutter;
use scallop_geom::{Point3, Vec3};
use scallop_mesh::TriMesh;
use scallop_parts::{FaceTag, PocketParams, closed_pocket};
use scallop_rough5::{
    AIR_MARGIN, AIR_STEP, BodyCheck, LevelOptions, MoveRole, ProofSettings, Rough5Settings, TiltMode,
    level_passes_with, plan_rough5, plan_rough5_in, prove, prove_from_blank,
};
use scallop_toolpath::MoveKind;

fn tool() -> Cutter {
    common::torus(20.0, 100.0)
}

/// The wall through the origin with unit normal `n` (horizontal part along
/// +x), 600 mm wide and high around the origin: every closest point of the
/// tool's axis is inside it.
fn wall(lean: f64) -> (TriMesh, Vec3) {
    let n = Vec3::new(lean.cos(), 0.0, lean.sin());
    let up = Vec3::new(-lean.sin(), 0.0, lean.cos());
    let side = Vec3::y() * 300.0;
    let (a, b) = (Point3::origin() - up * 300.0, Point3::origin() + up * 300.0);
    let m = TriMesh::from_soup(&[[a - side, a + side, b + side], [a - side, b + side, b - side]]).unwrap().0;
    (m, n)
}

proptest! {
    /// Against a planar wall, with the tool's axis on the wall's open side,
    /// the intrusion is reported exactly when the tool collides, its
    /// direction is the wall's normal, and the tool moved along it by the
    /// intrusion (and a hair) is clear.
    #[test]
    fn the_intrusion_is_the_walls(
        lean in -0.25f64..0.25,
        gap in 0.0f64..8.0,
        tilt in 0.0f64..0.35,
        azimuth in 0.0f64..std::f64::consts::TAU,
        z in -20.0f64..-5.0,
    ) {
        let (flank, n) = wall(lean);
        let body = BodyCheck::new(&flank, &tool(), 0.0);
        let axis = Vec3::new(tilt.sin() * azimuth.cos(), tilt.sin() * azimuth.sin(), tilt.cos());
        let tip = Point3::origin() + n * gap + Vec3::z() * z;
        // The axis from the tip to the holder's top (131 mm) on the open side.
        prop_assume!(tip.coords.dot(&n) > 0.0 && (tip + axis * 131.0).coords.dot(&n) > 0.0);
        let found = body.intrusion(&tip, &axis);
        prop_assert_eq!(found.is_some(), body.collides(&tip, &axis));
        if let Some((deficit, dir)) = found {
            prop_assert!(deficit > 0.0);
            prop_assert!((dir - n).norm() < 1e-9, "{dir:?} {n:?}");
            prop_assert!(!body.collides(&(tip + n * (deficit + 1e-6)), &axis));
        }
    }
}

fn settings(depth: f64, refined: bool) -> Rough5Settings {
    common::settings(depth).with_refinements(refined)
}

/// A 60 x 60 x 20 mm block with the closed pocket's drafts and undercuts.
fn small_pocket() -> scallop_parts::TestPart {
    closed_pocket(&PocketParams {
        stock: [60.0, 60.0, 20.0],
        bottom_z: 6.0,
        wall: 8.0,
        corner_radius: 6.0,
        dome: 1.0,
        ..Default::default()
    })
    .unwrap()
}

/// The azimuth of a tilted axis, `None` on the pole.
fn azimuth(u: &Vec3) -> Option<f64> {
    (u.angle(&Vec3::z()) > 1e-6).then(|| u.y.atan2(u.x))
}

#[test]
fn the_refined_program_leaves_less_and_stays_safe() {
    let part = small_pocket();
    let bottom = part.faces(&[FaceTag::Bottom]).unwrap();
    let flanks = part.faces(&[FaceTag::Flank]).unwrap();
    let depth = part.stock.max.z - bottom.bounds().min.z;
    let tool = tool();
    let body = BodyCheck::new(&flanks, &tool, 0.0);
    let proof_settings = ProofSettings { resolution: 0.5, axis_tolerance: 0.05 };
    let mut remaining = Vec::new();
    for refined in [false, true] {
        let s = settings(depth, refined);
        let plan = plan_rough5(&bottom, &flanks, &part.stock, &tool, &s, &|_, _| {}).unwrap();
        let path = &plan.toolpath;
        let mut held: Option<f64> = None;
        for (i, m) in path.moves().iter().enumerate().skip(1) {
            let (a, b) = (path.axis(i - 1), path.axis(i));
            if matches!(m.kind, MoveKind::Feed | MoveKind::Link | MoveKind::Plunge) {
                assert!(!body.collides(&m.to, &b), "move {i} meets a flank");
            }
            if matches!(m.kind, MoveKind::Feed | MoveKind::Link) {
                assert!(a.angle(&b) <= s.max_angle_step + 1e-9, "move {i}: {}", a.angle(&b));
            }
            // Leaving the pole while cutting only in the azimuth held (refined
            // program: the plain one does not guarantee it).
            if refined
                && m.kind != MoveKind::Rapid
                && azimuth(&a).is_none()
                && let Some(f) = azimuth(&b)
            {
                let h = held.unwrap();
                let d = (f - h).rem_euclid(std::f64::consts::TAU);
                assert!(d.min(std::f64::consts::TAU - d) <= 0.5f64.to_radians() + 1e-12, "move {i}");
            }
            if let Some(f) = azimuth(&b) {
                held = Some(f);
            }
        }
        let proof = prove(path, &tool, &part.stock, &part.mesh, &proof_settings, &|_, _| {}).unwrap();
        assert!(proof.gouge_depth <= proof_settings.resolution, "{proof:?}");
        if refined {
            let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
            let again = one.install(|| plan_rough5(&bottom, &flanks, &part.stock, &tool, &s, &|_, _| {}).unwrap());
            assert_eq!(again.toolpath, plan.toolpath);
        }
        remaining.push(proof.remaining_percent);
    }
    assert!(remaining[1] < remaining[0], "{remaining:?}");
}

/// Half the mean width (area over length) of a closed curve's inside: the
/// half-width of a strip, the inradius of a square.
fn half_width(c: &scallop_guides::Curve) -> f64 {
    c.signed_area().abs() / c.line.length() * 2.0
}

#[test]
fn the_bottom_centre_is_reached() {
    let part = closed_pocket(&PocketParams::default()).unwrap();
    let bottom = part.faces(&[FaceTag::Bottom]).unwrap();
    let flanks = part.faces(&[FaceTag::Flank]).unwrap();
    let depth = part.stock.max.z - bottom.bounds().min.z;
    let g = settings(depth, true).guides;
    let widths: Vec<f64> = [false, true]
        .iter()
        .map(|&centre| {
            let options = LevelOptions { centre_offsets: centre, pair_by_rank: false, open_bottom: false };
            let levels = level_passes_with(&bottom, &flanks, &g, TiltMode::Zero, &options).unwrap();
            half_width(&levels[0].passes[0].0)
        })
        .collect();
    // Without the centre offsets the innermost bottom pass leaves an island
    // beyond the tool's reach; with them it is within one step of the centre.
    assert!(widths[0] > g.tool_radius + 1.0, "{widths:?}");
    assert!(widths[1] < g.tool_radius + 1.0, "{widths:?}");
    assert!(widths[1] < widths[0] - 0.5 * g.radial_step, "{widths:?}");
}

/// A closed box mesh between `lo` and `hi`.
fn box_mesh(lo: Point3, hi: Point3) -> TriMesh {
    let p = |i: usize| Point3::new([lo.x, hi.x][i & 1], [lo.y, hi.y][(i >> 1) & 1], [lo.z, hi.z][i >> 2]);
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let soup: Vec<[Point3; 3]> =
        quads.iter().flat_map(|q| [[p(q[0]), p(q[1]), p(q[2])], [p(q[0]), p(q[2]), p(q[3])]]).collect();
    TriMesh::from_soup(&soup).unwrap().0
}

/// The small pocket, its bottom and flanks, the tool, refined settings and a
/// blank 8 mm under the stock top (`top`, its height).
struct LowBlank {
    part: scallop_parts::TestPart,
    bottom: TriMesh,
    flanks: TriMesh,
    tool: Cutter,
    s: Rough5Settings,
    top: f64,
    blank: TriMesh,
}

fn low_blank() -> LowBlank {
    let part = small_pocket();
    let bottom = part.faces(&[FaceTag::Bottom]).unwrap();
    let flanks = part.faces(&[FaceTag::Flank]).unwrap();
    let depth = part.stock.max.z - bottom.bounds().min.z;
    let (tool, s) = (tool(), settings(depth, true));
    let top = part.stock.max.z - 8.0;
    let blank = box_mesh(part.stock.min, Point3::new(part.stock.max.x, part.stock.max.y, top));
    LowBlank { part, bottom, flanks, tool, s, top, blank }
}

/// In a blank 8 mm under the stock top, the CL points whose tool lies above
/// the blank are left out: no cutting move runs higher than the blank's top
/// plus the tool radius, the margin and the entry clearance, where the plan
/// in the whole box has such moves; the program is shorter and proven from
/// the blank. The plan in no blank is the plan in the box.
#[test]
fn a_low_blank_trims_the_levels_above_it() {
    let LowBlank { part, bottom, flanks, tool, s, top, blank } = low_blank();
    let boxed = plan_rough5(&bottom, &flanks, &part.stock, &tool, &s, &|_, _| {}).unwrap();
    let none = plan_rough5_in(&bottom, &flanks, (&part.stock, None), &tool, &s, &|_, _| {}).unwrap();
    assert_eq!(none.toolpath, boxed.toolpath);
    let trimmed = plan_rough5_in(&bottom, &flanks, (&part.stock, Some(&blank)), &tool, &s, &|_, _| {}).unwrap();
    let ceiling = top + tool.radius() + AIR_MARGIN + s.clearance + 1e-9;
    let high = |p: &scallop_toolpath::Toolpath| {
        p.moves().iter().filter(|m| m.kind == MoveKind::Feed && m.to.z > ceiling).count()
    };
    assert!(high(&boxed.toolpath) > 0);
    assert_eq!(high(&trimmed.toolpath), 0);
    assert!(trimmed.passes.iter().map(|p| p.air).sum::<usize>() > 0);
    assert!(trimmed.toolpath.moves().len() < boxed.toolpath.moves().len());
    let proof_settings = ProofSettings { resolution: 0.5, axis_tolerance: 0.05 };
    let proof =
        prove_from_blank(&trimmed.toolpath, &tool, &part.stock, Some(&blank), &part.mesh, &proof_settings, &|_, _| {})
            .unwrap();
    assert!(proof.gouge_depth <= proof_settings.resolution, "{proof:?}");
}

/// The block of the small pocket with its top sloping from the stock's top
/// at x = `lo.x` down by `fall` mm at x = `hi.x` (a plane, so every face of
/// the hexahedron is flat).
fn sloped_box(lo: Point3, hi: Point3, fall: f64) -> TriMesh {
    let p = |i: usize| {
        let x = [lo.x, hi.x][i & 1];
        let top = hi.z - fall * (i & 1) as f64;
        Point3::new(x, [lo.y, hi.y][(i >> 1) & 1], [lo.z, top][i >> 2])
    };
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let soup: Vec<[Point3; 3]> =
        quads.iter().flat_map(|q| [[p(q[0]), p(q[1]), p(q[2])], [p(q[0]), p(q[2]), p(q[3])]]).collect();
    TriMesh::from_soup(&soup).unwrap().0
}

/// In a blank whose top falls by 10 mm across the small pocket, the first
/// level is entered from the blank's highest point plus the clearance; an
/// entry down a helix starts where the tool reaches the blank: at the end of
/// the first move of every helix whose approach ends above the blank, some
/// section of the flutes (every mm) comes within [`AIR_MARGIN`] of the blank
/// within the tool's radius (its lowest point `R sin tilt` under the
/// section), the test of the rapid approaches (without it, the first move of
/// a helix ended 2.2 mm over the blank). The program proves from the blank.
#[test]
fn helices_start_where_the_tool_reaches_the_blank() {
    let part = small_pocket();
    let bottom = part.faces(&[FaceTag::Bottom]).unwrap();
    let flanks = part.faces(&[FaceTag::Flank]).unwrap();
    let depth = part.stock.max.z - bottom.bounds().min.z;
    let (tool, s) = (tool(), settings(depth, true));
    let (lo, hi, fall) = (part.stock.min, part.stock.max, 10.0);
    let blank = sloped_box(lo, hi, fall);
    let blank_top = |x: f64| hi.z - fall * ((x - lo.x) / (hi.x - lo.x)).clamp(0.0, 1.0);
    let plan = plan_rough5_in(&bottom, &flanks, (&part.stock, Some(&blank)), &tool, &s, &|_, _| {}).unwrap();
    let path = &plan.toolpath;
    let moves = path.moves();
    assert_eq!(plan.roles.len(), moves.len());
    assert!(plan.entries.helix > 0, "{:?}", plan.entries);
    // How far the tool at move i is above the blank: the least, over the
    // sections of its flutes every mm, of the section's lowest point over the
    // blank's highest point within the tool's radius (the top falls with x).
    let over = |i: usize| {
        let (tip, u) = (moves[i].to, path.axis(i));
        let sections = tool.flute_length().ceil() as usize;
        (0..=sections)
            .map(|k| {
                let c = tip + u * (tool.flute_length() * k as f64 / sections as f64);
                c.z - tool.radius() * u.angle(&Vec3::z()).sin() - blank_top(c.x - tool.radius())
            })
            .fold(f64::INFINITY, f64::min)
    };
    let mut checked = 0;
    for (i, m) in moves.iter().enumerate().skip(1) {
        // The first move of an entry after its approach, the entry going on.
        let first = plan.roles[i] == MoveRole::Entry
            && plan.roles[i - 1] == MoveRole::Approach
            && m.kind == MoveKind::Feed
            && plan.roles.get(i + 1) == Some(&MoveRole::Entry);
        if first && over(i - 1) > AIR_MARGIN {
            assert!(
                over(i) <= AIR_MARGIN + 1e-9,
                "move {i}: the entry's first move ends {} mm over the blank",
                over(i)
            );
            checked += 1;
        }
    }
    assert!(checked > 0);
    let proof_settings = ProofSettings { resolution: 0.5, axis_tolerance: 0.05 };
    prove_from_blank(path, &tool, &part.stock, Some(&blank), &part.mesh, &proof_settings, &|_, _| {}).unwrap();
}

/// In a blank 8 mm under the stock top, the tool goes at the rapid rate
/// down to where its flutes come within [`AIR_MARGIN`] of the blank, and
/// back up from there: every approach at the feed (a plunge after a rapid)
/// and every exit at the feed (a link before a retract) ends or starts
/// within one [`AIR_STEP`] of that height (its lowest point `R sin tilt`
/// under the tip), where the program without the blank's rapids plunges
/// from the safe height, 14 mm over the blank. The program is proven from
/// the blank: no rapid meets its stock.
#[test]
fn the_tool_goes_rapid_over_the_blank() {
    let LowBlank { part, bottom, flanks, tool, s, top, blank } = low_blank();
    let plan = plan_rough5_in(&bottom, &flanks, (&part.stock, Some(&blank)), &tool, &s, &|_, _| {}).unwrap();
    let path = &plan.toolpath;
    let moves = path.moves();
    // The height of the tool's lowest point over the blank's top.
    let over = |i: usize| {
        let tilt = path.axis(i).angle(&Vec3::z());
        moves[i].to.z - tool.radius() * tilt.sin() - top
    };
    let reach = AIR_MARGIN + AIR_STEP + 1e-6;
    let mut checked = 0;
    for i in 1..moves.len() {
        let approach = moves[i].kind == MoveKind::Plunge && moves[i - 1].kind == MoveKind::Rapid;
        let exit = moves[i].kind == MoveKind::Link && moves.get(i + 1).is_some_and(|m| m.kind == MoveKind::Retract);
        if approach {
            // The plunge starts where the rapid ended.
            assert!(over(i - 1) <= reach, "move {i}: the plunge starts {} mm over the blank", over(i - 1));
            checked += 1;
        }
        if exit {
            assert!(over(i) <= reach, "move {i}: the exit at the feed ends {} mm over the blank", over(i));
            checked += 1;
        }
    }
    assert!(checked > 0);
    let proof_settings = ProofSettings { resolution: 0.5, axis_tolerance: 0.05 };
    prove_from_blank(path, &tool, &part.stock, Some(&blank), &part.mesh, &proof_settings, &|_, _| {}).unwrap();
}

/// On a bottom sloping by 0.2 along x (11.3 degrees), with vertical walls
/// and the axis +Z, the levels are planes a_p / cos(slope) apart along +Z,
/// and the tool tips of a level lie at one height over the bottom. A run is
/// entered from the level above where it starts: every entry plunge ends at
/// most that spacing plus the clearance (and half a voxel of the levels'
/// fields) over the lowest tip of the level it enters, not at the clearance
/// over the level above's highest tip, 8.8 mm higher at the bottom's low
/// side. The program is proven.
#[test]
fn a_run_is_entered_from_the_level_above_where_it_starts() {
    let part =
        closed_pocket(&PocketParams { walls: [0.0; 4], tilt: 0.2, dome: 0.0, ..common::small_pocket(24.0, 8.0) })
            .unwrap();
    let (bottom, flanks, depth) = common::bottom_flanks(&part);
    let (tool, s) = (tool(), Rough5Settings { tilt: TiltMode::Zero, ..settings(depth, true) });
    let plan = plan_rough5(&bottom, &flanks, &part.stock, &tool, &s, &|_, _| {}).unwrap();
    let moves = plan.toolpath.moves();
    // Height over the bottom plane z = 8 + 0.2 (x - 30).
    let over = |p: &Point3| p.z - (8.0 + 0.2 * (p.x - 30.0));
    let spacing = s.guides.axial_step / 0.2f64.atan().cos();
    let mut entries = 0;
    for i in 1..moves.len() {
        if !(moves[i].kind == MoveKind::Plunge && moves[i - 1].kind == MoveKind::Rapid) {
            continue;
        }
        // The level entered: the feeds up to the next rapid.
        let level = moves[i + 1..]
            .iter()
            .take_while(|m| !matches!(m.kind, MoveKind::Rapid | MoveKind::Retract))
            .filter(|m| m.kind == MoveKind::Feed)
            .map(|m| over(&m.to))
            .fold(f64::INFINITY, f64::min);
        // The first level is entered from above the stock.
        if entries > 0 {
            let lift = over(&moves[i].to) - level;
            assert!(lift <= spacing + s.clearance + 0.5 * s.guides.voxel, "move {i}: entered {lift} mm over its level");
        }
        entries += 1;
    }
    assert!(entries > 2, "{entries} entries");
    let proof_settings = ProofSettings { resolution: 0.5, axis_tolerance: 0.05 };
    prove(&plan.toolpath, &tool, &part.stock, &part.mesh, &proof_settings, &|_, _| {}).unwrap();
}
