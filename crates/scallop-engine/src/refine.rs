//! Refinement of a finishing plan by its simulation (docs/simulation.md,
//! "Refinement"). The planners hold `sh` by what they measure: between two
//! planes at the feed samples, between two waterline levels at their points.
//! A concave crease or a narrow feature between those samples can leave more
//! than `sh` on surface the cutter does reach, which only the stock
//! simulation sees. Rather than refuse the part, the engine takes the cells
//! the simulation names ([`scallop_sim::RestSplit::machined_over`]), finds the
//! two planes (or levels) that bracket each, and plans again with one more
//! plane (or level) half-way between them; the new program is simulated and
//! proven like the first. A plane's passes leave their scallop where the
//! cutter touches the part, beside the plane on a slope (by `R sin s` for a
//! ball, `R - r + r sin s` for a bull-nose, towards the uphill side): a cell
//! is bracketed by the planes of the cutter locations that touch it. After [`MAX_ROUNDS`] rounds a scallop still over
//! the limit is refused as before.

use std::collections::BTreeSet;

use scallop_cutter::{Cutter, CutterShape};
use scallop_geom::predicates::in_triangle;
use scallop_geom::{Aabb2, Point2, Vec3};
use scallop_mesh::MeshIndex;
use scallop_sim::OverCell;
use scallop_strategy::Refinement;

/// Rounds of refinement before a scallop over the limit is refused.
pub const MAX_ROUNDS: usize = 2;

/// Offsets closer than this are one (mm): two cells bracketed by the same
/// pair give the same mid-plane.
const SAME_OFFSET: f64 = 1e-6;

/// Where a plan put its passes: what a refinement needs to bracket a place.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct Layout {
    /// Feed direction (rad from +X).
    pub(crate) direction: f64,
    /// Plane offsets `d = m . p`, increasing (mm).
    pub(crate) planes: Vec<f64>,
    /// Waterline tip heights, decreasing (mm).
    pub(crate) levels: Vec<f64>,
    /// Slopes (rad): a cell at least `steep_min` steep is bracketed by levels,
    /// one under `shallow_max` by planes (both in the steep-and-shallow
    /// overlap band; planes alone when there are no levels).
    pub(crate) steep_min: f64,
    pub(crate) shallow_max: f64,
}

/// The planes and levels to add to `layout` for the cells `over`: one half-way
/// between the two that bracket each cell, one through a cell beyond the
/// first or last (the planner drops those without passes).
pub(crate) fn refinement_for(layout: &Layout, over: &[OverCell], cutter: &Cutter, index: &MeshIndex) -> Refinement {
    let m = (-layout.direction.sin(), layout.direction.cos());
    // The tip of a cutter touching the part at the cell lies this much below
    // the contact per unit of (1 - n_z): the corner radius.
    let corner = match *cutter.shape() {
        CutterShape::Ball { radius } => radius,
        CutterShape::Bull { corner, .. } => corner,
        _ => 0.0,
    };
    let key = |v: f64| {
        #[allow(clippy::cast_possible_truncation, reason = "offsets of a bounded part in units of SAME_OFFSET")]
        let k = (v / SAME_OFFSET).round() as i64;
        k
    };
    let (mut planes, mut levels) = (BTreeSet::new(), BTreeSet::new());
    let mut scratch = Vec::new();
    for cell in over {
        let slope = cell.nz.abs().min(1.0).acos();
        let by_levels = !layout.levels.is_empty() && slope >= layout.steep_min;
        let by_planes = layout.levels.is_empty() || slope < layout.shallow_max;
        if by_planes {
            let axis = cell.reached_from.map_or_else(|| touching_axis(cutter, index, cell, &mut scratch), |c| c.xy());
            let d = m.0 * axis.x + m.1 * axis.y;
            let i = layout.planes.partition_point(|&p| p < d);
            if i > 0 && i < layout.planes.len() {
                planes.insert(key(0.5 * (layout.planes[i - 1] + layout.planes[i])));
            } else if !layout.planes.is_empty() {
                // Beyond the first or last plane: a plane through the cell.
                planes.insert(key(d));
            }
        }
        if by_levels {
            let tip = cell.reached_from.map_or(cell.at.z - corner * (1.0 - cell.nz.abs().min(1.0)), |c| c.z);
            let j = layout.levels.partition_point(|&z| z > tip);
            if j > 0 && j < layout.levels.len() {
                levels.insert(key(0.5 * (layout.levels[j - 1] + layout.levels[j])));
            } else {
                // Above the top level or below the lowest: a level at the tip.
                levels.insert(key(tip));
            }
        }
    }
    #[allow(clippy::cast_precision_loss, reason = "keys of bounded offsets")]
    let value = |k: i64| k as f64 * SAME_OFFSET;
    Refinement { planes: planes.into_iter().map(value).collect(), levels: levels.into_iter().map(value).collect() }
}

