//! The bottom level on a floor triangulated into long slivers (docs/rough5.md,
//! "The fitting pocket: a bottom without offsets"): `refine_facets` splits
//! every edge longer than asked, keeps the area and the boundary (no
//! T-junction: the edges used once are the outline's, no longer in all) and
//! the facets' plane; on the fitting pocket, whose ear-clipped flat floor
//! has facets across the whole pocket, the bottom level's passes reach every
//! point of the bottom inside its limit curve within the tool radius.
#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

use std::collections::HashMap;

use proptest::prelude::*;
use scallop_geom::Point3;
use scallop_guides::GuideSettings;
use scallop_mesh::{Polyline3, PolylineQuery, TriMesh};
use scallop_parts::{FaceTag, fitting_pocket};
use scallop_rough5::{LevelOptions, TiltMode, level_passes_with, refine_facets};

/// The edges used by one facet only, and their total length.
fn boundary(mesh: &TriMesh) -> (usize, f64) {
    let mut count: HashMap<(u32, u32), usize> = HashMap::new();
    for t in mesh.triangles() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *count.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let v = mesh.vertices();
    let once: Vec<_> = count.iter().filter(|e| *e.1 == 1).map(|e| *e.0).collect();
    (once.len(), once.iter().map(|&(a, b)| (v[a as usize] - v[b as usize]).norm()).sum())
}

fn longest_edge(mesh: &TriMesh) -> f64 {
    (0..mesh.triangles().len())
        .map(|i| {
            let c = mesh.triangle(i);
            (c[1] - c[0]).norm().max((c[2] - c[1]).norm()).max((c[0] - c[2]).norm())
        })
        .fold(0.0, f64::max)
}

proptest! {
    /// A fan of slivers (a convex polygon triangulated from one corner, as
    /// ear clipping does) refined to `longest`: no longer edge, the same
    /// area, the same boundary length with no T-junction inside, every
    /// vertex on the plane.
    #[test]
    fn refined_facets_are_short_and_conforming(
        n in 3usize..12,
        rx in 20.0f64..120.0,
        ry in 2.0f64..60.0,
        slope in -0.3f64..0.3,
        longest in 0.7f64..6.0,
    ) {
        let ring: Vec<Point3> = (0..n)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / n as f64;
                let (x, y) = (rx * a.cos(), ry * a.sin());
                Point3::new(x, y, slope * x)
            })
            .collect();
        let tris: Vec<[usize; 3]> = (1..n - 1).map(|i| [0, i, i + 1]).collect();
        let mesh = TriMesh::from_indexed(&ring, &tris).unwrap().0;
        let fine = refine_facets(&mesh, longest).unwrap();
        prop_assert!(longest_edge(&fine) <= longest * (1.0 + 1e-9));
        prop_assert!((fine.area() - mesh.area()).abs() <= 1e-9 * mesh.area());
        let (before, after) = (boundary(&mesh), boundary(&fine));
        prop_assert!((after.1 - before.1).abs() <= 1e-9 * before.1, "boundary {} -> {}", before.1, after.1);
        for p in fine.vertices() {
            prop_assert!((p.z - slope * p.x).abs() <= 1e-9 * rx);
        }
        prop_assert!(refine_facets(&mesh, 0.0).is_err());
    }
}

/// Every point of the fitting's bottom inside the bottom level's limit curve
/// (seen along Z, every 1 mm) is within the tool radius plus half a step
/// of one of the bottom level's passes: the floor's offsets are there (the
/// worst point, 6.0 mm away, is where the third offset of the +x chamber is
/// not found at the bottom while it is on the levels above: docs/rough5.md).
/// Without the refinement the bottom level is its limit curve alone and the
/// chambers' middles are more than 10 mm from it.
#[test]
fn the_fitting_bottom_is_reached() {
    let part = fitting_pocket(&Default::default()).unwrap();
    let bottom = part.faces(&[FaceTag::Bottom]).unwrap();
    let flanks = part.faces(&[FaceTag::Flank]).unwrap();
    let radius = 5.0;
    let guides = GuideSettings {
        tool_radius: radius,
        flank_allowance: 0.5,
        axial_step: 4.0,
        radial_step: 4.5,
        voxel: 1.0,
        depth: part.stock.max.z - bottom.bounds().min.z,
    };
    let options = LevelOptions { centre_offsets: true, pair_by_rank: true, open_bottom: true };
    let levels = level_passes_with(&bottom, &flanks, &guides, TiltMode::Guides, &options).unwrap();
    let floor = &levels[0];
    let flat = |l: &Polyline3| Polyline3::new(l.points.iter().map(|p| Point3::new(p.x, p.y, 0.0)).collect(), l.closed);
    let limit = flat(&floor.passes.last().unwrap().0.line);
    let passes = PolylineQuery::new(floor.passes.iter().map(|(c, _)| flat(&c.line)).collect());
    let inside = |p: &Point3| {
        let mut odd = false;
        for s in 0..limit.segment_count() {
            let (a, b) = limit.segment(s);
            if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x) {
                odd = !odd;
            }
        }
        odd
    };
    let b = limit.bounds().unwrap();
    let mut worst = (0.0, Point3::origin());
    let mut x = b.min.x;
    while x <= b.max.x {
        let mut y = b.min.y;
        while y <= b.max.y {
            let p = Point3::new(x, y, 0.0);
            let d = passes.distance(&p);
            if inside(&p) && d > worst.0 {
                worst = (d, p);
            }
            y += 1.0;
        }
        x += 1.0;
    }
    assert!(
        worst.0 < radius + 0.5 * guides.radial_step,
        "the bottom point {:?} is {:.2} mm from every bottom pass",
        worst.1,
        worst.0
    );
    assert!(floor.passes.len() > 1, "the bottom level has {} pass(es)", floor.passes.len());
}
