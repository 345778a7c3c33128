//! The software render: deterministic, and the part's silhouette is where
//! the analytic outline says (pixel statistics).
#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

use scallop_geom::Point3;
use scallop_mesh::TriMesh;
use scallop_report::render::{BACKGROUND, Camera, render};
use scallop_report::{KIND_COLOURS, ReportData};
use scallop_toolpath::{Move, MoveKind, Toolpath};

fn box_mesh(lo: Point3, hi: Point3) -> TriMesh {
    let c = |k: usize| {
        Point3::new(
            if k & 1 == 0 { lo.x } else { hi.x },
            if k & 2 == 0 { lo.y } else { hi.y },
            if k & 4 == 0 { lo.z } else { hi.z },
        )
    };
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let soup: Vec<[Point3; 3]> =
        quads.iter().flat_map(|q| [[c(q[0]), c(q[1]), c(q[2])], [c(q[0]), c(q[2]), c(q[3])]]).collect();
    TriMesh::from_soup(&soup).unwrap().0
}

fn sphere_mesh(centre: Point3, r: f64, n: usize) -> TriMesh {
    let at = |i: usize, j: usize| {
        let (th, ph) = (std::f64::consts::PI * i as f64 / n as f64, std::f64::consts::TAU * j as f64 / (2 * n) as f64);
        centre + r * scallop_geom::Vec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos())
    };
    let mut soup = Vec::new();
    for i in 0..n {
        for j in 0..2 * n {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            if i > 0 {
                soup.push([a, b, d]);
            }
            if i + 1 < n {
                soup.push([b, c, d]);
            }
        }
    }
    TriMesh::from_soup(&soup).unwrap().0
}

fn covered(img: &scallop_report::png::Image) -> usize {
    img.pixels.chunks(3).filter(|p| *p != BACKGROUND).count()
}

/// Area of the convex hull of points (shoelace over Andrew's monotone chain).
fn hull_area(mut pts: Vec<[f64; 2]>) -> f64 {
    pts.sort_by(|a, b| a.partial_cmp(b).unwrap());
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
    let mut hull: Vec<[f64; 2]> = Vec::new();
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &[f64; 2]>> =
            if pass == 0 { Box::new(pts.iter()) } else { Box::new(pts.iter().rev()) };
        for &p in iter {
            while hull.len() >= start + 2 && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0 {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    let n = hull.len();
    0.5 * (0..n).map(|i| cross([0.0, 0.0], hull[i], hull[(i + 1) % n])).sum::<f64>().abs()
}

#[test]
fn a_box_covers_its_projected_hexagon() {
    let (lo, hi) = (Point3::new(-10.0, -5.0, 0.0), Point3::new(30.0, 15.0, 8.0));
    let mut data = ReportData::new("box");
    data.part = Some(box_mesh(lo, hi));
    let (w, h) = (400, 300);
    let img = render(&data, w, h);
    let cam = Camera::isometric(&data.bounds().unwrap(), w, h);
    let corners: Vec<[f64; 2]> = (0..8)
        .map(|k| {
            let p = Point3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            );
            let q = cam.project(&p);
            [q[0], q[1]]
        })
        .collect();
    let expected = hull_area(corners);
    let got = covered(&img) as f64;
    assert!((got - expected).abs() <= 0.03 * expected, "covered {got} px, outline {expected} px");
    // The image corners stay background.
    for (x, y) in [(0, 0), (w - 1, 0), (0, h - 1), (w - 1, h - 1)] {
        assert_eq!(img.get(x, y).unwrap(), BACKGROUND);
    }
    // Shaded: the three visible faces have three different colours.
    let mut colours: Vec<[u8; 3]> =
        img.pixels.chunks(3).map(|p| [p[0], p[1], p[2]]).filter(|p| *p != BACKGROUND).collect();
    colours.sort_unstable();
    colours.dedup();
    assert_eq!(colours.len(), 3, "{colours:?}");
}

#[test]
fn a_sphere_covers_its_disc_and_nothing_outside() {
    let (c, r) = (Point3::new(5.0, -3.0, 2.0), 12.0);
    let mut data = ReportData::new("sphere");
    data.part = Some(sphere_mesh(c, r, 48));
    let (w, h) = (320, 320);
    let img = render(&data, w, h);
    let cam = Camera::isometric(&data.bounds().unwrap(), w, h);
    let centre = cam.project(&c);
    let rp = r * cam.pixels_per_mm();
    let expected = std::f64::consts::PI * rp * rp;
    let got = covered(&img) as f64;
    assert!((got - expected).abs() <= 0.03 * expected, "covered {got} px, disc {expected} px");
    for y in 0..h {
        for x in 0..w {
            let d = ((x as f64 + 0.5 - centre[0]).powi(2) + (y as f64 + 0.5 - centre[1]).powi(2)).sqrt();
            let bg = img.get(x, y).unwrap() == BACKGROUND;
            if d > 1.02 * rp + 1.0 {
                assert!(bg, "pixel ({x}, {y}) outside the disc is drawn");
            }
            if d < 0.97 * rp - 1.0 {
                assert!(!bg, "pixel ({x}, {y}) inside the disc is background");
            }
        }
    }
}

#[test]
fn renders_are_byte_identical_and_show_the_toolpath_on_top() {
    let mut data = ReportData::new("box and path");
    data.part = Some(box_mesh(Point3::new(0.0, 0.0, 0.0), Point3::new(20.0, 10.0, 5.0)));
    let mut path = Toolpath::new(1000.0);
    path.push(Move::new(MoveKind::Rapid, Point3::new(0.0, 0.0, 10.0)));
    path.push(Move::new(MoveKind::Plunge, Point3::new(0.0, 0.0, 5.0)));
    for k in 0..10 {
        let y = f64::from(k);
        path.push(Move::new(MoveKind::Feed, Point3::new(if k % 2 == 0 { 20.0 } else { 0.0 }, y, 5.0)));
        path.push(Move::new(MoveKind::Link, Point3::new(if k % 2 == 0 { 20.0 } else { 0.0 }, y + 1.0, 5.0)));
    }
    path.push(Move::new(MoveKind::Retract, Point3::new(0.0, 10.0, 10.0)));
    path.push(Move::new(MoveKind::Rapid, Point3::new(0.0, 0.0, 10.0)));
    data.toolpath = Some(path);
    data.stock = Some(scallop_geom::Aabb3 { min: Point3::new(-1.0, -1.0, -1.0), max: Point3::new(21.0, 11.0, 6.0) });
    let a = render(&data, 300, 200).to_png();
    assert_eq!(a, render(&data, 300, 200).to_png());
    let img = render(&data, 300, 200);
    for (kind, colour) in KIND_COLOURS.iter().enumerate() {
        assert!(img.pixels.chunks(3).any(|p| p == colour), "kind {kind} not drawn");
    }
}
