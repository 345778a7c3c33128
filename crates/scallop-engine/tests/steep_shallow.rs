//! Steep-and-shallow finishing (issue 15, items 2 to 4): on parts with walls
//! the default mesh strategy finishes the whole part, the stock simulation
//! proves no gouge and a scallop on the machined surface within sh plus its
//! resolution bound (so the overlap of planes and levels leaves no strip), and
//! the material the cutter cannot reach is reported, not counted as scallop.
#![allow(clippy::unwrap_used)]

use scallop_cutter::{Cutter, CutterShape};
use scallop_engine::{FinishJob, Part, Strategy, run_finishing};
use scallop_geom::Point3;
use scallop_mesh::TriMesh;

/// A height field `z(x, y)` over `[0, size]^2` triangulated on a grid of
/// `step`, with a flat skirt ring so the part's edge is level.
fn height_field(size: f64, step: f64, z: impl Fn(f64, f64) -> f64) -> TriMesh {
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let n = (size / step).round() as usize;
    let at = |i: usize, j: usize| {
        #[allow(clippy::cast_precision_loss)]
        let (x, y) = (i as f64 * step, j as f64 * step);
        Point3::new(x, y, z(x, y))
    };
    let mut soup = Vec::with_capacity(2 * n * n);
    for j in 0..n {
        for i in 0..n {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            soup.push([a, b, c]);
            soup.push([a, c, d]);
        }
    }
    TriMesh::from_soup(&soup).unwrap().0
}

fn job(mesh: TriMesh, cutter: Cutter, sh: f64) -> FinishJob {
    let mut job = FinishJob::choi_demo();
    job.part = Part::Mesh(mesh);
    job.part_name = "generated part".into();
    job.cutter = cutter;
    job.scallop_height = sh;
    job.direction_deg = Some(0.0);
    job.strategy = Strategy::SteepShallow { threshold_deg: None };
    job
}

/// Runs the job and checks what every steep-and-shallow plan must hold;
/// returns (waterline levels and planes, unreachable area).
fn finish_and_check(job: &FinishJob) -> (usize, f64) {
    let out = run_finishing(job).unwrap();
    let r = &out.report;
    assert!(
        r.sim_max_scallop_mm <= job.scallop_height + r.sim_resolution_bound_mm,
        "scallop on the machined surface {} > {} + {}",
        r.sim_max_scallop_mm,
        job.scallop_height,
        r.sim_resolution_bound_mm
    );
    assert!(r.sim_min_deviation_mm >= -r.sim_gouge_tolerance_mm, "gouge {}", r.sim_min_deviation_mm);
    if r.rest.area_mm2 > 0.0 {
        assert_eq!(r.rest.machined_scallop_mm, r.sim_max_scallop_mm);
        assert!(r.rest.depth_mm > job.scallop_height);
    }
    (r.plan.planes, r.rest.area_mm2)
}

fn ball(radius: f64) -> Cutter {
    Cutter::new(CutterShape::Ball { radius }, 30.0).unwrap()
}

#[test]
fn hemisphere_on_a_plate_is_finished_and_its_foot_reported() {
    let (c, radius) = (15.0, 9.0);
    let mesh = height_field(30.0, 0.25, |x, y| {
        let r2 = (x - c).powi(2) + (y - c).powi(2);
        (radius * radius - r2).max(0.0).sqrt()
    });
    let (planes, rest) = finish_and_check(&job(mesh, ball(2.0), 0.02));
    assert!(planes > 0);
    // The foot of the hemisphere is a right-angle corner: a ball leaves a fillet there.
    assert!(rest > 0.0, "no rest material reported at the foot");
}

#[test]
fn cone_on_a_plate_is_finished() {
    let c = 15.0;
    // A 60-degree cone, 10 mm tall, on a plate: steep flanks, flat plate, a sharp tip.
    let mesh = height_field(30.0, 0.25, |x, y| {
        let r = ((x - c).powi(2) + (y - c).powi(2)).sqrt();
        (10.0 - r * 60f64.to_radians().tan()).max(0.0)
    });
    finish_and_check(&job(mesh, ball(2.0), 0.02));
}

#[test]
fn pocket_with_steep_walls_is_finished() {
    // A 16 x 16 mm pocket 6 mm deep in a 30 mm plate: walls of the grid's 87 degrees.
    let mesh =
        height_field(30.0, 0.25, |x, y| if (7.0..=23.0).contains(&x) && (7.0..=23.0).contains(&y) { 0.0 } else { 6.0 });
    let (_, rest) = finish_and_check(&job(mesh, ball(2.0), 0.02));
    assert!(rest > 0.0, "the pocket's floor corners are tighter than the ball");
}

