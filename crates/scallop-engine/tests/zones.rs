//! Zone finishing (issue 8): zone-restricted drop-cutter planning on a
//! synthetic two-zone labelling of a Bezier patch, and `finish_zones` on it.
//!
//! - every cutter location of a zone's passes has its contact in the zone
//!   dilated by the margin (checked by dropping the cutter again and measuring
//!   the contact's XY distance to the zone's triangles by brute force);
//! - the union of the two zones' passes finishes the surface: the simulated
//!   stock holds the scallop (<= sh + the simulation's resolution bound) with no
//!   gouge, borders included;
//! - one zone alone does not: the simulated scallop over the whole surface is
//!   far above sh (the test would catch a region rule that ignores the zone).

#![allow(clippy::unwrap_used, reason = "tests fail loudly by design")]

use scallop_cutter::{Contact, Cutter, CutterShape, drop_cutter};
use scallop_engine::{
    FinishJob, Part, ProgramCandidate, ZonePlanSpec, ZoneSpec, finish_candidates, finish_zones, run_finishing,
};
use scallop_geom::{Aabb3, Point2, Point3, Tolerances};
use scallop_mesh::{MeshIndex, TriMesh};
use scallop_network::{CellLabels, Transitions};
use scallop_sim::{VerifyOptions, simulate};
use scallop_strategy::{FinishingParams, Pattern, ZoneRegion, plan_zone_finishing};
use scallop_surface::{Patch, SurfaceSet};
use scallop_toolpath::{MoveKind, Toolpath};

/// A bicubic Bezier hill over 40 x 30 mm, up to about 8 mm high.
fn hill() -> Patch {
    let heights = [[0.0, 2.0, 3.0, 1.0], [1.0, 9.0, 7.0, 2.0], [2.0, 8.0, 10.0, 3.0], [0.0, 3.0, 2.0, 0.0]];
    let control: Vec<Vec<Point3>> = (0..4)
        .map(|i| (0..4).map(|j| Point3::new(40.0 * i as f64 / 3.0, 30.0 * j as f64 / 3.0, heights[i][j])).collect())
        .collect();
    Patch::bezier("hill", [3, 3], &control, None).unwrap()
}

fn cutter() -> Cutter {
    Cutter::new(CutterShape::Bull { radius: 3.0, corner: 1.0 }, 30.0).unwrap()
}

/// Two zones split along an oblique line in (u, v): u + 0.6 v < 0.8.
fn labels() -> CellLabels {
    let n = 40;
    let labels = (0..n * n)
        .map(|k| {
            let (a, b) = (k / n, k % n);
            let (u, v) = ((a as f64 + 0.5) / n as f64, (b as f64 + 0.5) / n as f64);
            u32::from(u + 0.6 * v >= 0.8)
        })
        .collect();
    CellLabels { cells_u: n, cells_v: n, labels }
}

/// A zone of the hill planned in the part's frame (no tilt), feeding along
/// `direction_deg`.
fn zone(label: u32, direction_deg: f64, predicted_time_s: Option<f64>) -> ZoneSpec {
    ZoneSpec { label, direction_deg, tilt_deg: 0.0, azimuth_deg: 0.0, predicted_time_s }
}

/// The spec of `zones` over [`labels`], default transitions and no fixed margin.
fn spec(
    zones: Vec<ZoneSpec>,
    predicted_time_s: Option<f64>,
    machine: Option<scallop_machine::Machine>,
) -> ZonePlanSpec {
    ZonePlanSpec {
        labels: labels(),
        zones,
        transitions: Transitions::default(),
        predicted_time_s,
        fixed_margin_mm: None,
        machine,
    }
}

/// Zigzag finishing parameters along `direction` (radians) for scallop height `sh`.
fn zigzag(direction: f64, sh: f64) -> FinishingParams {
    FinishingParams {
        direction,
        pattern: Pattern::Zigzag,
        scallop_height: sh,
        boundary: scallop_strategy::Boundary::ContactInside,
        max_step: 0.5,
        clearance: 5.0,
        machine: scallop_analysis::MachineLimits::default(),
        plunge_feed: 20.0,
        rapid_rate: 500.0,
        sharp_corner: 30f64.to_radians(),
        blend_tolerance: 0.01,
    }
}

/// The contact point of every pass point of `planned`, found by dropping the
/// cutter again onto `index` from `floor`.
fn pass_contacts(planned: &scallop_strategy::Planned, index: &MeshIndex, floor: f64) -> Vec<Point3> {
    let mut contacts = Vec::new();
    for plane in &planned.planes {
        for pass in &plane.passes {
            for p in pass {
                let cl = drop_cutter(&cutter(), index, Point2::new(p.x, p.y), floor);
                if let Contact::Facet { point, .. } | Contact::Edge { point, .. } | Contact::Vertex { point, .. } =
                    cl.contact
                {
                    contacts.push(point);
                }
            }
        }
    }
    contacts
}

