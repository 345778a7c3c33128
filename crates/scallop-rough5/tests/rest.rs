//! The rest pass along the bottom's limit passes and the bottom passes along
//! its normal (docs/rough5.md, "Impeller hub and roots").
#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

mod common;

use proptest::prelude::*;
use scallop_geom::{Point3, Vec3};
use scallop_mesh::{MeshQuery, TriMesh};
use scallop_parts::{PocketParams, closed_pocket};
use scallop_rough5::rest::{inside, root_rest_pairs};
use scallop_rough5::{BodyCheck, Placement, Placer, ProofSettings, Rough5Settings, SyncPoint, plan_rough5, prove};
use scallop_toolpath::MoveKind;

const ALLOWANCE: f64 = 0.5;
const TOOL: (f64, f64, f64) = (5.0, 1.5, 30.0);

fn mesh(quads: &[[Point3; 4]]) -> TriMesh {
    let soup: Vec<[Point3; 3]> = quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect();
    TriMesh::from_soup(&soup).unwrap().0
}

/// A floor z = 0 for x in [0, 40] and a wall 20 mm high rising from its edge
/// x = 0, leaning over the floor by `lean` (rad; negative: a draft).
fn floor_and_wall(lean: f64) -> (TriMesh, TriMesh) {
    let p = Point3::new;
    let top = 20.0 * lean.tan();
    let floor = mesh(&[[p(0.0, -40.0, 0.0), p(40.0, -40.0, 0.0), p(40.0, 40.0, 0.0), p(0.0, 40.0, 0.0)]]);
    let wall = mesh(&[[p(0.0, -40.0, 0.0), p(0.0, 40.0, 0.0), p(top, 40.0, 20.0), p(top, -40.0, 20.0)]]);
    (floor, wall)
}

/// The floor's limit pass: vertical tools along y, as near the wall as the
/// tool (its flutes' radius plus the allowance) clears it, and those tools.
fn limit_pass(placer: &Placer, body: &BodyCheck) -> (Vec<SyncPoint>, Vec<Placement>) {
    let clear =
        |x: f64| placer.place(&Point3::new(x, 0.0, 0.0), &Vec3::z()).filter(|p| !body.collides(&p.tip, &p.axis));
    let mut x = 30.0;
    while clear(x - 0.05).is_some() && x > 0.0 {
        x -= 0.05;
    }
    let pairs: Vec<SyncPoint> = (-30..=30)
        .map(|k| {
            let path = Point3::new(x, f64::from(k), 0.0);
            SyncPoint { path, tilt: None, normal: Vec3::z(), tangent: Vec3::y(), axis: Vec3::z() }
        })
        .collect();
    let cut = pairs.iter().map(|s| placer.place(&s.path, &s.axis).unwrap()).collect();
    (pairs, cut)
}

/// Points of the cross-section y = 0 (every 0.25 mm, 0.75 to 4 mm over the
/// floor) more than the allowance from the wall.
/// The limit pass of the floor's tool along `wall` (pairs, tools) and the
/// rest pass's runs after it.
fn rest_pass(
    placer: &Placer,
    wall: &TriMesh,
    query: &MeshQuery,
) -> (Vec<SyncPoint>, Vec<Placement>, Vec<Vec<SyncPoint>>) {
    let cutter = common::torus(30.0, 192.0);
    let body = BodyCheck::new(wall, &cutter, 0.0);
    let rest = BodyCheck::new(wall, &cutter, ALLOWANCE);
    let (pairs, cut) = limit_pass(placer, &body);
    let runs = root_rest_pairs(placer, &rest, query, (&pairs, &cut), TOOL, ALLOWANCE);
    (pairs, cut, runs)
}

fn section(wall: &MeshQuery) -> Vec<Point3> {
    (0..=80)
        .flat_map(|i| (0..=13).map(move |k| Point3::new(0.25 * f64::from(i), 0.0, 0.75 + 0.25 * f64::from(k))))
        .filter(|q| wall.closest_point(q).distance > ALLOWANCE)
        .collect()
}

