//! Contour features narrower than the grid step: a slot barely wider than the
//! cutter (a thin gap of outside between two inside regions) and a bump that
//! only just reaches above z (a small island of inside). Every mesh is
//! generated here; the oracle is the brute-force drop-cutter.

use proptest::prelude::*;
use scallop_cutter::{Cutter, drop_cutter_brute_force};
use scallop_geom::{Point2, Point3};
use scallop_mesh::{MeshIndex, TriMesh};
use scallop_waterline::{Loop, WaterlineGrid, WaterlineOptions};

fn winding(loops: &[Loop], q: Point2) -> i32 {
    loops.iter().map(|l| l.winding_number(q)).sum()
}

const BOX_HEIGHT: f64 = 10.0;
const BOX_LENGTH: f64 = 10.0;

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, .. ProptestConfig::default() })]

    /// Two boxes 10 mm high side by side, their facing walls `2 R + gap` apart,
    /// the pair turned by a random angle. At z = 5 every shape meets the walls
    /// with its full radius R, so the cutter fits between the boxes on a strip
    /// `gap` wide (a few micrometres, far under the grid step R/4): the
    /// waterline is two loops, one around each box, and the strip is outside.
    #[test]
    fn a_slot_barely_wider_than_the_cutter_separates_the_two_loops(
        kind in 0u8..4,
        radius in 0.8..2.5f64,
        gap in 2e-6..2e-3f64,
        angle in 0.0..std::f64::consts::TAU,
        wall in 0.0..1.0f64,
    ) {
        slot_separates_the_two_loops(kind, radius, gap, angle, wall)?;
    }
}

/// The check of `a_slot_barely_wider_than_the_cutter_separates_the_two_loops`
/// for one input: two loops, both outer, and the middle of the strip between
/// the boxes outside by the brute force and by the loops.
fn slot_separates_the_two_loops(kind: u8, radius: f64, gap: f64, angle: f64, wall: f64) -> Result<(), TestCaseError> {
    let x1 = BOX_LENGTH + wall; // the first box's wall, off the grid lines
    let x2 = x1 + 2.0 * radius + gap;
    let mut soup = common::box_soup(angle, 0.0, x1, BOX_LENGTH, BOX_HEIGHT);
    soup.extend(common::box_soup(angle, x2, x2 + BOX_LENGTH, BOX_LENGTH, BOX_HEIGHT));
    let mesh = TriMesh::from_soup(&soup).expect("two boxes").0;
    let index = MeshIndex::build(&mesh);
    let cutter = Cutter::new(common::shape_of(kind, radius), 40.0).expect("cutter");
    let z = 0.5 * BOX_HEIGHT;
    let loops =
        WaterlineGrid::new(&cutter, &index, &WaterlineOptions::default()).expect("grid").loops(z).expect("level");
    prop_assert_eq!(loops.len(), 2, "one loop around each box");
    prop_assert!(loops.iter().all(Loop::is_outer));
    // The middle of the strip, along the walls: outside by the brute force and by the loops.
    let floor = -100.0;
    for k in 0..=16 {
        let y = BOX_LENGTH * (0.05 + 0.9 * f64::from(k) / 16.0);
        let m = common::rotated(angle, x1 + radius + 0.5 * gap, y, 0.0);
        let q = Point2::new(m.x, m.y);
        let d = drop_cutter_brute_force(&cutter, &index, q, floor).tip.z;
        prop_assert!(d <= z, "the brute force puts the strip's middle {q:?} inside ({d})");
        prop_assert_eq!(winding(&loops, q), 0, "strip middle {:?} inside the loops", q);
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, .. ProptestConfig::default() })]

    /// The slot of `a_slot_barely_wider_than_the_cutter_separates_the_two_loops`
    /// with a flat cutter, a few micrometres wide and within 4 degrees of a
    /// grid direction, where its failures were found: the slot's mouth runs
    /// along a grid edge for several cells, and a grid edge with ends on
    /// different sides may hold three crossings.
    #[test]
    fn a_thin_slot_nearly_along_the_grid_separates_the_two_loops(
        radius in 0.8..2.5f64,
        gap in 2e-6..2e-5f64,
        quarter in 0u8..4,
        off in -0.07..0.07f64,
        wall in 0.0..1.0f64,
    ) {
        let angle = (f64::from(quarter) * std::f64::consts::FRAC_PI_2 + off).rem_euclid(std::f64::consts::TAU);
        slot_separates_the_two_loops(0, radius, gap, angle, wall)?;
    }
}

