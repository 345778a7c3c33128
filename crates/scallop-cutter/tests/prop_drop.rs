#![allow(
    clippy::float_cmp,
    reason = "exact equalities (bit-identical heights, floor values) are the property under test"
)]
//! Property tests of the drop-cutter: no gouge, touches, index = brute force,
//! translation invariance, monotone under adding triangles, and analytic cases.

use proptest::prelude::*;
use scallop_cutter::{
    BoxDrop, ClPoint, Contact, Cutter, CutterShape, drop_cutter, drop_cutter_brute_force, drop_grid, drop_patch,
    drop_path, drop_triangle,
};
use scallop_geom::{Point2, Point3, Vec3, assert_near};
use scallop_mesh::{MeshIndex, TriMesh};

const FLOOR: f64 = -100.0;
/// Measurement tolerance of these tests (mm): models are ~10 mm, rounding ~1e-14.
const EPS: f64 = 1e-9;

fn shape_strategy() -> impl Strategy<Value = CutterShape> {
    (0usize..4, 0.3f64..3.0, 0.05f64..1.0, 0.15f64..1.45).prop_map(|(kind, radius, frac, angle)| match kind {
        0 => CutterShape::Flat { radius },
        1 => CutterShape::Ball { radius },
        2 => CutterShape::Bull { radius, corner: radius * frac },
        _ => CutterShape::Cone { radius, half_angle: angle },
    })
}

fn cutter(shape: CutterShape) -> Cutter {
    Cutter::new(shape, 100.0).expect("valid cutter")
}

fn triangle_strategy() -> impl Strategy<Value = [Point3; 3]> {
    prop::array::uniform3((0.0f64..10.0, 0.0f64..10.0, 0.0f64..3.0))
        .prop_map(|v| v.map(|(x, y, z)| Point3::new(x, y, z)))
}

fn soup_strategy(max: usize) -> impl Strategy<Value = Vec<[Point3; 3]>> {
    prop::collection::vec(triangle_strategy(), 1..max)
}

fn build(soup: &[[Point3; 3]]) -> Option<(TriMesh, MeshIndex)> {
    let (mesh, _) = TriMesh::from_soup(soup).ok()?;
    let index = MeshIndex::build(&mesh);
    Some((mesh, index))
}

/// Lowest clearance between the cutter at `cl` and triangle `t`, by dense
/// barycentric sampling (independent of the contact solvers): the surface z
/// minus the cutter's lower surface z, over samples within the disk.
fn min_clearance(shape: &CutterShape, cl: &ClPoint, t: &[Point3; 3]) -> f64 {
    let n = 40;
    let r = shape.radius();
    let mut worst = f64::INFINITY;
    for i in 0..=n {
        for j in 0..=(n - i) {
            let (u, v) = (f64::from(i) / f64::from(n), f64::from(j) / f64::from(n));
            let p = t[0] + (t[1] - t[0]) * u + (t[2] - t[0]) * v;
            let rho = (p.x - cl.tip.x).hypot(p.y - cl.tip.y);
            if rho <= r {
                worst = worst.min(cl.tip.z + shape.height_at(rho) - p.z);
            }
        }
    }
    worst
}

