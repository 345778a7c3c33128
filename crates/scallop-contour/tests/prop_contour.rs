//! Analytic offsets and boolean identities of the contour layer.
#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

use std::f64::consts::PI;

use proptest::prelude::*;
use scallop_contour::{Contour, Region};

fn rect(x0: f64, y0: f64, w: f64, h: f64) -> Region {
    let c = Contour::polygon(&[[x0, y0], [x0 + w, y0], [x0 + w, y0 + h], [x0, y0 + h]], true).unwrap();
    Region::with_holes(c, Vec::new()).unwrap()
}

fn disc(cx: f64, cy: f64, r: f64) -> Region {
    Region::with_holes(Contour::circle([cx, cy], r).unwrap(), Vec::new()).unwrap()
}

/// Chord tolerance of the booleans in these tests (mm).
const CHORD: f64 = 1e-4;

proptest! {
    /// A disc offset inwards by d is the disc of radius r - d; outwards, r + d.
    #[test]
    fn circle_offsets_are_circles(r in 1.0..50.0_f64, f in 0.05..0.9_f64, cx in -100.0..100.0_f64) {
        let d = f * r;
        let inner = disc(cx, 1.0, r).offset(d);
        prop_assert!((inner.area() - PI * (r - d).powi(2)).abs() < 1e-9 * r * r, "{}", inner.area());
        let outer = disc(cx, 1.0, r).offset(-d);
        prop_assert!((outer.area() - PI * (r + d).powi(2)).abs() < 1e-9 * r * r);
        // Arcs kept: one ring of arcs, no chords.
        prop_assert_eq!(inner.rings().len(), 1);
        prop_assert!(inner.rings()[0].vertices().iter().all(|v| v.bulge != 0.0));
    }

    /// A rectangle offset inwards by d: (w - 2d)(h - 2d); outwards: the
    /// rectangle, four side strips and four quarter discs.
    #[test]
    fn rectangle_offsets(w in 2.0..80.0_f64, h in 2.0..80.0_f64, f in 0.01..0.49_f64) {
        let d = f * w.min(h);
        let r = rect(-3.0, 7.0, w, h);
        let a = r.offset(d).area();
        prop_assert!((a - (w - 2.0 * d) * (h - 2.0 * d)).abs() < 1e-9 * w * h, "{a}");
        let a = r.offset(-d).area();
        prop_assert!((a - (w * h + 2.0 * d * (w + h) + PI * d * d)).abs() < 1e-9 * w * h, "{a}");
    }

    /// |A u B| = |A| + |B| - |A n B| and |A \ B| = |A| - |A n B|, for
    /// rectangles and discs (chords within CHORD).
    #[test]
    fn boolean_area_identities(
        x in -20.0..20.0_f64, y in -20.0..20.0_f64, w in 1.0..30.0_f64, h in 1.0..30.0_f64,
        cx in -20.0..20.0_f64, cy in -20.0..20.0_f64, r in 1.0..20.0_f64,
    ) {
        let (a, b) = (rect(x, y, w, h), disc(cx, cy, r));
        let (u, i, d) = (a.union(&b, CHORD), a.intersection(&b, CHORD), a.difference(&b, CHORD));
        // The chords of the disc lose at most its perimeter times the tolerance.
        let slack = 2.0 * PI * r * CHORD + 1e-9 * (w * h + r * r);
        prop_assert!((u.area() - (a.area() + b.area() - i.area())).abs() < 2.0 * slack, "{} {} {} {}", u.area(), a.area(), b.area(), i.area());
        prop_assert!((d.area() - (a.area() - i.area())).abs() < 2.0 * slack);
        prop_assert!(i.area() <= a.area().min(b.area()) + slack);
        // Containment agrees with the parts away from the boundaries.
        let p = [x + 0.5 * w, y + 0.5 * h];
        let dist = ((p[0] - cx).hypot(p[1] - cy) - r).abs();
        if dist > 0.01 {
            let in_b = (p[0] - cx).hypot(p[1] - cy) < r;
            prop_assert!(u.contains(p));
            prop_assert_eq!(i.contains(p), in_b);
            prop_assert_eq!(d.contains(p), !in_b);
        }
    }

    /// Chords of an arc contour within a tolerance, fitted back to arcs,
    /// keep the area within the tolerance times the perimeter.
    #[test]
    fn arcs_to_chords_and_back(r in 0.5..40.0_f64, tol_exp in -4.0..-1.0_f64) {
        let tolerance = 10f64.powf(tol_exp);
        let c = Contour::circle([2.0, -1.0], r).unwrap();
        let pts = c.to_points(tolerance);
        // Every chord midpoint within the tolerance of the circle.
        for k in 0..pts.len() {
            let (p, q) = (pts[k], pts[(k + 1) % pts.len()]);
            let m = [(p[0] + q[0]) / 2.0 - 2.0, (p[1] + q[1]) / 2.0 + 1.0];
            prop_assert!(r - m[0].hypot(m[1]) <= tolerance * (1.0 + 1e-9));
        }
        let back = Contour::from_points(&pts, true, tolerance).unwrap();
        prop_assert!(back.len() < pts.len() || pts.len() <= 4);
        let exact = PI * r * r;
        prop_assert!((back.signed_area() - exact).abs() <= 2.0 * PI * r * tolerance * 2.0, "{} {}", back.signed_area(), exact);
    }
}