fn job(sh: f64) -> FinishJob {
    FinishJob {
        part: Part::Surfaces(SurfaceSet::new(vec![hill()]).unwrap()),
        part_name: "hill".into(),
        cutter: cutter(),
        scallop_height: sh,
        sim_resolution: 0.1,
        ..FinishJob::choi_demo()
    }
}

#[test]
fn two_zones_cover_the_hill_within_the_scallop_and_stay_in_their_regions() {
    let sh = 0.02;
    let spec = spec(vec![zone(0, 0.0, None), zone(1, 70.0, None)], None, None);
    // finish_zones fails on a gouge, a rapid into stock or a simulated scallop over the limit.
    let out = finish_zones(&job(sh), &spec).unwrap();
    let r = &out.report;
    assert_eq!(r.zones.len(), 2);
    for z in &r.zones {
        assert!(z.passes > 5 && z.skipped.is_none(), "{z:?}");
        assert!(z.max_scallop_mm <= sh * (1.0 + 1e-6), "{z:?}");
        assert!(z.margin_mm >= 2.0 * z.max_spacing_mm, "{z:?}");
        assert!(z.region_triangles > z.triangles, "{z:?}");
    }
    assert!(r.sim_max_scallop_mm <= r.sim_scallop_limit_mm, "{r:?}");
    assert!(r.sim_max_scallop_mm > 0.3 * sh, "a stock left untouched? {r:?}");
    assert!(r.sim_min_deviation_mm >= -r.sim_gouge_tolerance_mm, "{r:?}");
    assert_eq!(r.transitions, 1);
    assert!(r.transition_time_s > 0.0 && r.transition_time_model_s > 0.0);
    assert_eq!(out.zone_of_move.len(), out.toolpath.moves().len());
    assert!(out.gcode.contains("simulated scallop"));
    // Deterministic: the same program on one thread.
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    assert_eq!(one.install(|| finish_zones(&job(sh), &spec).unwrap()).gcode, out.gcode);

    // Every CL point of zone 0's passes has its contact within the margin of zone 0.
    let prepared = &out.prepared;
    let mesh = &prepared.mesh;
    let zone0 = &r.zones[0];
    let labels_of_triangles = triangle_labels(mesh, &spec.labels);
    let zone_vertices: Vec<Point3> = mesh
        .triangles()
        .iter()
        .zip(&labels_of_triangles)
        .filter(|(_, l)| **l == 0)
        .flat_map(|(t, _)| t.map(|v| mesh.vertices()[v as usize]))
        .collect();
    let longest_edge = mesh
        .triangles()
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
        .map(|(a, b)| (mesh.vertices()[a as usize] - mesh.vertices()[b as usize]).norm())
        .fold(0.0, f64::max);
    let floor = mesh.bounds().min.z - 100.0;
    let mut checked = 0;
    for (m, &zone) in out.toolpath.moves().iter().zip(&out.zone_of_move) {
        if zone != 0 || m.kind != MoveKind::Feed {
            continue;
        }
        let cl = drop_cutter(&cutter(), &prepared.index, Point2::new(m.to.x, m.to.y), floor);
        let point = match cl.contact {
            Contact::Facet { point, .. } | Contact::Edge { point, .. } | Contact::Vertex { point, .. } => point,
            Contact::Floor => panic!("a pass point over nothing: {m:?}"),
        };
        let distance = zone_vertices.iter().map(|v| (v.x - point.x).hypot(v.y - point.y)).fold(f64::INFINITY, f64::min);
        assert!(distance <= zone0.margin_mm + longest_edge, "{distance} at {point:?}");
        checked += 1;
    }
    assert!(checked > 100, "{checked}");
}