/// The XY place of the axis of `cutter` touching the part at `cell` when the
/// simulation did not say where the cutter that reaches it stands
/// ([`OverCell::reached_from`]), by the cell's facet alone: the contact lies on the cutter's side towards the uphill direction `-n_h`, at
/// `R |n_h|` from the axis for a ball, `R - r + r |n_h|` for a bull-nose and
/// `R` for a flat end (`n` the part's unit normal under the cell). The cell
/// itself on a flat place or where no facet lies under it.
fn touching_axis(cutter: &Cutter, index: &MeshIndex, cell: &OverCell, scratch: &mut Vec<u32>) -> Point2 {
    let at = Point2::new(cell.at.x, cell.at.y);
    let Some(n) = normal_under(index, at, cell.at.z, scratch) else { return at };
    let horizontal = n.x.hypot(n.y);
    if horizontal <= 0.0 {
        return at;
    }
    let offset = match *cutter.shape() {
        CutterShape::Ball { radius } => radius * horizontal,
        CutterShape::Bull { radius, corner } => radius - corner + corner * horizontal,
        CutterShape::Flat { radius } => radius,
        CutterShape::Cone { .. } => 0.0,
    };
    at + scallop_geom::Vec2::new(n.x, n.y) * (offset / horizontal)
}

/// The unit upward normal of the facet under `at` whose height there is
/// nearest `z` (a cell's part point), `None` without one.
fn normal_under(index: &MeshIndex, at: Point2, z: f64, scratch: &mut Vec<u32>) -> Option<Vec3> {
    scratch.clear();
    index.collect_box(&Aabb2::around(at, 0.0), scratch);
    let mut best: Option<(f64, Vec3)> = None;
    for &slot in scratch.iter() {
        let c = index.corners(slot as usize);
        let n = *index.normal(slot as usize);
        if n.z == 0.0 || !in_triangle(&at, &c[0].xy(), &c[1].xy(), &c[2].xy()) {
            continue;
        }
        // The facet's plane through its first corner, at `at`.
        let height = c[0].z - (n.x * (at.x - c[0].x) + n.y * (at.y - c[0].y)) / n.z;
        if best.is_none_or(|(d, _)| (height - z).abs() < d) {
            best = Some(((height - z).abs(), if n.z < 0.0 { -n } else { n }));
        }
    }
    best.map(|(_, n)| n)
}

/// `a` with the planes and levels of `b` added.
pub(crate) fn merged(a: &Refinement, b: &Refinement) -> Refinement {
    let join = |x: &[f64], y: &[f64]| {
        let mut v: Vec<f64> = x.iter().chain(y).copied().collect();
        v.sort_by(f64::total_cmp);
        v.dedup_by(|p, q| (*p - *q).abs() <= SAME_OFFSET);
        v
    };
    Refinement { planes: join(&a.planes, &b.planes), levels: join(&a.levels, &b.levels) }
}

#[cfg(test)]
mod tests {
    use scallop_geom::Point3;

    use super::*;

    fn cell(x: f64, y: f64, z: f64, nz: f64) -> OverCell {
        OverCell { at: Point3::new(x, y, z), nz, thickness: 0.1, reached_from: None }
    }

    /// The plane `z = y tan(slope)` over `[-20, 20]^2`, rising towards +Y.
    fn ramp(slope: f64) -> MeshIndex {
        let p = |x: f64, y: f64| Point3::new(x, y, y * slope.tan());
        let (a, b, c, d) = (p(-20.0, -20.0), p(20.0, -20.0), p(20.0, 20.0), p(-20.0, 20.0));
        let (mesh, _) = scallop_mesh::TriMesh::from_soup(&[[a, b, c], [a, c, d]]).expect("two triangles");
        MeshIndex::build(&mesh)
    }