/// The inputs of `a_slot_barely_wider_than_the_cutter_separates_the_two_loops`
/// that failed for random seeds before the fix of docs/waterline.md (step 3,
/// "A side's midpoint against its crossings"): a flat cutter, a 2 µm slot
/// within 3 degrees of a grid direction, whose mouth passes within a micrometre
/// of a grid edge with ends on different sides that holds three crossings.
#[test]
fn a_slot_nearly_along_the_grid_separates_the_two_loops() {
    let cases = [
        (2.223210482161757, 4.770445022835908, 0.0),
        (2.374435273889911, 1.5975191050731326, 0.4224856279390674),
        (1.6231453952751853, 3.1992017541795468, 0.0),
        (1.7682290773247413, 3.1585699007764974, 0.0),
        // Found by `a_thin_slot_nearly_along_the_grid_separates_the_two_loops`.
        (0.8089310291157943, std::f64::consts::PI + 0.016355600673108418, 0.0),
        (1.1278162019523357, std::f64::consts::FRAC_PI_2 + 0.02937806583184269, 0.3319373871831357),
    ];
    let failed: Vec<String> = cases
        .iter()
        .filter_map(|&(radius, angle, wall)| {
            let e = slot_separates_the_two_loops(0, radius, 2e-6, angle, wall).err()?;
            Some(format!("flat R {radius}, angle {angle}, wall {wall}: {e}"))
        })
        .collect();
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}

/// A square pyramid 10 mm high over the base [-2, 2]^2 at height 0, apex at (ax, ay).
fn pyramid(ax: f64, ay: f64) -> TriMesh {
    let apex = Point3::new(ax, ay, BOX_HEIGHT);
    let c = [Point3::new(-2., -2., 0.), Point3::new(2., -2., 0.), Point3::new(2., 2., 0.), Point3::new(-2., 2., 0.)];
    let soup: Vec<[Point3; 3]> = (0..4).map(|k| [c[k], c[(k + 1) % 4], apex]).collect();
    TriMesh::from_soup(&soup).expect("pyramid").0
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, .. ProptestConfig::default() })]

    /// z just under the apex of a steep pyramid: the cutter cuts the part only
    /// on a small island around the apex (for the ball and the cone a few
    /// micrometres to a few hundredths of a millimetre across, far under the
    /// grid step), which the waterline must hold.
    #[test]
    fn a_peak_just_above_z_gives_a_small_island(
        kind in 0u8..4,
        radius in 0.8..2.5f64,
        below in 0.002..0.08f64,
        ax in -0.5..0.5f64,
        ay in -0.5..0.5f64,
    ) {
        let mesh = pyramid(ax, ay);
        let index = MeshIndex::build(&mesh);
        let cutter = Cutter::new(common::shape_of(kind, radius), 40.0).expect("cutter");
        let z = BOX_HEIGHT - below;
        let loops = WaterlineGrid::new(&cutter, &index, &WaterlineOptions::default()).expect("grid").loops(z).expect("level");
        let apex = Point2::new(ax, ay);
        let floor = -100.0;
        prop_assert!(drop_cutter_brute_force(&cutter, &index, apex, floor).tip.z > z);
        prop_assert_eq!(loops.len(), 1, "one island around the apex");
        prop_assert_eq!(winding(&loops, apex), 1, "the apex is inside the loops");
        for q in &loops[0].points {
            prop_assert!(drop_cutter_brute_force(&cutter, &index, *q, floor).tip.z <= z, "loop point {:?} cuts", q);
        }
    }
}

mod common;