/// The torus's surface points (every 10 degrees round the axis and along
/// the corner, the flutes every 0.5 mm): the whole tool keeps the allowance
/// from the wall when all of them do.
fn surface(p: &Placement) -> Vec<Point3> {
    let (radius, corner, flutes) = TOOL;
    let u = p.axis;
    let e1 = u.cross(&if u.x.abs() < 0.9 { Vec3::x() } else { Vec3::y() }).normalize();
    let e2 = u.cross(&e1);
    let mut out = Vec::new();
    for k in 0..36 {
        let phi = f64::from(k) * 10f64.to_radians();
        let e = e1 * phi.cos() + e2 * phi.sin();
        let ring = p.tip + u * corner + e * (radius - corner);
        for j in 0..=9 {
            let psi = f64::from(j) * 10f64.to_radians();
            out.push(ring + e * (corner * psi.sin()) - u * (corner * psi.cos()));
        }
        for j in 0..=((flutes - corner) / 0.5) as usize {
            out.push(ring + e * corner + u * (0.5 * j as f64));
        }
        for j in 0..=6 {
            out.push(p.tip + e * ((radius - corner) * f64::from(j) / 6.0));
        }
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(8))]

    /// Under a wall leaning 15 to 35 degrees over the floor, the vertical
    /// tool's limit pass stands off the root by the overhang: the rest pass
    /// runs along the whole wall, every tool of it keeps the allowance from
    /// the wall (its surface sampled, independently of the planner's axis
    /// check), and it cuts at least 3 mm^2 of the cross-section that the
    /// limit pass left.
    #[test]
    fn the_rest_pass_reaches_under_an_overhang(lean_deg in 15.0f64..35.0) {
        let (floor, wall) = floor_and_wall(lean_deg.to_radians());
        let cutter = common::torus(30.0, 192.0);
        let placer = Placer::new(&floor, &cutter, ALLOWANCE).unwrap();
        let query = MeshQuery::new(&wall);
        let (pairs, cut, runs) = rest_pass(&placer, &wall, &query);
        let kept: Vec<&SyncPoint> = runs.iter().flatten().collect();
        prop_assert!(kept.len() >= pairs.len() - 2, "{} of {} pairs kept", kept.len(), pairs.len());
        let mut middle = None;
        for s in &kept {
            let p = placer.place(&s.path, &s.axis).unwrap();
            let nearest = surface(&p).iter().map(|q| query.closest_point(q).distance).fold(f64::INFINITY, f64::min);
            prop_assert!(nearest >= ALLOWANCE - 1e-6, "a tool at {:?} comes {nearest:.4} mm from the wall", p.tip);
            if s.path.y.abs() < 0.5 {
                middle = Some(p);
            }
        }
        let middle = middle.unwrap();
        let left: Vec<Point3> = section(&query).into_iter().filter(|q| !cut.iter().any(|p| inside(p, TOOL, q))).collect();
        let gained = left.iter().filter(|q| inside(&middle, TOOL, q)).count() as f64 * 0.0625;
        prop_assert!(gained >= 3.0, "the rest tool cuts {gained:.2} mm^2 of the section, the limit pass left {:.2}",
            left.len() as f64 * 0.0625);
    }

    /// Along a vertical wall or one with a draft the limit pass leaves only
    /// the corner's fillet: no rest pass (it would cost time for nothing).
    #[test]
    fn no_rest_pass_along_an_open_wall(draft_deg in 0.0f64..10.0) {
        let (floor, wall) = floor_and_wall(-draft_deg.to_radians());
        let cutter = common::torus(30.0, 192.0);
        let placer = Placer::new(&floor, &cutter, ALLOWANCE).unwrap();
        let query = MeshQuery::new(&wall);
        let (_, _, runs) = rest_pass(&placer, &wall, &query);
        prop_assert!(runs.is_empty(), "{} rest runs", runs.len());
    }
}

/// A 60 x 60 mm pocket with vertical walls whose bottom slopes along x by
/// `slope` (rad), 24 mm high, planned by `scallop rough5`'s settings with or
/// without the bottom's inner passes along its normal (the rest pass left
/// out), and proven: V_r (%) and the feeds' largest tilt (rad).
fn sloped_pocket(slope: f64, bottom_normal: bool) -> (f64, f64, Vec<scallop_toolpath::Move>) {
    let part =
        closed_pocket(&PocketParams { walls: [0.0; 4], tilt: slope, dome: 0.0, ..common::small_pocket(24.0, 10.0) })
            .unwrap();
    let (bottom, flanks, depth) = common::bottom_flanks(&part);
    let tool = common::torus(30.0, 192.0);
    let s = Rough5Settings { bottom_normal, root_rest: false, ..common::settings(depth) };
    let plan = plan_rough5(&bottom, &flanks, &part.stock, &tool, &s, &|_, _| {}).unwrap();
    let proof_settings = ProofSettings { resolution: 0.5, axis_tolerance: 0.05 };
    let proof = prove(&plan.toolpath, &tool, &part.stock, &part.mesh, &proof_settings, &|_, _| {}).unwrap();
    assert!(proof.gouge_depth <= proof_settings.axis_tolerance, "gouge {} mm", proof.gouge_depth);
    let moves = plan.toolpath.moves().to_vec();
    let tilt = (0..moves.len())
        .filter(|&i| moves[i].kind == MoveKind::Feed)
        .map(|i| plan.toolpath.axis(i).angle(&Vec3::z()))
        .fold(0.0, f64::max);
    (proof.remaining_percent, tilt, moves)
}

/// On a bottom sloping 11 degrees, steeper than the step rule's 6.3 degrees
/// (a_e 4.5 mm, 0.5 mm allowance), the bottom's inner passes follow its
/// normal: the program is proven and leaves less than with vertical inner
/// passes, whose torus stands on its corner. On a bottom sloping 3 degrees
/// the program is the same move for move.
#[test]
fn a_sloped_bottom_is_cut_along_its_normal() {
    let steep = 0.2;
    let (along, tilt, _) = sloped_pocket(steep, true);
    let (vertical, _, _) = sloped_pocket(steep, false);
    assert!(tilt >= steep.atan() - 1e-6, "the feeds lean {:.2} deg at most", tilt.to_degrees());
    assert!(along < vertical - 0.2, "V_r {along:.2} % along the normal, {vertical:.2} % with vertical inner passes");
    let gentle = 0.05;
    let (_, _, on) = sloped_pocket(gentle, true);
    let (_, _, off) = sloped_pocket(gentle, false);
    assert_eq!(on, off, "a 3 deg bottom's program changed");
}
