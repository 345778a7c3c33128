//! The guide-curve builder on the closed test pocket (100 x 100 x 35 mm,
//! drafts and undercuts, Jousselin 2020 Ch. 2 §4): every level has one closed
//! limit loop, its offsets are closed loops that do not cross themselves in
//! plan view, and every pair of neighbouring levels pairs.
#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

use scallop_guides::{GuideSettings, build_guides};
use scallop_mesh::Polyline3;
use scallop_parts::{FaceTag, PocketParams, closed_pocket};

/// Whether two segments of the plan view of `line` cross (brute force).
fn crosses_itself(line: &Polyline3) -> bool {
    let p: Vec<[f64; 2]> = line.points.iter().map(|q| [q.x, q.y]).collect();
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

#[test]
fn the_closed_pocket_has_closed_guide_curves_on_every_level() {
    let part = closed_pocket(&PocketParams::default()).unwrap();
    let bottom = part.faces(&[FaceTag::Bottom]).unwrap();
    let flanks = part.faces(&[FaceTag::Flank]).unwrap();
    let depth = part.stock.max.z - bottom.bounds().max.z;
    let settings =
        GuideSettings { tool_radius: 5.0, flank_allowance: 0.5, axial_step: 4.0, radial_step: 4.5, voxel: 1.0, depth };
    let set = build_guides(&bottom, &flanks, &settings).unwrap();
    assert!(set.levels.len() >= 4, "{} levels", set.levels.len());
    for (k, level) in set.levels.iter().enumerate() {
        assert_eq!((level.limit.loops.len(), level.limit.open.len()), (1, 0), "level {k}");
        assert!(!level.offsets.is_empty(), "level {k}: no path curve");
        for step in &level.offsets {
            for c in &step.curves {
                assert!(c.line.closed && !crosses_itself(&c.line), "level {k}");
            }
        }
        assert!(!crosses_itself(&level.limit.loops[0].line), "level {k}: limit curve");
    }
    assert_eq!(set.pairs.len(), set.levels.len() - 1);
    for (k, pair) in &set.pairs {
        let pair = pair.as_ref().unwrap();
        assert_eq!(pair.path.len(), pair.tilt.len(), "levels {k} and {}", k + 1);
        assert!(pair.path_spacing <= settings.radial_step + 2.0 * settings.voxel, "{}", pair.path_spacing);
    }
}