    #[test]
    fn a_cell_between_two_planes_gets_the_mid_plane_and_one_beyond_them_a_plane_through_it() {
        // Direction 0: planes along +X, offsets are y.
        let layout = Layout { planes: vec![0.0, 1.0, 3.0], ..Layout::default() };
        let cutter = Cutter::new(CutterShape::Ball { radius: 3.0 }, 20.0).expect("a ball");
        let r = refinement_for(
            &layout,
            &[cell(5.0, 2.5, 0.0, 1.0), cell(7.0, 2.9, 0.0, 1.0), cell(0.0, 4.0, 0.0, 1.0)],
            &cutter,
            &ramp(0.0),
        );
        assert_eq!(r.planes, vec![2.0, 4.0]);
        assert!(r.levels.is_empty());
    }

    #[test]
    fn a_steep_cell_gets_the_level_between_those_bracketing_its_tip() {
        let layout = Layout {
            planes: vec![0.0, 2.0],
            levels: vec![10.0, 8.0, 6.0],
            steep_min: 40_f64.to_radians(),
            shallow_max: 50_f64.to_radians(),
            ..Layout::default()
        };
        let cutter = Cutter::new(CutterShape::Ball { radius: 2.0 }, 20.0).expect("a ball");
        // A vertical wall point at z = 9: the ball's tip touching it is R = 2
        // below, at 7, between the levels 8 and 6.
        let r = refinement_for(&layout, &[cell(0.0, 1.0, 9.0, 0.0)], &cutter, &ramp(0.0));
        assert_eq!(r.levels, vec![7.0]);
        assert!(r.planes.is_empty(), "a vertical cell is not the planes'");
    }

    #[test]
    fn a_cell_on_a_slope_is_bracketed_by_the_planes_of_the_cutters_that_touch_it() {
        // Planes along +X every 0.5 mm on a 20-degree ramp rising towards +Y: a
        // cutter touches the ramp on its uphill side, so the passes that leave
        // a scallop at the cell have their axes below it (smaller y).
        let slope = 20_f64.to_radians();
        let layout = Layout { planes: (0..40).map(|i| -10.0 + 0.5 * f64::from(i)).collect(), ..Layout::default() };
        let index = ramp(slope);
        let cells = |y: f64| [cell(0.0, y, y * slope.tan(), slope.cos())];
        for (shape, offset) in [
            (CutterShape::Ball { radius: 3.0 }, 3.0 * slope.sin()),
            (CutterShape::Bull { radius: 3.0, corner: 1.0 }, 2.0 + slope.sin()),
        ] {
            let cutter = Cutter::new(shape, 20.0).expect("a cutter");
            for y in [0.1, 0.3, 0.45] {
                let r = refinement_for(&layout, &cells(y), &cutter, &index);
                let axis = y - offset;
                let mid = 0.5 * ((axis / 0.5).floor() + (axis / 0.5).ceil()) * 0.5;
                assert_eq!(r.planes.len(), 1, "{shape:?} at {y}");
                assert!((r.planes[0] - mid).abs() < 1e-5, "{shape:?} at {y}: {:?}, axis {axis}", r.planes);
            }
        }
    }

    /// A groove along X: a 43-degree flank rising towards -Y, a 70-degree
    /// wall towards +Y, flat beyond.
    fn groove() -> (scallop_mesh::TriMesh, f64, f64) {
        let (a, b) = (43_f64.to_radians().tan(), 70_f64.to_radians().tan());
        let depth = 5.0;
        let (ya, yb) = (-depth / a, depth / b);
        let p = |x: f64, y: f64| Point3::new(x, y, if y < 0.0 { -a * y } else { b * y }.min(depth));
        let ys = [-9.0, ya, 0.0, yb, 5.0];
        let mut soup = Vec::new();
        for w in ys.windows(2) {
            let (q0, q1, q2, q3) = (p(-6.0, w[0]), p(6.0, w[0]), p(6.0, w[1]), p(-6.0, w[1]));
            soup.push([q0, q1, q2]);
            soup.push([q0, q2, q3]);
        }
        (scallop_mesh::TriMesh::from_soup(&soup).expect("a groove").0, a, b)
    }

