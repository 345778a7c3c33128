//! The 3-axis baselines on the closed test pocket: the z-level program and
//! the z-level plus 3+2 rest program are proven on a tri-dexel stock (no
//! rapid into stock, no shank or holder collision, nothing removed outside
//! the volume to remove beyond the rays' rounding), do not depend on the
//! thread count, and the rest setups remove at least what the z-level
//! program removes; the setups are chosen by the undercuts.
#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

mod common;

use scallop_cutter::Cutter;
use scallop_geom::Vec3;
use scallop_parts::{FaceTag, PocketParams, TestPart, closed_pocket};
use scallop_rough5::{
    BaselinePlan, BaselineSettings, Pocket, ProofSettings, TorusTool, plan_three_plus_two, plan_zlevel, prove,
    setup_axes,
};
use scallop_toolpath::MoveKind;

fn settings() -> BaselineSettings {
    BaselineSettings {
        stepdown: 4.0,
        stepover: 4.5,
        flank_allowance: 0.5,
        bottom_allowance: 0.5,
        feed: 2400.0,
        rapid_rate: 20_000.0,
        clearance: 1.0,
        max_tilt: 90f64.to_radians(),
        resolution: 1.0,
        axis_tolerance: 0.05,
    }
}

fn tool() -> Cutter {
    common::torus(30.0, 100.0)
}

struct Faces {
    surface: scallop_mesh::TriMesh,
    opening: scallop_mesh::TriMesh,
    flanks: scallop_mesh::TriMesh,
}

fn faces(part: &TestPart) -> Faces {
    Faces {
        surface: part.faces(&[FaceTag::Bottom, FaceTag::Flank]).unwrap(),
        opening: part.faces(&[FaceTag::Top]).unwrap(),
        flanks: part.faces(&[FaceTag::Flank]).unwrap(),
    }
}

fn pocket<'a>(part: &'a TestPart, f: &'a Faces) -> Pocket<'a> {
    Pocket {
        surface: &f.surface,
        opening: &f.opening,
        flanks: &f.flanks,
        volume: &part.mesh,
        stock: part.stock,
        blank: part.blank.as_ref(),
    }
}

/// Every move stays above the stock's floor, every setup's axis is fixed
/// along its moves (straight moves only), and the plan on one thread is the
/// same.
fn check_plan(plan: &BaselinePlan, again: &BaselinePlan, floor: f64) {
    assert_eq!(again.toolpath, plan.toolpath);
    assert_eq!(plan.toolpath.arc_count(), 0);
    assert!(plan.toolpath.moves().iter().all(|m| m.to.z >= floor));
    let mut from = 0;
    for s in &plan.setups {
        for i in from..from + s.moves {
            let cutting = matches!(plan.toolpath.moves()[i].kind, MoveKind::Feed | MoveKind::Link | MoveKind::Plunge);
            if cutting {
                assert!((plan.toolpath.axis(i) - s.axis).norm() < 1e-12, "move {i}");
            }
        }
        from += s.moves;
    }
    assert_eq!(from, plan.toolpath.moves().len());
}

#[test]
fn both_baselines_prove_themselves_on_the_closed_pocket() {
    let part = closed_pocket(&PocketParams::default()).unwrap();
    let f = faces(&part);
    let p = pocket(&part, &f);
    let (tool, s) = (tool(), settings());
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    let proof_settings = ProofSettings { resolution: 1.0, axis_tolerance: 0.05 };
    let mut proofs = Vec::new();
    for three_plus_two in [false, true] {
        let plan_of = || if three_plus_two { plan_three_plus_two(&p, &tool, &s) } else { plan_zlevel(&p, &tool, &s) };
        let plan = plan_of().unwrap();
        let again = one.install(|| plan_of().unwrap());
        check_plan(&plan, &again, part.stock.min.z);
        assert_eq!(plan.setups[0].axis, Vec3::z());
        assert!(plan.setups[0].levels >= 5 && plan.setups[0].passes > 0, "{:?}", plan.setups[0]);
        if three_plus_two {
            // The pocket's two undercut sides (+x and -y) give the rest setups.
            assert!(plan.setups.len() >= 2, "{:?}", plan.setups);
        } else {
            assert_eq!(plan.setups.len(), 1);
        }
        let proof = prove(&plan.toolpath, &tool, &part.stock, &part.mesh, &proof_settings, &|_, _| {}).unwrap();
        assert!(proof.gouge_depth <= proof_settings.resolution, "{proof:?}");
        assert!(proof.remaining_percent < 100.0 && proof.removed_volume > 0.0, "{proof:?}");
        let again = one.install(|| prove(&plan.toolpath, &tool, &part.stock, &part.mesh, &proof_settings, &|_, _| {}));
        assert_eq!(again.unwrap(), proof);
        proofs.push(proof);
    }
    let (zlevel, rest) = (&proofs[0], &proofs[1]);
    assert!(rest.removed_volume >= zlevel.removed_volume, "{zlevel:?} {rest:?}");
    assert!(rest.remaining_volume <= zlevel.remaining_volume, "{zlevel:?} {rest:?}");
}