/// The XY distance from `p` to the triangle `t` (0 inside), for the tests.
fn xy_distance(t: &[Point3; 3], p: Point2) -> f64 {
    let cross = |a: &Point3, b: &Point3| (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
    let s = [cross(&t[0], &t[1]), cross(&t[1], &t[2]), cross(&t[2], &t[0])];
    if s.iter().all(|&v| v >= 0.0) || s.iter().all(|&v| v <= 0.0) {
        return 0.0;
    }
    (0..3)
        .map(|k| {
            let (a, b) = (&t[k], &t[(k + 1) % 3]);
            let (ex, ey, wx, wy) = (b.x - a.x, b.y - a.y, p.x - a.x, p.y - a.y);
            let len2 = ex * ex + ey * ey;
            let u = if len2 > 0.0 { ((wx * ex + wy * ey) / len2).clamp(0.0, 1.0) } else { 0.0 };
            (wx - u * ex).hypot(wy - u * ey)
        })
        .fold(f64::INFINITY, f64::min)
}

fn contact_point(c: &Contact) -> Option<(usize, Point3)> {
    match *c {
        Contact::Floor => None,
        Contact::Vertex { triangle, point }
        | Contact::Edge { triangle, point }
        | Contact::Facet { triangle, point } => Some((triangle, point)),
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    #[test]
    fn index_equals_brute_force(soup in soup_strategy(60), shape in shape_strategy(),
                                pts in prop::collection::vec((-2.0f64..12.0, -2.0f64..12.0), 1..20)) {
        let Some((_, index)) = build(&soup) else { return Ok(()) };
        let c = cutter(shape);
        for (x, y) in pts {
            let xy = Point2::new(x, y);
            let fast = drop_cutter(&c, &index, xy, FLOOR);
            let slow = drop_cutter_brute_force(&c, &index, xy, FLOOR);
            prop_assert_eq!(fast.tip.z.to_bits(), slow.tip.z.to_bits(), "at {:?}: {:?} vs {:?}", xy, fast, slow);
            prop_assert_eq!(matches!(fast.contact, Contact::Floor), matches!(slow.contact, Contact::Floor));
        }
    }

    #[test]
    fn grid_equals_brute_force(soup in soup_strategy(80), shape in shape_strategy(),
                               x0 in -3.0f64..3.0, step in 0.05f64..1.5, y0 in -3.0f64..3.0) {
        let Some((_, index)) = build(&soup) else { return Ok(()) };
        let c = cutter(shape);
        let xs: Vec<f64> = (0..40).map(|i| x0 + step * f64::from(i)).collect();
        let ys: Vec<f64> = (0..8).map(|j| y0 + 1.7 * f64::from(j)).collect();
        let grid = drop_grid(&c, &index, &xs, &ys, FLOOR, &|_| {});
        for (k, cl) in grid.iter().enumerate() {
            let xy = Point2::new(xs[k % xs.len()], ys[k / xs.len()]);
            let slow = drop_cutter_brute_force(&c, &index, xy, FLOOR);
            prop_assert_eq!(cl.tip.z.to_bits(), slow.tip.z.to_bits(), "at {:?}: {:?} vs {:?}", xy, cl, slow);
        }
    }

    /// A patch (one candidate list for all its rows, walked back and forth)
    /// gives the brute-force heights bit for bit.
    #[test]
    fn patch_equals_brute_force(soup in soup_strategy(80), shape in shape_strategy(),
                                x0 in -3.0f64..10.0, step in 0.02f64..0.8, y0 in -3.0f64..10.0,
                                n in (1usize..10, 1usize..10)) {
        let Some((_, index)) = build(&soup) else { return Ok(()) };
        let c = cutter(shape);
        let xs: Vec<f64> = (0..n.0).map(|i| x0 + step * i as f64).collect();
        let ys: Vec<f64> = (0..n.1).map(|j| y0 + step * j as f64).collect();
        let patch = drop_patch(&c, &index, &xs, &ys, FLOOR);
        prop_assert_eq!(patch.len(), xs.len() * ys.len());
        for (k, cl) in patch.iter().enumerate() {
            let xy = Point2::new(xs[k % xs.len()], ys[k / xs.len()]);
            let slow = drop_cutter_brute_force(&c, &index, xy, FLOOR);
            prop_assert_eq!((cl.tip.x, cl.tip.y), (xy.x, xy.y));
            prop_assert_eq!(cl.tip.z.to_bits(), slow.tip.z.to_bits(), "at {:?}: {:?} vs {:?}", xy, cl, slow);
        }
    }

    /// Long thin triangles (a fan of slivers, as the flat faces of CAD meshes
    /// and a cone's side, down to nearly vertical walls), whose XY boxes reach
    /// far past them: the search
    /// through the index, a patch and a box's candidate list (which skip a
    /// triangle by its distance to its edge lines, `MeshIndex::edge_distance`)
    /// give the brute-force heights bit for bit, and that distance is never
    /// above the XY distance to the triangle.
    #[test]
    fn slivers_give_the_brute_force_heights(shape in shape_strategy(),
                                            fan in prop::collection::vec((0.0f64..6.3, 0.7f64..9.0, 4.0f64..12.0,
                                                                          0.0f64..3.0, 0.0f64..3.0), 1..40),
                                            pts in prop::collection::vec((-4.0f64..14.0, -4.0f64..14.0), 1..30)) {
        let apex = Point3::new(5.0, 5.0, 1.5);
        let soup: Vec<[Point3; 3]> = fan
            .iter()
            .map(|&(angle, thin, length, z1, z2)| {
                // Down to walls of 1e-9 mm, whose XY area is at its rounding.
                let width = 10f64.powf(-thin);
                let at = |a: f64| Point3::new(5.0 + length * a.cos(), 5.0 + length * a.sin(), 0.0);
                let (mut b, mut c) = (at(angle), at(angle + width / length));
                (b.z, c.z) = (z1, z2);
                [apex, b, c]
            })
            .collect();
        let Some((_, index)) = build(&soup) else { return Ok(()) };
        let c = cutter(shape);
        let local = BoxDrop::new(&c, &index, Point2::new(-4.0, -4.0), Point2::new(14.0, 14.0));
        // A patch is a grid: its xs in order.
        let mut xs: Vec<f64> = pts.iter().map(|p| p.0).collect();
        xs.sort_by(f64::total_cmp);
        let patch = drop_patch(&c, &index, &xs, &[pts[0].1], FLOOR);
        for (k, &(x, y)) in pts.iter().enumerate() {
            let xy = Point2::new(x, y);
            let slow = drop_cutter_brute_force(&c, &index, xy, FLOOR);
            let fast = drop_cutter(&c, &index, xy, FLOOR);
            prop_assert_eq!(fast.tip.z.to_bits(), slow.tip.z.to_bits(), "index at {:?}: {:?} vs {:?}", xy, fast, slow);
            let (cl, _) = local.drop(xy, FLOOR, None);
            prop_assert_eq!(cl.tip.z.to_bits(), slow.tip.z.to_bits(), "box at {:?}: {:?} vs {:?}", xy, cl, slow);
            let row = Point2::new(xs[k], pts[0].1);
            let slow_row = drop_cutter_brute_force(&c, &index, row, FLOOR);
            prop_assert_eq!(patch[k].tip.z.to_bits(), slow_row.tip.z.to_bits(), "patch at {:?}", row);
            for slot in 0..index.len() {
                let t = index.corners(slot);
                let d = xy_distance(t, xy);
                prop_assert!(index.edge_distance(slot, xy) <= d + 1e-12, "slot {} at {:?}: {} > {}",
                             slot, xy, index.edge_distance(slot, xy), d);
            }
        }
    }

    /// The candidate list of a box gives the brute-force heights bit for bit,
    /// at points inside the box (any seed) and outside it (the index), and its
    /// one-triangle drop equals `drop_triangle`.
    #[test]
    fn box_drop_equals_brute_force(soup in soup_strategy(80), shape in shape_strategy(),
                                   lo in (-3.0f64..10.0, -3.0f64..10.0), size in (0.0f64..3.0, 0.0f64..3.0),
                                   pts in prop::collection::vec((-0.5f64..1.5, -0.5f64..1.5, 0usize..200), 1..40)) {
        let Some((_, index)) = build(&soup) else { return Ok(()) };
        let c = cutter(shape);
        let (lo, hi) = (Point2::new(lo.0, lo.1), Point2::new(lo.0 + size.0, lo.1 + size.1));
        let local = BoxDrop::new(&c, &index, lo, hi);
        for (u, v, seed) in pts {
            let xy = Point2::new(lo.x + u * size.0, lo.y + v * size.1);
            let seed = (seed < index.len()).then_some(seed);
            let (cl, slot) = local.drop(xy, FLOOR, seed);
            let slow = drop_cutter_brute_force(&c, &index, xy, FLOOR);
            prop_assert_eq!(cl.tip.z.to_bits(), slow.tip.z.to_bits(), "at {:?}: {:?} vs {:?}", xy, cl, slow);
            if let Some(slot) = slot {
                let one = local.drop_one(slot, xy, FLOOR);
                let mut best = ClPoint::floor(xy, FLOOR);
                drop_triangle(&c, index.corners(slot), index.normal(slot), index.original_index(slot), &mut best);
                prop_assert_eq!(one.tip.z.to_bits(), best.tip.z.to_bits());
                prop_assert_eq!(one.tip.z.to_bits(), cl.tip.z.to_bits(), "the slot gives the height");
            }
        }
    }

    /// `BoxDrop::drop_one_features` never exceeds the whole triangle's height
    /// (`drop_one`) whatever the features kept, and equals it, bit for bit,
    /// on the features of `contact_features` of `drop_one`'s contact (the
    /// contact's corner, or its edge and that edge's corners: those of both
    /// edges where the contact is a corner reached from an edge).
    /// On a connected mesh (edges shared, each tested by the triangle that
    /// owns it), a box's candidate list gives the same height, bit for bit,
    /// whatever triangle seeds the search: the seed is tested on its own
    /// corners and edges, as the scan tests it (an edge tested from the other
    /// triangle, in the opposite direction, can differ in the last bit).
    #[test]
    fn any_seed_gives_the_unseeded_height(shape in shape_strategy(),
                                          h in prop::collection::vec(0.0f64..3.0, 49),
                                          flips in prop::collection::vec(any::<bool>(), 36),
                                          pts in prop::collection::vec((0.5f64..9.5, 0.5f64..9.5), 8)) {
        let at = |i: usize, j: usize| Point3::new(i as f64 * 1.7, j as f64 * 1.7, h[j * 7 + i]);
        let mut soup = Vec::new();
        for j in 0..6 {
            for i in 0..6 {
                let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                if flips[j * 6 + i] {
                    soup.extend([[a, b, c], [a, c, d]]);
                } else {
                    soup.extend([[a, b, d], [b, c, d]]);
                }
            }
        }
        let Some((_, index)) = build(&soup) else { return Ok(()) };
        let c = cutter(shape);
        let local = BoxDrop::new(&c, &index, Point2::new(0.0, 0.0), Point2::new(10.2, 10.2));
        for (x, y) in pts {
            let xy = Point2::new(x, y);
            for floor in [FLOOR, 1.5] {
                let (plain, _) = local.drop(xy, floor, None);
                for seed in 0..index.len() {
                    let (seeded, _) = local.drop(xy, floor, Some(seed));
                    prop_assert_eq!(seeded.tip.z.to_bits(), plain.tip.z.to_bits(),
                                    "{:?} at {:?}, floor {}, seed {}: {:?} vs {:?}", shape, xy, floor, seed, seeded, plain);
                }
            }
        }
    }

    #[test]
    fn features_of_the_contact_give_the_triangles_height(soup in soup_strategy(30), shape in shape_strategy(),
                                                         pts in prop::collection::vec((-2.0f64..12.0, -2.0f64..12.0,
                                                                                       0usize..30, 0u8..64), 1..40)) {
        let Some((_, index)) = build(&soup) else { return Ok(()) };
        let c = cutter(shape);
        let local = BoxDrop::new(&c, &index, Point2::new(0.0, 0.0), Point2::new(10.0, 10.0));
        for (x, y, slot, mask) in pts {
            let (xy, slot) = (Point2::new(x, y), slot % index.len());
            let whole = local.drop_one(slot, xy, FLOOR);
            let some = local.drop_one_features(slot, mask, xy, FLOOR);
            prop_assert!(some.tip.z <= whole.tip.z, "slot {} at {:?}, mask {:b}: {:?} above {:?}", slot, xy, mask, some, whole);
            let held = local.contact_features(slot, &whole.contact);
            let kept = local.drop_one_features(slot, held, xy, FLOOR);
            prop_assert_eq!(kept.tip.z.to_bits(), whole.tip.z.to_bits(), "slot {} at {:?}, {:?}, features {:b}",
                            slot, xy, whole.contact, held);
            if let Contact::Vertex { .. } = whole.contact {
                prop_assert_eq!((held & 0b11_1111).count_ones(), 1, "a corner: {:b}", held);
            }
        }
    }

    /// `BoxDrop::contact_gradient` is the slope of the triangle's height:
    /// central differences of `drop_one` along x and y, where the contact
    /// keeps its kind on both sides and stays off the rim (where the height
    /// jumps or turns steep), agree with it.
    #[test]
    fn contact_gradient_is_the_slope_of_the_triangles_height(soup in soup_strategy(20), shape in shape_strategy(),
                                                              pts in prop::collection::vec((-2.0f64..12.0,
                                                                                            -2.0f64..12.0,
                                                                                            0usize..20), 1..40)) {
        let Some((_, index)) = build(&soup) else { return Ok(()) };
        let c = cutter(shape);
        let local = BoxDrop::new(&c, &index, Point2::new(0.0, 0.0), Point2::new(10.0, 10.0));
        let kind = |c: &Contact| std::mem::discriminant(c);
        for (x, y, slot) in pts {
            let (xy, slot) = (Point2::new(x, y), slot % index.len());
            let at = local.drop_one(slot, xy, FLOOR);
            let Some(g) = local.contact_gradient(&at.contact, xy) else { continue };
            let Some((_, q)) = contact_point(&at.contact) else { continue };
            if (q.x - x).hypot(q.y - y) > 0.99 * shape.radius() {
                continue; // steep near a ball's rim: differences are poor there
            }
            let step = 1e-6;
            for (k, e) in [(0, Point2::new(step, 0.0)), (1, Point2::new(0.0, step))] {
                let (hi, lo) = (local.drop_one(slot, xy + e.coords, FLOOR), local.drop_one(slot, xy - e.coords, FLOOR));
                if kind(&hi.contact) != kind(&at.contact) || kind(&lo.contact) != kind(&at.contact) {
                    continue;
                }
                let diff = (hi.tip.z - lo.tip.z) / (2.0 * step);
                prop_assert!((diff - g[k]).abs() <= 1e-3 * (1.0 + g[k].abs()),
                             "{:?} slot {} at {:?}, {:?}: gradient {:?}, difference {} along {}",
                             shape, slot, xy, at.contact, g, diff, k);
            }
        }
    }

    /// `BoxDrop::lifts` (the search pruned at z) answers as one triangle's
    /// height does (`drop_one` from a floor below z), also at z equal to that
    /// height and one rounding unit either side of it.
    #[test]
    fn lifts_answers_as_the_triangles_height(soup in soup_strategy(30), shape in shape_strategy(),
                                             pts in prop::collection::vec((-2.0f64..12.0, -2.0f64..12.0, 0usize..30,
                                                                           -1.0f64..4.0), 1..40)) {
        let Some((_, index)) = build(&soup) else { return Ok(()) };
        let c = cutter(shape);
        let local = BoxDrop::new(&c, &index, Point2::new(0.0, 0.0), Point2::new(10.0, 10.0));
        for (x, y, slot, z) in pts {
            let (xy, slot) = (Point2::new(x, y), slot % index.len());
            let h = local.drop_one(slot, xy, FLOOR).tip.z;
            for z in [z, h, h.next_down(), h.next_up(), h - 1e-9, h + 1e-9] {
                let lifted = local.drop_one(slot, xy, FLOOR.min(z - 1.0)).tip.z > z;
                prop_assert_eq!(local.lifts(slot, xy, z), lifted, "slot {} at {:?}, z {} (height {})", slot, xy, z, h);
            }
        }
    }

    /// A wandering path (small steps with occasional jumps, so blocks of many
    /// points and blocks of one) gives the brute-force heights bit for bit.
    #[test]
    fn path_equals_brute_force(soup in soup_strategy(80), shape in shape_strategy(),
                               x0 in -3.0f64..12.0, y0 in -3.0f64..12.0,
                               steps in prop::collection::vec((-0.6f64..0.6, -0.6f64..0.6, 0u8..20), 1..150)) {
        let Some((_, index)) = build(&soup) else { return Ok(()) };
        let c = cutter(shape);
        let mut p = Point2::new(x0, y0);
        let mut path = Vec::new();
        for (dx, dy, jump) in steps {
            let k = if jump == 0 { 12.0 } else { 1.0 };
            p = Point2::new((p.x + k * dx).clamp(-3.0, 13.0), (p.y + k * dy).clamp(-3.0, 13.0));
            path.push(p);
        }
        let fast = drop_path(&c, &index, &path, FLOOR);
        prop_assert_eq!(fast.len(), path.len());
        for (cl, xy) in fast.iter().zip(&path) {
            let slow = drop_cutter_brute_force(&c, &index, *xy, FLOOR);
            prop_assert_eq!(cl.tip.z.to_bits(), slow.tip.z.to_bits(), "at {:?}: {:?} vs {:?}", xy, cl, slow);
            prop_assert_eq!((cl.tip.x, cl.tip.y), (xy.x, xy.y));
        }
    }

    #[test]
    fn no_gouge_and_touches(soup in soup_strategy(12), shape in shape_strategy(),
                            pts in prop::collection::vec((-1.0f64..11.0, -1.0f64..11.0), 1..6)) {
        let Some((mesh, index)) = build(&soup) else { return Ok(()) };
        let c = cutter(shape);
        for (x, y) in pts {
            let cl = drop_cutter(&c, &index, Point2::new(x, y), FLOOR);
            for t in mesh.soup() {
                let clearance = min_clearance(&shape, &cl, &t);
                prop_assert!(clearance >= -EPS, "gouge {clearance} at {cl:?}");
            }
            if let Some((tri, p)) = contact_point(&cl.contact) {
                let rho = (p.x - cl.tip.x).hypot(p.y - cl.tip.y);
                prop_assert!(rho <= shape.radius() + EPS);
                prop_assert!((cl.tip.z + shape.height_at(rho.min(shape.radius())) - p.z).abs() <= 1e-7,
                    "contact point not on the cutter: {cl:?}");
                // the contact point lies on the named triangle (distance to its plane)
                let t = mesh.triangle(tri);
                let n = (t[1] - t[0]).cross(&(t[2] - t[0])).normalize();
                prop_assert!(n.dot(&(p - t[0])).abs() <= 1e-7, "contact off triangle {tri}: {cl:?}");
            } else {
                prop_assert_eq!(cl.tip.z, FLOOR);
            }
        }
    }

    /// A wall whose vertical edge leans by a rounding-level offset (its ends
    /// 1e-18 to 1e-14 mm apart in XY, as a CAD export writes -0.0 as -1e-17)
    /// gives the heights of the same wall exactly vertical, up to rounding:
    /// the edge's parameter there is all rounding, and its slope must not carry
    /// it past the wall's top (on `idler_riser.STL`, docs/validation.md, the
    /// bull-nose was lifted 6.6 mm above the part, in spikes that split the
    /// waterline passes).
    #[test]
    fn a_wall_leaning_by_rounding_gives_the_vertical_walls_heights(
        shape in shape_strategy(), base in (0.0f64..10.0, 0.0f64..10.0), lean in (-18.0f64..-14.0, 0.0f64..6.3),
        heights in (0.0f64..3.0, 3.0f64..6.0, 0.0f64..6.0), side in (1.0f64..8.0, 0.0f64..6.3),
        pts in prop::collection::vec((0.0f64..1.2, 0.0f64..6.3), 1..20)) {
        let (x0, y0) = base;
        let e = 10f64.powf(lean.0);
        let (lo, hi, zc) = heights;
        let far = Point3::new(x0 + side.0 * side.1.cos(), y0 + side.0 * side.1.sin(), zc);
        let top = Point3::new(x0, y0, hi);
        let leaning = Point3::new(x0 + e * lean.1.cos(), y0 + e * lean.1.sin(), lo);
        let upright = Point3::new(x0, y0, lo);
        let Some((_, bent)) = build(&[[leaning, top, far]]) else { return Ok(()) };
        let Some((_, straight)) = build(&[[upright, top, far]]) else { return Ok(()) };
        let c = cutter(shape);
        for (rho, angle) in pts {
            let r = rho * shape.radius();
            let xy = Point2::new(x0 + r * angle.cos(), y0 + r * angle.sin());
            let a = drop_cutter(&c, &bent, xy, FLOOR);
            let b = drop_cutter(&c, &straight, xy, FLOOR);
            prop_assert!(a.tip.z <= hi.max(zc) + EPS, "above the wall at {:?}: {:?}", xy, a);
            prop_assert!((a.tip.z - b.tip.z).abs() <= EPS, "at {:?}: {:?} vs {:?}", xy, a, b);
        }
    }

    #[test]
    fn translation_moves_the_result(soup in soup_strategy(30), shape in shape_strategy(),
                                    t in (-50.0f64..50.0, -50.0f64..50.0, -50.0f64..50.0),
                                    pts in prop::collection::vec((-1.0f64..11.0, -1.0f64..11.0), 1..10)) {
        let Some((mesh, index)) = build(&soup) else { return Ok(()) };
        let offset = Vec3::new(t.0, t.1, t.2);
        let moved = MeshIndex::build(&mesh.translated(&offset));
        let c = cutter(shape);
        for (x, y) in pts {
            let a = drop_cutter(&c, &index, Point2::new(x, y), FLOOR);
            let b = drop_cutter(&c, &moved, Point2::new(x + t.0, y + t.1), FLOOR + t.2);
            prop_assert!((b.tip.z - (a.tip.z + t.2)).abs() <= 1e-8, "{a:?} vs {b:?}");
        }
    }

    #[test]
    fn adding_triangles_never_lowers(soup in soup_strategy(30), extra in soup_strategy(10), shape in shape_strategy(),
                                     pts in prop::collection::vec((-1.0f64..11.0, -1.0f64..11.0), 1..10)) {
        let Some((_, index)) = build(&soup) else { return Ok(()) };
        let mut all = soup.clone();
        all.extend(extra);
        let Some((_, bigger)) = build(&all) else { return Ok(()) };
        let c = cutter(shape);
        for (x, y) in pts {
            let a = drop_cutter(&c, &index, Point2::new(x, y), FLOOR);
            let b = drop_cutter(&c, &bigger, Point2::new(x, y), FLOOR);
            prop_assert!(b.tip.z >= a.tip.z, "{a:?} vs {b:?}");
        }
    }
}

/// A big triangle through the origin, tilted by `theta` about the y axis.
fn inclined_plane(theta: f64) -> MeshIndex {
    let z = |x: f64| x * theta.tan();
    let p = |x: f64, y: f64| Point3::new(x, y, z(x));
    let (m, _) = TriMesh::from_soup(&[[p(-50.0, -50.0), p(50.0, -50.0), p(0.0, 80.0)]]).expect("mesh");
    MeshIndex::build(&m)
}

#[test]
fn analytic_inclined_plane_every_shape() {
    let (big_r, small_r, alpha) = (3.0, 1.0, 0.5f64);
    for &theta in &[0.0, 0.2, 0.7, 1.2] {
        let index = inclined_plane(theta);
        let (s, c) = (theta.sin(), theta.cos());
        let cases = [
            (CutterShape::Flat { radius: big_r }, big_r * s / c),
            (CutterShape::Ball { radius: big_r }, big_r * (1.0 / c - 1.0)),
            (
                CutterShape::Bull { radius: big_r, corner: small_r },
                (big_r - small_r) * s / c + small_r * (1.0 / c - 1.0),
            ),
            (
                CutterShape::Cone { radius: big_r, half_angle: alpha },
                if theta < std::f64::consts::FRAC_PI_2 - alpha { 0.0 } else { big_r * s / c - big_r / alpha.tan() },
            ),
        ];
        for (shape, lift) in cases {
            let cl = drop_cutter(&cutter(shape), &index, Point2::new(1.5, 0.5), FLOOR);
            assert_near!(cl.tip.z, 1.5 * theta.tan() + lift, 1e-12);
        }
    }
}

#[test]
fn analytic_ridge_edge_every_shape() {
    // A vertical wall in the plane y = 0 whose top edge is at z = 0: vertical facets
    // never hold a contact, so only the top edge touches.
    let p = |x: f64, y: f64, z: f64| Point3::new(x, y, z);
    let (m, _) = TriMesh::from_soup(&[
        [p(-30., 0., 0.), p(30., 0., 0.), p(-30., 0., -50.)],
        [p(30., 0., 0.), p(30., 0., -50.), p(-30., 0., -50.)],
    ])
    .expect("mesh");
    let index = MeshIndex::build(&m);
    let (big_r, small_r, alpha) = (2.0, 0.5, 0.6f64);
    for &d in &[0.0, 0.4, 1.0, 1.7, 1.99] {
        let shapes = [
            CutterShape::Flat { radius: big_r },
            CutterShape::Ball { radius: big_r },
            CutterShape::Bull { radius: big_r, corner: small_r },
            CutterShape::Cone { radius: big_r, half_angle: alpha },
        ];
        for shape in shapes {
            let cl = drop_cutter(&cutter(shape), &index, Point2::new(3.0, d), FLOOR);
            assert_near!(cl.tip.z, -shape.height_at(d), 1e-12);
        }
    }
}

#[test]
fn grid_is_row_major_and_thread_independent() {
    let p = |x: f64, y: f64, z: f64| Point3::new(x, y, z);
    let mut soup = Vec::new();
    for i in 0..20 {
        for j in 0..20 {
            let (x, y) = (f64::from(i), f64::from(j));
            let h = |x: f64, y: f64| (x * 0.7).sin() + (y * 0.4).cos();
            soup.push([p(x, y, h(x, y)), p(x + 1., y, h(x + 1., y)), p(x, y + 1., h(x, y + 1.))]);
            soup.push([p(x + 1., y, h(x + 1., y)), p(x + 1., y + 1., h(x + 1., y + 1.)), p(x, y + 1., h(x, y + 1.))]);
        }
    }
    let (mesh, _) = TriMesh::from_soup(&soup).expect("mesh");
    let index = MeshIndex::build(&mesh);
    let c = cutter(CutterShape::Bull { radius: 1.5, corner: 0.4 });
    let xs: Vec<f64> = (0..50).map(|i| f64::from(i) * 0.4).collect();
    let ys: Vec<f64> = (0..40).map(|i| f64::from(i) * 0.5).collect();
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("pool");
    let two = rayon::ThreadPoolBuilder::new().num_threads(2).build().expect("pool");
    let a = one.install(|| drop_grid(&c, &index, &xs, &ys, FLOOR, &|_| {}));
    let b = two.install(|| drop_grid(&c, &index, &xs, &ys, FLOOR, &|_| {}));
    assert_eq!(a.len(), xs.len() * ys.len());
    for (k, (pa, pb)) in a.iter().zip(&b).enumerate() {
        assert_eq!(pa.tip.z.to_bits(), pb.tip.z.to_bits());
        assert_eq!(pa.tip.x, xs[k % xs.len()]);
        assert_eq!(pa.tip.y, ys[k / xs.len()]);
    }
}

/// The wall of `idler_riser.STL` (inches, scaled to mm) whose vertical edge
/// from (0, 0, 0.79375) to (0, 0, 12.7) leans 3.6e-17 mm in x: the bull-nose
/// R5 r2 at (-0.4, -4.5) rests on the edge's top corner, at distance 4.518,
/// not 6.6 mm higher on the edge produced past its top (the bug this pins).
#[test]
fn the_idler_risers_leaning_edge_holds_the_bull_nose_at_its_top_corner() {
    let p = |x: f64, y: f64, z: f64| Point3::new(x, y, z);
    let wall = [
        p(-6.938_893_956_846_787_6e-15, 5.080_000_075_697_899, 11.906_250_756_978_988),
        p(3.577_140_604_771_371e-17, 0.0, 0.79375),
        p(0.0, 0.0, 12.7),
    ];
    let (_, index) = build(&[wall]).expect("mesh");
    let c = cutter(CutterShape::Bull { radius: 5.0, corner: 2.0 });
    let xy = Point2::new(-0.4, -4.5);
    let cl = drop_cutter(&c, &index, xy, FLOOR);
    // The corner contact: the torus at horizontal distance 4.518 from the axis.
    let rho = xy.coords.norm();
    let corner = 12.7 - (2.0 - (4.0 - (rho - 3.0) * (rho - 3.0)).sqrt());
    assert_near!(cl.tip.z, corner, EPS);
}