/// A rectangle with a round island: the area and containment; components
/// keep the hole with its outer boundary; a pocket region offset inwards
/// grows the island by the offset.
#[test]
fn island_region() {
    let outer = Contour::polygon(&[[0.0, 0.0], [100.0, 0.0], [100.0, 60.0], [0.0, 60.0]], true).unwrap();
    let island = Contour::circle([50.0, 30.0], 12.0).unwrap().reversed();
    let region = Region::with_holes(outer, vec![island]).unwrap();
    assert!((region.area() - (6000.0 - PI * 144.0)).abs() < 1e-9);
    assert!(region.contains([5.0, 5.0]) && !region.contains([50.0, 30.0]) && !region.contains([150.0, 30.0]));
    assert_eq!(region.components().len(), 1);
    assert_eq!(region.components()[0].rings().len(), 2);
    let off = region.offset(3.0);
    assert!((off.area() - (94.0 * 54.0 - PI * 15.0 * 15.0)).abs() < 1e-6, "{}", off.area());
    // A segment across the island leaves the region; one along the side does not.
    assert!(!region.contains_segment([10.0, 30.0], [90.0, 30.0], 1e-3));
    assert!(region.contains_segment([10.0, 5.0], [90.0, 5.0], 1e-3));
    // Oriented polygon input: a clockwise ring inside is a hole.
    let poly = Region::from_polygons(
        &[
            vec![[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]],
            vec![[2.0, 2.0], [2.0, 8.0], [8.0, 8.0], [8.0, 2.0]],
        ],
        true,
    );
    assert!((poly.area() - 64.0).abs() < 1e-9, "{}", poly.area());
}

/// Starting a closed contour near a point keeps its length and area.
#[test]
fn starting_near_splits_a_segment() {
    let c = Contour::polygon(&[[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]], true).unwrap();
    let s = c.starting_near([4.0, -1.0]);
    assert_eq!(s.start(), Some([4.0, 0.0]));
    assert!((s.length() - 40.0).abs() < 1e-12 && (s.signed_area() - 100.0).abs() < 1e-12);
    let circle = Contour::circle([0.0, 0.0], 5.0).unwrap().starting_near([0.0, 9.0]);
    let p = circle.start().unwrap();
    assert!(p[0].abs() < 1e-9 && (p[1] - 5.0).abs() < 1e-9, "{p:?}");
    assert!((circle.signed_area() - 25.0 * PI).abs() < 1e-9);
}

proptest! {
    /// `holds_disc(c, r)` is `offset(r).contains(c)` (a rectangle with a
    /// round island and a rounded corner: lines, arcs, a hole), away from
    /// ties: points within 1e-6 mm of the offset boundary are skipped.
    #[test]
    fn holds_disc_is_containment_in_the_offset(
        r in 0.2..6.0_f64,
        points in proptest::collection::vec((-5.0..65.0_f64, -5.0..45.0_f64), 60),
    ) {
        let outer = Contour::new(
            &[
                scallop_contour::Vertex { x: 0.0, y: 0.0, bulge: 0.0 },
                scallop_contour::Vertex { x: 60.0, y: 0.0, bulge: 0.0 },
                scallop_contour::Vertex { x: 60.0, y: 30.0, bulge: (PI / 8.0).tan() },
                scallop_contour::Vertex { x: 50.0, y: 40.0, bulge: 0.0 },
                scallop_contour::Vertex { x: 0.0, y: 40.0, bulge: 0.0 },
            ],
            true,
        )
        .unwrap();
        let island = Contour::circle([25.0, 20.0], 6.0).unwrap().reversed();
        let region = Region::with_holes(outer, vec![island]).unwrap();
        let eroded = region.offset(r);
        let (inner, outer_band) = (eroded.offset(1e-6), eroded.offset(-1e-6));
        for (x, y) in points {
            let c = [x, y];
            if inner.contains(c) != outer_band.contains(c) {
                continue;
            }
            prop_assert_eq!(region.holds_disc(c, r), eroded.contains(c), "{:?} r {}", c, r);
        }
    }
}
