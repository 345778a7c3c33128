//! The z-map's banding, stadium clipping and tile skipping never change a
//! result: after a random program every cell equals the minimum over the
//! moves of the exact swept floor at its centre (clamped to the stock), and
//! the move recorded as its last cut is one that reaches that height.

#![allow(clippy::unwrap_used, reason = "tests fail loudly by design")]

mod common;

use proptest::prelude::*;
use scallop_cutter::{Cutter, CutterShape};
use scallop_geom::{Aabb3, Point3};
use scallop_sim::{ZMap, swept_floor};
use scallop_toolpath::{Move, MoveKind, Toolpath};

fn shapes() -> impl Strategy<Value = CutterShape> {
    common::shapes(0.3..3.0, 0.1..1.0, 0.2..1.4)
}

fn points() -> impl Strategy<Value = Vec<Point3>> {
    prop::collection::vec((-1.0..11.0f64, -1.0..9.0f64, -3.0..1.0f64), 1..12)
        .prop_map(|v| v.into_iter().map(|(x, y, z)| Point3::new(x, y, z)).collect())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn cells_equal_the_minimum_of_the_exact_floors(shape in shapes(), points in points(), resolution in 0.07..0.3f64) {
        let stock = Aabb3 { min: Point3::new(0.0, 0.0, -2.0), max: Point3::new(10.0, 8.0, 0.0) };
        let cutter = Cutter::new(shape, 30.0).unwrap();
        let mut path = Toolpath::new(1000.0);
        for q in &points {
            path.push(Move::new(MoveKind::Feed, *q));
        }
        let mut zmap = ZMap::new(stock, resolution).unwrap();
        let report = zmap.cut(&cutter, &path).unwrap();
        let floors = |c: &scallop_geom::Point2| -> Vec<f64> {
            (0..points.len())
                .map(|k| {
                    let from = if k == 0 { points[0] } else { points[k - 1] };
                    swept_floor(&shape, &from, &points[k], c).unwrap_or(f64::INFINITY)
                })
                .collect()
        };
        let mut removed = 0.0;
        for j in 0..zmap.ny() {
            for i in 0..zmap.nx() {
                let c = zmap.cell_center(i, j);
                let f = floors(&c);
                let expected = f.iter().copied().fold(stock.max.z, f64::min).max(stock.min.z);
                let h = zmap.height(i, j).unwrap();
                prop_assert!((h - expected).abs() <= 1e-12, "cell ({i}, {j}) at {c}: {h} vs {expected}");
                removed += stock.max.z - h;
                if let Some(id) = zmap.last_cut(i, j) {
                    prop_assert!(f[id.index as usize].max(stock.min.z) <= h + 1e-12);
                } else {
                    prop_assert!(expected >= stock.max.z - 1e-12);
                }
            }
        }
        let (cx, cy) = zmap.cell_size();
        prop_assert!((report.removed_volume - removed * cx * cy).abs() <= 1e-9 * (1.0 + removed * cx * cy));
    }
}