/// A wedge ridge along x over `[x0, x1]`, its crest at height `top` on the
/// line y = `y` and its flanks `half` wide at height 0, rotated.
fn ridge_soup(angle: f64, x0: f64, x1: f64, y: f64, half: f64, top: f64) -> Vec<[Point3; 3]> {
    let p = |x, yy, z| common::rotated(angle, x, yy, z);
    let (a0, a1) = (p(x0, y - half, 0.), p(x1, y - half, 0.));
    let (c0, c1) = (p(x0, y, top), p(x1, y, top));
    let (b0, b1) = (p(x0, y + half, 0.), p(x1, y + half, 0.));
    vec![[a0, a1, c1], [a0, c1, c0], [c0, c1, b1], [c0, b1, b0]]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, .. ProptestConfig::default() })]

    /// The slot between two boxes (barely wider than the cutter) is crossed by
    /// a low ridge whose crest is just above z: the channel of outside is cut
    /// in two by a thin band of inside. No chord may run along the channel
    /// across the band (it would cut the ridge): every vertex and chord is on
    /// the contact surface. Flat, ball and bull-nose: the cone fails the chord
    /// check here too (kind 3, R 0.8, gap 0.01927, angle 1.8078, wall 0,
    /// ridge_y 5.1204, above 0.006636: a midpoint 3.9e-4 mm too high), an open
    /// item of `docs/waterline.md`.
    #[test]
    fn a_ridge_across_a_thin_slot_is_never_cut(
        kind in 0u8..3,
        radius in 0.8..2.5f64,
        gap in 2e-6..2e-2f64,
        angle in 0.0..std::f64::consts::TAU,
        wall in 0.0..1.0f64,
        ridge_y in 2.0..8.0f64,
        above in 1e-3..0.05f64,
    ) {
        let x1 = BOX_LENGTH + wall;
        let x2 = x1 + 2.0 * radius + gap;
        let z = 0.5 * BOX_HEIGHT;
        let mut soup = common::box_soup(angle, 0.0, x1, BOX_LENGTH, BOX_HEIGHT);
        soup.extend(common::box_soup(angle, x2, x2 + BOX_LENGTH, BOX_LENGTH, BOX_HEIGHT));
        soup.extend(ridge_soup(angle, x1 - 1.0, x2 + 1.0, ridge_y, 0.5, z + above));
        let mesh = TriMesh::from_soup(&soup).expect("boxes and ridge").0;
        let index = MeshIndex::build(&mesh);
        let cutter = Cutter::new(common::shape_of(kind, radius), 40.0).expect("cutter");
        let options = WaterlineOptions::default();
        let grid = WaterlineGrid::new(&cutter, &index, &options).expect("grid");
        let loops = grid.loops(z).expect("level");
        let reach = options.chord_tolerance * (1.0 + 1e-6) + options.crossing_tolerance;
        let checked = common::check_on_contact(&cutter, &index, &loops, z, 1e-5, reach, grid.step());
        prop_assert!(checked.is_ok(), "{}", checked.unwrap_err());
    }
}

/// The points of a mesh (a triangle soup) that lie inside the contour at `z`
/// with a margin of at least `margin`: the inside is the union of the disks of
/// radius `radius_at(q.z - z)` around the mesh points q above z, so every
/// vertex whose radius there is at least `margin`, and every point where an
/// edge crosses the height where the radius reaches `margin`.
fn witnesses(cutter: &Cutter, soup: &[[Point3; 3]], z: f64, margin: f64) -> Vec<Point2> {
    let shape = cutter.shape();
    let clip = z + shape.height_at(margin).max(1e-6);
    let mut out = Vec::new();
    for t in soup {
        for k in 0..3 {
            let (v, w) = (t[k], t[(k + 1) % 3]);
            if v.z > z && shape.radius_at(v.z - z) >= margin {
                out.push(Point2::new(v.x, v.y));
            }
            if (v.z > clip) != (w.z > clip) {
                let s = (clip - v.z) / (w.z - v.z);
                out.push(Point2::new(v.x + s * (w.x - v.x), v.y + s * (w.y - v.y)));
            }
        }
    }
    out
}

/// Whether two chords of the loops cross at a point interior to both.
fn loops_cross(loops: &[Loop]) -> Option<(Point2, Point2)> {
    use scallop_geom::predicates::orient2d;
    let chords: Vec<(Point2, Point2)> = loops
        .iter()
        .flat_map(|l| (0..l.points.len()).map(move |i| (l.points[i], l.points[(i + 1) % l.points.len()])))
        .collect();
    let apart = |s: f64, t: f64| (s > 0.0 && t < 0.0) || (s < 0.0 && t > 0.0);
    for (k, (p, q)) in chords.iter().enumerate() {
        for (a, b) in &chords[k + 1..] {
            if apart(orient2d(p, q, a), orient2d(p, q, b)) && apart(orient2d(a, b, p), orient2d(a, b, q)) {
                return Some((*p, *a));
            }
        }
    }
    None
}

/// A vertical fin in the plane y = `y0` (box frame): its top edge runs from
/// `z + above` at `x0` down to `z - above` at `x0 + 2 * run`, so it crosses z at
/// `x0 + run`; its third corner is at height 0 under the first.
fn fin_soup(angle: f64, x0: f64, run: f64, y0: f64, z: f64, above: f64) -> [Point3; 3] {
    let p = |x, y, zz| common::rotated(angle, x, y, zz);
    [p(x0, y0, z + above), p(x0 + 2.0 * run, y0, z - above), p(x0, y0, 0.0)]
}