/// The final choice's candidates (issue 20): each result is the program its
/// candidate gives alone (a zone plan: `finish_zones`; a single zone: the
/// program of `run_finishing` along that direction, proven), in input order, and
/// the same on one thread.
#[test]
fn candidates_are_the_programs_they_name_in_order() {
    let sh = 0.02;
    let spec = spec(vec![zone(0, 0.0, Some(10.0)), zone(1, 70.0, Some(10.0))], Some(20.0), None);
    let candidates = [
        ProgramCandidate::SingleZone { direction_deg: 70.0, predicted_time_s: Some(20.0) },
        ProgramCandidate::Zones(spec.clone()),
        ProgramCandidate::SingleZone { direction_deg: 0.0, predicted_time_s: None },
    ];
    let job = job(sh);
    let results: Vec<_> = finish_candidates(&job, &candidates).into_iter().map(Result::unwrap).collect();
    assert_eq!(results[1].gcode, finish_zones(&job, &spec).unwrap().gcode);
    for (k, direction) in [(0, 70.0), (2, 0.0)] {
        let alone = run_finishing(&FinishJob { direction_deg: Some(direction), ..job.clone() }).unwrap();
        let r = &results[k].report;
        assert_eq!(results[k].gcode, alone.gcode);
        assert_eq!(r.plan.total_time_s.to_bits(), alone.report.plan.total_time_s.to_bits());
        assert_eq!((r.zones.len(), r.zones[0].direction_deg.to_bits(), r.transitions), (1, direction.to_bits(), 0));
        assert_eq!(r.zones[0].passes, alone.report.plan.passes);
        assert!(r.sim_max_scallop_mm <= r.sim_scallop_limit_mm && r.sim_max_scallop_mm > 0.3 * sh, "{r:?}");
        assert_eq!(results[k].zone_of_move.len(), results[k].toolpath.moves().len());
    }
    assert_eq!(
        results[0].report.time_ratio.map(f64::to_bits),
        Some((results[0].report.plan.total_time_s / 20.0).to_bits())
    );
    assert_eq!(results[2].report.time_ratio, None);
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    let again = one.install(|| finish_candidates(&job, &candidates));
    for (a, b) in again.iter().zip(&results) {
        assert_eq!(a.as_ref().unwrap().gcode, b.gcode);
    }
}

#[test]
fn one_zone_alone_leaves_the_other_uncut() {
    let sh = 0.02;
    let job = job(sh);
    let Part::Surfaces(set) = &job.part else { unreachable!() };
    let tolerances = Tolerances { path: 0.01, gouge: 0.0 };
    let tessellation = set.tessellate(tolerances.tessellation()).unwrap();
    let mesh = tessellation.mesh;
    let index = MeshIndex::build(&mesh);
    // A synthetic labelling by the triangle's XY centroid: x < 20 mm is zone 0.
    let labels: Vec<u32> = (0..mesh.triangles().len())
        .map(|t| {
            let c = mesh.triangle(t);
            u32::from((c[0].x + c[1].x + c[2].x) / 3.0 >= 20.0)
        })
        .collect();
    let region = ZoneRegion::new(&mesh, &labels, 0, 2.0).unwrap();
    let params = zigzag(0.3, sh);
    let planned = plan_zone_finishing(&index, &cutter(), &params, &tolerances, &region).unwrap();
    assert!(planned.scallop.max_mm <= sh * (1.0 + 1e-6));
    // Every pass point's contact lies at x < 20 + margin + a triangle.
    for point in pass_contacts(&planned, &index, mesh.bounds().min.z - 100.0) {
        assert!(point.x <= 20.0 + 2.0 + 1.5, "{point:?}");
    }
    let b = mesh.bounds();
    let stock = Aabb3 {
        min: Point3::new(b.min.x - 3.0, b.min.y - 3.0, b.min.z - 1.0),
        max: Point3::new(b.max.x + 3.0, b.max.y + 3.0, b.max.z + 1.0),
    };
    let options = VerifyOptions { gouge_tolerance: 0.02, scallop_margin: 3.0, ..VerifyOptions::default() };
    let sim = simulate(stock, 0.2, &cutter(), &planned.toolpath, &index, &options).unwrap();
    assert!(sim.verification.max_thickness > 0.5, "{:?}", sim.verification.max_thickness);
    let _: &Toolpath = &planned.toolpath;
}

/// Labels of the machining mesh's triangles, by the cell under the parameter
/// point nearest to the triangle's centroid (brute force, independent of the
/// engine's grid bookkeeping).
fn triangle_labels(mesh: &TriMesh, labels: &CellLabels) -> Vec<u32> {
    let patch = hill();
    (0..mesh.triangles().len())
        .map(|t| {
            let c = mesh.triangle(t);
            let centroid = Point3::from((c[0].coords + c[1].coords + c[2].coords) / 3.0);
            let closest = patch.closest_point(&centroid);
            labels.label_at(closest.u, closest.v)
        })
        .collect()
}

