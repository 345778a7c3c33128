//! The per-face metrics of the proof (spec 10.1, `face_metrics`): on a blank
//! whose top is a plane parallel to the pocket's tilted bottom, one known
//! thickness above it, every sample outside the corners reads that thickness
//! along the normal, whatever the slope; crests are the thickness above the
//! allowance; a stock cut to the bottom reads no crest, and cut below it a
//! negative deviation of the overcut.

use proptest::prelude::*;
use scallop_geom::{Aabb3, Point3};
use scallop_mesh::TriMesh;
use scallop_rough5::{ProofFace, face_metrics};
use scallop_sim::{DexelPart, DexelStock};

const SIZE: f64 = 20.0;

/// The 12 triangles of a hexahedron over [0, SIZE]^2 between `bottom(x)` and
/// `top(x)`, outward normals: bottom (2), top (2), then the four sides (8).
fn prism(bottom: impl Fn(f64) -> f64, top: impl Fn(f64) -> f64) -> Vec<[Point3; 3]> {
    let b = |x: f64, y: f64| Point3::new(x, y, bottom(x));
    let t = |x: f64, y: f64| Point3::new(x, y, top(x));
    let (b00, b10, b11, b01) = (b(0.0, 0.0), b(SIZE, 0.0), b(SIZE, SIZE), b(0.0, SIZE));
    let (t00, t10, t11, t01) = (t(0.0, 0.0), t(SIZE, 0.0), t(SIZE, SIZE), t(0.0, SIZE));
    vec![
        [b00, b01, b11],
        [b00, b11, b10],
        [t00, t10, t11],
        [t00, t11, t01],
        [b00, b10, t10],
        [b00, t10, t00],
        [b10, b11, t11],
        [b10, t11, t10],
        [b11, b01, t01],
        [b11, t01, t11],
        [b01, b00, t00],
        [b01, t00, t01],
    ]
}

fn mesh(triangles: &[[Point3; 3]]) -> TriMesh {
    TriMesh::from_soup(triangles).expect("mesh").0
}

/// The bottom metrics of a pocket over a bottom of slope `slope` at height 5,
/// on a blank whose top is `lift` above the bottom along Z.
fn bottom_metrics(slope: f64, lift: f64, allowance: f64) -> scallop_rough5::FaceMetrics {
    let floor = move |x: f64| 5.0 + slope * x;
    let volume = prism(floor, |_| 30.0);
    let blank = mesh(&prism(|_| 0.0, move |x| floor(x) + lift));
    let stock = Aabb3 { min: Point3::new(0.0, 0.0, 0.0), max: Point3::new(SIZE, SIZE, 30.0) };
    let dexels = DexelStock::from_solid(stock, 0.5, &DexelPart::new(&blank)).expect("stock");
    let (bottom, sides) = (mesh(&volume[..2]), mesh(&volume[4..]));
    let face = ProofFace { name: "bottom", mesh: &bottom, others: &sides, allowance, corner: 2.0 };
    face_metrics(&dexels, &DexelPart::new(&mesh(&volume)), &face, 0.5)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(12))]
    #[test]
    fn a_parallel_layer_reads_its_normal_thickness(slope in 0.0..0.5f64, lift in 0.2..3.0f64, allowance in 0.0..0.5f64) {
        let m = bottom_metrics(slope, lift, allowance);
        // The layer's thickness along the bottom's normal.
        let t = lift / slope.hypot(1.0);
        let d = m.deviation_quartiles_outside_corners;
        for q in d {
            prop_assert!((q - (t - allowance)).abs() < 1e-9, "{d:?} against {}", t - allowance);
        }
        prop_assert!(m.corner_samples > 0 && m.corner_samples < m.samples);
        prop_assert!((m.area - SIZE * SIZE * slope.hypot(1.0)).abs() < 1e-9);
        let crest = (t - allowance).max(0.0);
        prop_assert!((m.crest_max - crest).abs() < 1e-9 && (m.crest_mean - crest).abs() < 1e-9);
        prop_assert!(m.crest_sigma < 1e-6);
    }
}

#[test]
fn an_overcut_bottom_reads_a_negative_deviation() {
    // The blank's top 0.3 mm below the bottom: cut 0.3 mm too deep, 0.5 mm allowance asked.
    let m = bottom_metrics(0.2, -0.3, 0.5);
    let t = -0.3 / 0.2f64.hypot(1.0);
    for q in m.deviation_quartiles_outside_corners {
        assert!((q - (t - 0.5)).abs() < 1e-9, "{:?}", m.deviation_quartiles_outside_corners);
    }
    assert!(m.crest_max == 0.0 && m.crest_mean == 0.0);
}