/// A box 10.1 x 10 mm, 5 mm high, and a fin leaving its side at x = 10.9
/// whose top edge crosses z = 1 at x = 12.1, 0.1 mm off the grid row y = 5;
/// a cone 2 mm across (90 degrees included), grid step 0.5 mm. The inside at
/// z = 1 is the box widened by the radius (its side at x = 11.1) and a thin
/// arm along the fin, at most 0.2 mm wide, whose tip is where the fin's top
/// edge meets z (the cone's radius there is 0): no sample lies in the arm, and
/// the chord along the side at x = 11.1 passes its base. The loop reaches the
/// tip.
#[test]
fn a_thin_arm_between_samples_reaches_its_tip() {
    let (z, step) = (1.0, 0.5);
    let mut soup = common::box_soup(0.0, 0.0, 10.1, BOX_LENGTH, 5.0);
    soup.push(fin_soup(0.0, 10.9, 1.2, 5.1, z, 0.12));
    let mesh = TriMesh::from_soup(&soup).expect("box and fin").0;
    let index = MeshIndex::build(&mesh);
    let cone = scallop_cutter::CutterShape::Cone { radius: 1.0, half_angle: std::f64::consts::FRAC_PI_4 };
    let cutter = Cutter::new(cone, 20.0).expect("cutter");
    let options = WaterlineOptions { step: Some(step), ..WaterlineOptions::default() };
    let grid = WaterlineGrid::new(&cutter, &index, &options).expect("grid");
    // The setup: no sample beyond the box's widened side is inside.
    let (nx, ny) = grid.shape();
    for j in 0..ny {
        for i in 0..nx {
            let x = grid.origin().x + i as f64 * step;
            assert!(x <= 11.1 || grid.height(i, j) <= z, "sample ({i}, {j}) in the arm");
        }
    }
    let loops = grid.loops(z).expect("level");
    assert_eq!(loops.len(), 1);
    let far = loops[0].points.iter().map(|q| q.x).fold(f64::MIN, f64::max);
    assert!((far - 12.1).abs() < 1e-5, "the loop reaches x = {far}, the arm's tip is at 12.1");
    assert_eq!(loops_cross(&loops), None);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, .. ProptestConfig::default() })]

    /// A box 10 mm high and a fin leaving its side, whose top edge runs down
    /// through z = 5 just outside the box's widened side (ball or cone): a thin
    /// arm of inside, often between the samples of the default grid. Every
    /// mesh point inside the contour with a margin of 8 chord tolerances (the
    /// witnesses) is inside the loops (a winding number other than 0). That
    /// no two chords cross, and a winding number of exactly 1, are not
    /// asserted here: where the grid sees a piece of the arm apart from its
    /// base, the trace gives that piece a loop of its own, which crosses the
    /// main loop (an open item of `docs/waterline.md`).
    #[test]
    fn every_mesh_point_with_margin_is_inside_the_loops(
        cone in any::<bool>(),
        radius in 0.8..2.5f64,
        angle in 0.0..std::f64::consts::TAU,
        wall in 0.0..1.0f64,
        y0 in 2.0..8.0f64,
        above in 1e-3..0.03f64,
        run in 0.2..0.8f64,
    ) {
        let z = 0.5 * BOX_HEIGHT;
        let x1 = BOX_LENGTH + wall;
        let mut soup = common::box_soup(angle, 0.0, x1, BOX_LENGTH, BOX_HEIGHT);
        // The fin starts 0.2 mm inside the widened side and crosses z `run - 0.2` mm outside it.
        soup.push(fin_soup(angle, x1 + radius - 0.2, run, y0, z, above));
        let mesh = TriMesh::from_soup(&soup).expect("box and fin").0;
        let index = MeshIndex::build(&mesh);
        let cutter = Cutter::new(common::shape_of(if cone { 3 } else { 1 }, radius), 40.0).expect("cutter");
        let options = WaterlineOptions::default();
        let loops = WaterlineGrid::new(&cutter, &index, &options).expect("grid").loops(z).expect("level");
        for w in witnesses(&cutter, &soup, z, 8.0 * options.chord_tolerance) {
            prop_assert!(winding(&loops, w) != 0, "mesh point {:?} (inside with margin) outside the loops", w);
        }
    }
}