#[test]
fn a_tilted_zone_is_an_indexed_setup_proven_in_its_own_frame() {
    let sh = 0.02;
    let tilted = ZoneSpec { tilt_deg: 20.0, azimuth_deg: 150.0, ..zone(1, 30.0, None) };
    let machine = scallop_machine::Machine::builtin("linuxcnc-xyzac-trt").unwrap();
    let spec = spec(vec![zone(0, 0.0, None), tilted], None, Some(machine));
    let job =
        FinishJob { cutter: Cutter::new(CutterShape::Bull { radius: 3.0, corner: 1.0 }, 60.0).unwrap(), ..job(sh) };
    // finish_zones fails on a gouge or collision in either frame, or a zone that
    // leaves more than sh + the resolution bound on its own triangles.
    let out = finish_zones(&job, &spec).unwrap();
    let r = &out.report;
    assert!(r.indexed && out.simulation.is_none());
    for z in &r.zones {
        let own = z.sim_zone_scallop_mm.unwrap();
        assert!(own <= r.sim_scallop_limit_mm && own > 0.3 * sh, "{z:?}");
        assert!(z.passes > 5 && z.max_scallop_mm <= sh * (1.0 + 1e-6), "{z:?}");
    }
    assert!(r.sim_min_deviation_mm >= -r.sim_gouge_tolerance_mm, "{r:?}");
    // Two setups: the rotaries are positioned twice, tilt 0 then tilt 20 degrees.
    let rotary_blocks: Vec<&str> = out.gcode.lines().filter(|l| l.contains(" A")).collect();
    assert_eq!(rotary_blocks.len(), 2, "{rotary_blocks:?}");
    assert!(rotary_blocks[1].contains("A20.0000") || rotary_blocks[1].contains("A-20.0000"), "{rotary_blocks:?}");
    // The program replays through the machine's forward kinematics onto the part-frame
    // cutter locations with each zone's tool axis.
    let machine = spec.machine.as_ref().unwrap();
    let kin = scallop_machine::Kinematics::new(machine, 0.0);
    let mut records = Vec::new();
    let mut start = 0;
    let moves = out.toolpath.moves();
    while start < moves.len() {
        let end = (start..moves.len()).find(|&k| out.zone_of_move[k] != out.zone_of_move[start]).unwrap_or(moves.len());
        let mut piece = Toolpath::new(out.toolpath.feed);
        piece.plunge_feed = out.toolpath.plunge_feed;
        for m in &moves[start..end] {
            piece.push(*m);
        }
        records.extend(scallop_machine::program::records_from_toolpath(&piece, &out.toolpath.axis(start)));
        start = end;
    }
    let blocks = scallop_post::replay(&out.gcode, &job.output.dialect, &kin).unwrap();
    let options = scallop_machine::program::ProgramOptions::default();
    scallop_post::check_replay(&blocks, &records, &kin, &job.output.dialect, options.tol_pos, options.tol_ang).unwrap();
    // The part-frame toolpath's second zone lies on the turned-back CL surface: its
    // feed moves stay within the part's box grown by the cutter radius.
    let b = out.prepared.mesh.bounds();
    for (m, &zone) in out.toolpath.moves().iter().zip(&out.zone_of_move) {
        if zone == 1 && m.kind == MoveKind::Feed {
            assert!(m.to.x > b.min.x - 4.0 && m.to.x < b.max.x + 4.0 && m.to.z > b.min.z - 4.0, "{m:?}");
        }
    }
}

/// A U-shaped zone (two arms joined at low y): planes along X across the arms
/// give two passes each, and no pass point has its contact in the gap between
/// the arms beyond the margin.
#[test]
fn a_non_convex_zone_splits_its_planes_into_several_passes() {
    let sh = 0.02;
    let tolerances = Tolerances { path: 0.01, gouge: 0.0 };
    let mesh = SurfaceSet::new(vec![hill()]).unwrap().tessellate(tolerances.tessellation()).unwrap().mesh;
    let index = MeshIndex::build(&mesh);
    let in_u = |x: f64, y: f64| !(12.0..=28.0).contains(&x) || y < 8.0;
    let labels: Vec<u32> = (0..mesh.triangles().len())
        .map(|t| {
            let c = mesh.triangle(t);
            u32::from(!in_u((c[0].x + c[1].x + c[2].x) / 3.0, (c[0].y + c[1].y + c[2].y) / 3.0))
        })
        .collect();
    let margin = 1.0;
    let region = ZoneRegion::new(&mesh, &labels, 0, margin).unwrap();
    let params = zigzag(0.0, sh);
    let planned = plan_zone_finishing(&index, &cutter(), &params, &tolerances, &region).unwrap();
    let split = planned.planes.iter().filter(|p| p.passes.len() >= 2).count();
    assert!(split > 10, "{split} planes cross both arms");
    // The gap between the arms (x in [12 + margin + a triangle, 28 - margin - a triangle],
    // y > 8 + margin + a triangle) has no contact of the zone's passes.
    let floor = mesh.bounds().min.z - 100.0;
    for point in pass_contacts(&planned, &index, floor) {
        let deep = point.x > 12.0 + margin + 1.0 && point.x < 28.0 - margin - 1.0 && point.y > 8.0 + margin + 1.0;
        assert!(!deep, "{point:?}");
    }
}