#[test]
fn setups_lean_away_from_the_undercuts_only() {
    let deg = f64::to_radians;
    // Drafts on every side: nothing to reach under.
    let drafts = PocketParams { walls: [deg(5.0), deg(8.0), deg(5.0), deg(3.0)], ..PocketParams::default() };
    let part = closed_pocket(&drafts).unwrap();
    let f = faces(&part);
    assert!(setup_axes(&f.flanks, deg(90.0)).is_empty());
    // So the 3+2 program is the z-level one.
    let (zlevel, rest) = (
        plan_zlevel(&pocket(&part, &f), &tool(), &settings()),
        plan_three_plus_two(&pocket(&part, &f), &tool(), &settings()),
    );
    let (zlevel, rest) = (zlevel.unwrap(), rest.unwrap());
    assert_eq!(rest.setups.len(), 1);
    assert_eq!(rest.toolpath, zlevel.toolpath);
    // One undercut side, +x by `a`: the main setup leans towards -x by about
    // a plus the margin, no more than the steepest flank plus the margin.
    for a in [6.0, 10.0, 15.0] {
        let params = PocketParams { walls: [deg(-a), deg(8.0), deg(5.0), deg(3.0)], ..PocketParams::default() };
        let part = closed_pocket(&params).unwrap();
        let flanks = faces(&part).flanks;
        let axes = setup_axes(&flanks, deg(90.0));
        // The steepest undercut of any flank triangle (brute force).
        let v = flanks.vertices();
        let steepest = flanks
            .triangles()
            .iter()
            .map(|t| {
                let [p, q, r] = t.map(|i| v[i as usize]);
                let n = (q - p).cross(&(r - p)).normalize();
                n.z.asin()
            })
            .fold(f64::NEG_INFINITY, f64::max);
        // The corners next to the undercut side blend into it: their sectors
        // may get a setup of their own, with much less undercut.
        assert!(!axes.is_empty() && axes[1..].iter().all(|x| x.1 < axes[0].1 / 3.0), "{axes:?}");
        let (u, area) = axes[0];
        let tilt = u.angle(&Vec3::z());
        assert!(u.x < 0.0 && u.y.abs() < 0.05 * u.x.abs(), "{u:?}");
        assert!(tilt > deg(0.5 * a) && tilt <= steepest + scallop_rough5::tol::SETUP_MARGIN + 1e-9, "{a}: {tilt}");
        assert!(area > 0.0);
        // The machine's tilt range caps it.
        let capped = setup_axes(&flanks, deg(2.0));
        assert!((capped[0].0.angle(&Vec3::z()) - deg(2.0)).abs() < 1e-9);
    }
}

/// A closed box mesh (outward normals).
fn box_mesh(b: &scallop_geom::Aabb3) -> scallop_mesh::TriMesh {
    let (lo, hi) = (b.min, b.max);
    let v: Vec<scallop_geom::Point3> = (0..8)
        .map(|k| {
            scallop_geom::Point3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            )
        })
        .collect();
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let t: Vec<[usize; 3]> = quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect();
    scallop_mesh::TriMesh::from_indexed(&v, &t).unwrap().0
}

/// The 3+2 program on a blank smaller than its stock box (the impeller's
/// turned blank; docs/rough5.md, "Baselines"): the rest setups are planned on
/// the in-process stock of the blank, as the proof cuts it. Here the blank is
/// the pocket's block and the box reaches 20 mm above it: a holder 41 mm
/// above a tip on the bottom near a flank stands in the box's material over
/// the block's top, which is not there. Planned on the box, the z-level
/// program "collides"; on the blank it is planned and proven.
#[test]
fn three_plus_two_starts_from_the_blank() {
    let mut part = closed_pocket(&PocketParams::default()).unwrap();
    let block = part.stock;
    part.stock.max.z += 20.0;
    let blank = box_mesh(&block);
    let f = faces(&part);
    let (tool, s) = (tool(), settings());
    // The cause, on the box: the z-level program's holder meets material that
    // the blank does not have.
    let boxed = plan_three_plus_two(&pocket(&part, &f), &tool, &s);
    assert!(
        matches!(&boxed, Err(scallop_rough5::Rough5Error::Simulation(e)) if e.contains("into the stock")),
        "{boxed:?}"
    );
    part.blank = Some(blank);
    let plan = plan_three_plus_two(&pocket(&part, &f), &tool, &s).unwrap();
    assert!(plan.setups.len() >= 2, "{:?}", plan.setups);
    let proof_settings = ProofSettings { resolution: 1.0, axis_tolerance: 0.05 };
    let proof = scallop_rough5::prove_from_blank(
        &plan.toolpath,
        &tool,
        &part.stock,
        part.blank.as_ref(),
        &part.mesh,
        &proof_settings,
        &|_, _| {},
    )
    .unwrap();
    assert!(proof.gouge_depth <= proof_settings.resolution, "{proof:?}");
    assert!(proof.remaining_percent < 100.0 && proof.removed_volume > 0.0, "{proof:?}");
}

/// The rest setups keep the shank and the holder off the in-process stock
/// (docs/rough5.md, "Baselines"): with 27 mm of flutes, 28 mm out of a holder
/// R 20, a setup leaning 15 deg puts the holder's rim under the block's top
/// next to the undercut flanks, which the setup's levels (the flutes against
/// the pocket's faces) do not see. The 3+2 program is planned and proven,
/// its shank and holder clear of the stock along every move.
#[test]
fn rest_setups_keep_the_holder_off_the_stock() {
    let part = closed_pocket(&PocketParams::default()).unwrap();
    let f = faces(&part);
    let tool =
        TorusTool { flutes: 27.0, stick_out: 28.0, holder_diameter: 40.0, holder_length: 100.0, ..TorusTool::THESIS }
            .cutter()
            .unwrap();
    let plan = plan_three_plus_two(&pocket(&part, &f), &tool, &settings()).unwrap();
    assert!(plan.setups.len() >= 2 && plan.setups[1..].iter().all(|s| s.passes > 0), "{:?}", plan.setups);
    let proof_settings = ProofSettings { resolution: 1.0, axis_tolerance: 0.05 };
    let proof = prove(&plan.toolpath, &tool, &part.stock, &part.mesh, &proof_settings, &|_, _| {}).unwrap();
    assert!(proof.min_stick_out <= 28.0, "{proof:?}");
}
