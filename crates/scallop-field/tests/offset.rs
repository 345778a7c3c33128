//! Offsets by the voxel field against exact distances (the roughing
//! specification's check of Marching Cubes offsets, docs/guides.md): every
//! vertex within h / 2 of the offset distance for h in {1, 0.5, 0.25} mm,
//! watertight on closed input, no self-intersection, a spread that shrinks
//! with h.

#![allow(clippy::unwrap_used, reason = "tests")]

mod common;

use common::{brute_distance, cylinder, open_and_nonmanifold_edges, self_intersections, sphere, square};
use scallop_field::{FieldError, LevelOptions, Side, Surface, morph_levels, offset_levels};
use scallop_mesh::TriMesh;

const VOXELS: [f64; 3] = [1.0, 0.5, 0.25];

/// (min, max) of distance(vertex, S) - d over the level's vertices.
fn deviation(level: &TriMesh, surface: &TriMesh, d: f64) -> (f64, f64) {
    level.vertices().iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        let e = brute_distance(v, surface) - d;
        (lo.min(e), hi.max(e))
    })
}

fn check_shape(mesh: &TriMesh, d: f64, closed: bool) {
    let surface = Surface::new(mesh);
    let mut spreads = Vec::new();
    for h in VOXELS {
        let options = LevelOptions { voxel: h, side: Side::Along, ..LevelOptions::default() };
        let levels = offset_levels(&surface, &[d], &options).unwrap();
        let (lo, hi) = deviation(&levels[0], mesh, d);
        assert!(lo >= -0.5 * h && hi <= 0.5 * h, "h = {h}: deviation [{lo}, {hi}] beyond h / 2");
        if closed {
            assert_eq!(open_and_nonmanifold_edges(&levels[0]), (0, 0), "h = {h}: not watertight");
        }
        spreads.push(hi - lo);
    }
    assert!(spreads[2] < spreads[0], "spread does not shrink with h: {spreads:?}");
}

#[test]
fn plane_offset_within_half_voxel() {
    check_shape(&square(20.0, 0.0, 4), 2.0, false);
}

#[test]
fn sphere_offset_within_half_voxel_and_watertight() {
    check_shape(&sphere(10.0, 3), 2.0, true);
}

#[test]
fn cylinder_offset_within_half_voxel_and_watertight() {
    check_shape(&cylinder(8.0, 20.0, 48), 1.5, true);
}

#[test]
fn several_levels_from_one_field_keep_their_distances() {
    let mesh = sphere(6.0, 2);
    let ds = [1.0, 2.0, 3.0];
    let levels = offset_levels(&Surface::new(&mesh), &ds, &LevelOptions::default()).unwrap();
    assert_eq!(levels.len(), 3);
    for (level, d) in levels.iter().zip(ds) {
        let (lo, hi) = deviation(level, &mesh, d);
        assert!(lo >= -0.25 && hi <= 0.25, "d = {d}: [{lo}, {hi}]");
    }
}

#[test]
fn inner_sheet_of_a_sphere_is_behind_its_normals() {
    let mesh = sphere(8.0, 3);
    let levels =
        offset_levels(&Surface::new(&mesh), &[2.0], &LevelOptions { side: Side::Against, ..LevelOptions::default() })
            .unwrap();
    assert!(levels[0].vertices().iter().all(|v| (v.coords.norm() - 6.0).abs() < 0.25));
    assert_eq!(open_and_nonmanifold_edges(&levels[0]), (0, 0));
}

#[test]
fn small_offsets_do_not_self_intersect() {
    for mesh in [sphere(4.0, 2), cylinder(3.0, 6.0, 16)] {
        let level =
            offset_levels(&Surface::new(&mesh), &[1.0], &LevelOptions { voxel: 0.5, ..LevelOptions::default() })
                .unwrap();
        assert_eq!(self_intersections(&level[0]), 0);
    }
}

#[test]
fn open_plane_keeps_one_sheet_per_side() {
    let mesh = square(10.0, 0.0, 2);
    let surface = Surface::new(&mesh);
    let along = offset_levels(&surface, &[1.0], &LevelOptions::default()).unwrap();
    let against =
        offset_levels(&surface, &[1.0], &LevelOptions { side: Side::Against, ..LevelOptions::default() }).unwrap();
    // Triangles are kept by their centroid: a cap triangle across the plane's
    // extension may reach below it by less than a voxel.
    let h = LevelOptions::default().voxel;
    assert!(along[0].vertices().iter().all(|v| v.z > -h));
    assert!(against[0].vertices().iter().all(|v| v.z < h));
    assert!(along[0].vertices().iter().filter(|v| v.z > 0.5).count() > along[0].vertices().len() / 2);
}

#[test]
fn morph_between_parallel_planes_gives_one_sheet_per_level() {
    let (bottom, top) = (square(20.0, 0.0, 2), square(20.0, 10.0, 2));
    let options = LevelOptions { voxel: 0.5, ..LevelOptions::default() };
    let levels = morph_levels(&Surface::new(&bottom), &Surface::new(&top), 2, &options).unwrap();
    for (k, level) in levels.iter().enumerate() {
        let z = 10.0 * (k + 1) as f64 / 3.0;
        for v in level.vertices() {
            assert!(v.z > 0.0 && v.z < 10.0, "spurious sheet at {v:?}");
            if (0.0..=20.0).contains(&v.x) && (0.0..=20.0).contains(&v.y) {
                assert!((v.z - z).abs() <= 0.25, "level {k}: {v:?} off z = {z}");
            }
        }
    }
}

#[test]
fn absurd_grid_is_refused_with_the_fix() {
    let mesh = sphere(50.0, 1);
    let err = offset_levels(&Surface::new(&mesh), &[1.0], &LevelOptions { voxel: 0.001, ..LevelOptions::default() })
        .unwrap_err();
    assert!(matches!(err, FieldError::GridTooLarge { .. }));
    assert!(err.to_string().contains("use a voxel size of at least"));
    let bad = offset_levels(&Surface::new(&mesh), &[-1.0], &LevelOptions::default()).unwrap_err();
    assert!(matches!(bad, FieldError::BadDistance { index: 0, .. }));
}

#[test]
fn same_levels_on_one_and_two_threads() {
    let mesh = sphere(5.0, 2);
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| offset_levels(&Surface::new(&mesh), &[1.0, 2.0], &LevelOptions::default()).unwrap())
    };
    let (a, b) = (run(1), run(2));
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(x.triangles(), y.triangles());
        let bits =
            |m: &TriMesh| m.vertices().iter().flat_map(|v| [v.x, v.y, v.z].map(f64::to_bits)).collect::<Vec<_>>();
        assert_eq!(bits(x), bits(y));
    }
}
