//! [`StockView`]: what an operation may read of the in-process stock that the
//! operations before it left, whatever the stock model (z-map or tri-dexel).

use scallop_geom::{Aabb3, Point2};

use crate::{DexelStock, ZMap};

/// A read-only view of the in-process stock: the material top above a point
/// and the material intervals along the vertical line through it. Cell
/// queries: the answer of the grid cell (or Z ray) whose centre is nearest.
pub trait StockView {
    /// The stock's box (mm).
    fn bounds(&self) -> Aabb3;
    /// The highest material point above `(x, y)` (mm), `None` outside the
    /// stock's footprint or where the column holds no material.
    fn top(&self, at: Point2) -> Option<f64>;
    /// The material intervals `[z_low, z_high]` along the vertical line
    /// through `(x, y)`, sorted; empty outside the footprint.
    fn column(&self, at: Point2) -> Vec<[f64; 2]>;
    /// The highest material point of the whole stock (mm), `None` when no
    /// material is left.
    fn max_top(&self) -> Option<f64>;
}

/// The cell of `at` on a grid of `n` cells of `size` from `min`, if inside.
fn cell(at: f64, min: f64, size: f64, n: usize) -> Option<usize> {
    let k = ((at - min) / size).floor();
    // Cell counts far below 2^52: exact conversions.
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, clippy::cast_precision_loss)]
    (k >= 0.0 && k < n as f64).then_some(k as usize)
}

impl StockView for ZMap {
    fn bounds(&self) -> Aabb3 {
        self.stock()
    }

    fn top(&self, at: Point2) -> Option<f64> {
        let (cx, cy) = self.cell_size();
        let b = self.stock();
        let (i, j) = (cell(at.x, b.min.x, cx, self.nx())?, cell(at.y, b.min.y, cy, self.ny())?);
        self.height(i, j).filter(|&h| h > b.min.z + self.eps())
    }

    fn column(&self, at: Point2) -> Vec<[f64; 2]> {
        let bottom = self.stock().min.z;
        self.top(at).map(|h| vec![[bottom, h]]).unwrap_or_default()
    }

    fn max_top(&self) -> Option<f64> {
        let bottom = self.stock().min.z + self.eps();
        self.heights().iter().copied().filter(|&h| h > bottom).reduce(f64::max)
    }
}

impl StockView for DexelStock {
    fn bounds(&self) -> Aabb3 {
        self.stock()
    }

    fn top(&self, at: Point2) -> Option<f64> {
        self.column(at).last().map(|s| s[1])
    }

    fn column(&self, at: Point2) -> Vec<[f64; 2]> {
        let [cx, cy, _] = self.cell_size();
        let [nx, ny, _] = self.counts();
        let b = self.stock();
        match (cell(at.x, b.min.x, cx, nx), cell(at.y, b.min.y, cy, ny)) {
            (Some(i), Some(j)) => self.intervals(2, i, j),
            _ => Vec::new(),
        }
    }

    fn max_top(&self) -> Option<f64> {
        let [nx, ny, _] = self.counts();
        (0..ny)
            .flat_map(|j| (0..nx).map(move |i| (i, j)))
            .filter_map(|(i, j)| self.intervals(2, i, j).last().map(|s| s[1]))
            .reduce(f64::max)
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]
mod tests {
    use super::*;
    use scallop_cutter::{Cutter, CutterShape};
    use scallop_geom::Point3;
    use scallop_toolpath::{Move, MoveKind, Toolpath};

    /// A slot cut by a flat end mill, seen the same way on both stock models:
    /// the top is the slot's floor inside it and the stock top outside.
    #[test]
    fn both_stocks_show_the_slot_a_flat_end_mill_cut() {
        let stock = Aabb3 { min: Point3::new(0.0, 0.0, -5.0), max: Point3::new(20.0, 10.0, 0.0) };
        let flat = Cutter::new(CutterShape::Flat { radius: 2.0 }, 10.0).unwrap();
        let mut path = Toolpath::new(1000.0);
        path.push(Move::new(MoveKind::Rapid, Point3::new(-3.0, 5.0, 5.0)));
        path.push(Move::new(MoveKind::Plunge, Point3::new(-3.0, 5.0, -1.0)));
        path.push(Move::new(MoveKind::Feed, Point3::new(23.0, 5.0, -1.0)));
        path.push(Move::new(MoveKind::Retract, Point3::new(23.0, 5.0, 5.0)));
        let mut zmap = ZMap::new(stock, 0.25).unwrap();
        zmap.cut(&flat, &path).unwrap();
        let mut dexels = DexelStock::new(stock, 0.25).unwrap();
        dexels.cut(&flat, &crate::ToolMove::from_toolpath(&path), &crate::DexelOptions::default()).unwrap();
        let views: [&dyn StockView; 2] = [&zmap, &dexels];
        for view in views {
            let top = |x, y| view.top(Point2::new(x, y));
            assert!((top(10.1, 5.1).unwrap() + 1.0).abs() < 1e-9, "{:?}", top(10.1, 5.1));
            assert_eq!(top(10.1, 9.1), Some(0.0));
            assert_eq!(top(-1.0, 5.0), None);
            assert_eq!(top(10.1, 10.5), None);
            assert_eq!(view.max_top(), Some(0.0));
            let column = view.column(Point2::new(10.1, 5.1));
            assert_eq!(column.len(), 1);
            assert!((column[0][0] + 5.0).abs() < 1e-9 && (column[0][1] + 1.0).abs() < 1e-9, "{column:?}");
        }
    }
}