#[test]
fn inclined_wall_is_finished_with_a_bull_nose() {
    // A 65-degree ramp from a low floor to a high one.
    let k = 65f64.to_radians().tan();
    let mesh = height_field(30.0, 0.25, |x, _| (k * (x - 10.0)).clamp(0.0, 8.0));
    let cutter = Cutter::new(CutterShape::Bull { radius: 3.0, corner: 1.0 }, 30.0).unwrap();
    finish_and_check(&job(mesh, cutter, 0.02));
}

/// A terrace: a wall of `wall_deg` falling `width` mm (in XY) from a plateau
/// onto a face of `face_deg`, then a floor. With both slopes above the planes'
/// band (55 degrees for a ball) the waterline levels alone finish the concave
/// crease between the wall and the face, which runs along the levels; the cusp
/// of the two levels either side of it stands higher above the cutter's reach
/// (the profile circle sitting in the crease) than the spacing rule's scallop,
/// about linearly in the level spacing. The simulation measures it against the
/// reach.
fn terrace(wall_deg: f64, width: f64, face_deg: f64) -> TriMesh {
    let (kw, kf) = (wall_deg.to_radians().tan(), face_deg.to_radians().tan());
    let (top, crest) = (6.0, 8.0);
    height_field(20.0, 0.25, move |_, y| {
        if y <= crest {
            top
        } else if y <= crest + width {
            top - kw * (y - crest)
        } else {
            (top - kw * width - kf * (y - crest - width)).max(0.0)
        }
    })
}

#[test]
fn concave_crease_between_steep_walls_holds_the_scallop() {
    finish_and_check(&job(terrace(85.0, 0.25, 58.0), ball(1.5), 0.05));
}

#[test]
fn concave_crease_between_steep_walls_holds_the_scallop_with_a_bull_nose() {
    let cutter = Cutter::new(CutterShape::Bull { radius: 3.0, corner: 1.0 }, 30.0).unwrap();
    finish_and_check(&job(terrace(85.0, 0.25, 62.0), cutter, 0.05));
}

/// A ridge along X (a cylinder of radius 5 at its crest, flanks of 30
/// degrees, down to a floor at 0) cut across by a slot 1 mm wide and 3 mm
/// deep at x = 15: the slot is rest material on every plane pair that
/// crosses it, the ridge is a convex surface where the spacing rule (a
/// model of planes) is optimistic.
fn ridge_with_a_slot(x: f64, y: f64) -> f64 {
    let (radius, flank) = (5.0_f64, 30_f64.to_radians());
    let u = (y - 15.0).abs();
    let edge = radius * flank.sin();
    let crest =
        if u <= edge { (radius * radius - u * u).sqrt() } else { radius * flank.cos() - (u - edge) * flank.tan() };
    let slot = if (x - 15.0).abs() < 0.5 { 3.0 } else { 0.0 };
    crest.max(0.0) + 2.0 - slot
}

#[test]
fn rest_on_one_section_does_not_leave_the_rest_of_the_plane_pair_unchecked() {
    // Steep-and-shallow's planes alone (no refinement by the simulation): the
    // stock simulation of the program holds sh plus its resolution bound on
    // the machined surface, for a bull-nose and a ball.
    let mesh = height_field(30.0, 0.25, ridge_with_a_slot);
    let bull = Cutter::new(CutterShape::Bull { radius: 3.0, corner: 1.0 }, 30.0).unwrap();
    for cutter in [bull, ball(1.5)] {
        let job = job(mesh.clone(), cutter.clone(), 0.05);
        let index = scallop_mesh::MeshIndex::build(&mesh);
        let split = scallop_strategy::SteepShallow::default_for(&cutter, job.scallop_height);
        let params = job.timing_params();
        let plan = scallop_strategy::plan_steep_shallow(
            &mesh,
            &index,
            &cutter,
            &params,
            &job.tolerances,
            &split,
            &scallop_strategy::Refinement::default(),
        )
        .unwrap();
        let stock = scallop_engine::stock_box(&mesh, cutter.radius());
        // The engine's allowance on a mesh part (no chordal error).
        let gouge_tolerance = job.tolerances.gouge + job.tolerances.path;
        let options =
            scallop_sim::VerifyOptions { gouge_tolerance, scallop_margin: cutter.radius(), ..Default::default() };
        let sim = scallop_sim::simulate(stock, job.sim_resolution, &cutter, &plan.toolpath, &index, &options).unwrap();
        let limit = job.scallop_height + sim.zmap.resolution_bound(cutter.shape());
        let field = scallop_sim::PartField::new(&sim.zmap, &index);
        let rest = scallop_sim::split_rest(&sim.zmap, &field, &index, &cutter, &options, limit);
        assert!(
            rest.machined_max <= limit,
            "{:?}: scallop {} at {:?} over {limit}",
            cutter.shape(),
            rest.machined_max,
            rest.machined_at
        );
        assert!(rest.unreachable_area > 0.0, "the slot is not reported");
    }
}