    /// Where a cell of the machined surface lies on a facet that other faces
    /// keep the cutter off (a hollow narrower than the cutter: here the foot
    /// of a 43-degree flank in a groove whose far wall holds a bull-nose R3
    /// r1 up), the cutter that reaches it stands where it touches both faces,
    /// not where it would rest on the flank alone (`R - r + r sin s` downhill
    /// of the cell, inside the wall). The planes around that cutter are the
    /// ones that leave the cell's scallop (mount_rush, docs/validation.md,
    /// "mount_rush with the bull-nose"): the cell is bracketed by them.
    #[test]
    fn a_cell_the_cutter_reaches_wedged_in_a_hollow_is_bracketed_around_the_wedged_cutter() {
        let (mesh, ta, tb) = groove();
        let index = MeshIndex::build(&mesh);
        let (radius, corner) = (3.0, 1.0);
        let cutter = Cutter::new(CutterShape::Bull { radius, corner }, 20.0).expect("a bull-nose");
        // The axis touching both faces with the two corner arcs (a section across the groove).
        let (ca, cb) = (43_f64.to_radians().cos(), 70_f64.to_radians().cos());
        let flat = radius - corner;
        let wedged = (flat * (ta - tb) + corner / ca - corner / cb) / (ta + tb);
        // Passes along X: every 0.1 mm up the flank from 0.2 mm off the wedged
        // axis, every 0.05 mm up the wall from 0.03 mm off it.
        let mut planes: Vec<f64> = (2..80).map(|k| wedged - 0.1 * f64::from(k)).collect();
        planes.extend((0..40).map(|k| wedged + 0.03 + 0.05 * f64::from(k)));
        planes.sort_by(f64::total_cmp);
        let mut path = scallop_toolpath::Toolpath::new(1000.0);
        for &y in &planes {
            for k in 0..=150 {
                let x = -7.5 + 0.1 * f64::from(k);
                let cl = scallop_cutter::drop_cutter(&cutter, &index, Point2::new(x, y), -10.0);
                if k == 0 {
                    let above = Point3::new(cl.tip.x, cl.tip.y, 10.0);
                    path.push(scallop_toolpath::Move::new(scallop_toolpath::MoveKind::Rapid, above));
                    path.push(scallop_toolpath::Move::new(scallop_toolpath::MoveKind::Plunge, cl.tip));
                } else {
                    path.push(scallop_toolpath::Move::new(scallop_toolpath::MoveKind::Feed, cl.tip));
                }
            }
            path.push(scallop_toolpath::Move::new(scallop_toolpath::MoveKind::Retract, Point3::new(7.5, y, 10.0)));
        }
        let stock = scallop_geom::Aabb3 { min: Point3::new(-9.0, -12.0, -1.0), max: Point3::new(9.0, 8.0, 5.0 + 1e-3) };
        let options =
            scallop_sim::VerifyOptions { gouge_tolerance: 0.01, scallop_margin: radius, ..Default::default() };
        let sim = scallop_sim::simulate(stock, 0.1, &cutter, &path, &index, &options).expect("simulated");
        let field = scallop_sim::PartField::new(&sim.zmap, &index);
        let limit = 0.01 + sim.zmap.resolution_bound(cutter.shape());
        let split = scallop_sim::split_rest(&sim.zmap, &field, &index, &cutter, &options, limit);
        // The cells on the flank within a cutter's reach of the groove's foot.
        let flank: Vec<OverCell> =
            split.machined_over.iter().filter(|c| (c.nz - ca).abs() < 1e-6 && c.at.y > -6.0).copied().collect();
        let layout = Layout { planes: planes.clone(), ..Layout::default() };
        let r = refinement_for(&layout, &flank, &cutter, &index);
        assert!(!flank.is_empty(), "the program leaves the flank's foot over the limit");
        // The mid-plane of the pair around the wedged axis, and no other.
        assert_eq!(r.planes.len(), 1, "{:?}", r.planes);
        assert!((r.planes[0] - (wedged - 0.085)).abs() < 1e-5, "{:?}, wedged axis {wedged}", r.planes);
    }

    #[test]
    fn merging_keeps_each_offset_once_in_order() {
        let a = Refinement { planes: vec![2.0, 1.0], levels: vec![] };
        let b = Refinement { planes: vec![1.0, 3.0], levels: vec![5.0] };
        let m = merged(&a, &b);
        assert_eq!(m.planes, vec![1.0, 2.0, 3.0]);
        assert_eq!(m.levels, vec![5.0]);
    }
}
