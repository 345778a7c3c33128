//! The closed test pocket with drafts and undercuts (a look-alike of the
//! pocket of Jousselin 2020, Ch. 2 section 4, Fig. 2.40, whose CAD is not public).

use std::f64::consts::{FRAC_PI_2, PI};

use scallop_geom::{Aabb3, Point3, Vec3};

use crate::{FaceTag, PartError, TestPart, build::Builder, check};

/// Parameters of [`closed_pocket`] (mm, radians).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PocketParams {
    /// Stock block size (x, y, z); the stock's lower corner is the origin.
    pub stock: [f64; 3],
    /// Height of the bottom at the pocket centre.
    pub bottom_z: f64,
    /// Distance from the stock's sides to the pocket's bottom outline.
    pub wall: f64,
    /// Corner radius of the bottom outline.
    pub corner_radius: f64,
    /// Wall angles from the vertical on the sides +x, -x, +y, -y: positive opens
    /// the pocket upwards (draft), negative closes it (undercut).
    pub walls: [f64; 4],
    /// Slope of the bottom along x (a tilted bottom).
    pub tilt: f64,
    /// Height of the dome on the bottom.
    pub dome: f64,
    /// Ring count along the flanks (height).
    pub rings: usize,
    /// Points per straight side and per corner arc of an outline.
    pub side_points: usize,
    /// Points per corner arc.
    pub corner_points: usize,
}

impl Default for PocketParams {
    fn default() -> Self {
        PocketParams {
            stock: [100.0, 100.0, 35.0],
            bottom_z: 10.0,
            wall: 12.0,
            corner_radius: 8.0,
            walls: [(-10f64).to_radians(), 8f64.to_radians(), 5f64.to_radians(), (-12f64).to_radians()],
            tilt: 0.05,
            dome: 2.0,
            rings: 10,
            side_points: 8,
            corner_points: 6,
        }
    }
}

impl PocketParams {
    fn validate(&self) -> Result<(), PartError> {
        for (name, v) in [("stock[0]", self.stock[0]), ("stock[1]", self.stock[1]), ("stock[2]", self.stock[2])] {
            check(name, v, 1.0, 1e4, "a stock size between 1 mm and 10 m")?;
        }
        check(
            "bottom_z",
            self.bottom_z,
            0.5,
            self.stock[2] - 1.0,
            "above the stock floor and at least 1 mm below its top",
        )?;
        let half = 0.5 * self.stock[0].min(self.stock[1]);
        check("wall", self.wall, 0.5, half - 1.0, "positive and leaving an opening")?;
        check(
            "corner_radius",
            self.corner_radius,
            0.1,
            half - self.wall - 0.5,
            "positive and below the opening's half-width",
        )?;
        for (k, &a) in self.walls.iter().enumerate() {
            let name = ["walls[0]", "walls[1]", "walls[2]", "walls[3]"][k];
            check(name, a, -0.5, 0.5, "a wall angle within +-0.5 rad of the vertical")?;
            let shift = (self.stock[2] - self.bottom_z) * a.tan();
            check(
                name,
                shift,
                -(half - self.wall - self.corner_radius),
                self.wall - 0.5,
                "a wall that stays inside the stock",
            )?;
        }
        check("tilt", self.tilt, -0.2, 0.2, "a bottom slope within +-0.2")?;
        check("dome", self.dome, -5.0, 5.0, "a dome within +-5 mm")?;
        for (name, n, lo) in
            [("rings", self.rings, 1), ("side_points", self.side_points, 1), ("corner_points", self.corner_points, 1)]
        {
            #[allow(clippy::cast_precision_loss, reason = "small counts")]
            check(name, n as f64, lo as f64, 1000.0, "a count between 1 and 1000")?;
        }
        Ok(())
    }

    fn bottom(&self, x: f64, y: f64) -> f64 {
        let (cx, cy) = (0.5 * self.stock[0], 0.5 * self.stock[1]);
        let (u, v) = ((x - cx) / self.stock[0], (y - cy) / self.stock[1]);
        self.bottom_z + self.tilt * (x - cx) + self.dome * (PI * u).cos() * (PI * v).cos()
    }

    /// The outline at height fraction `s` (0 bottom, 1 top), counter-clockwise
    /// from the middle of the -y side, as XY points.
    fn outline(&self, s: f64) -> Vec<(f64, f64)> {
        let depth = self.stock[2] - self.bottom_z;
        let shift = self.walls.map(|a| s * depth * a.tan());
        let (x0, x1) = (self.wall - shift[1], self.stock[0] - self.wall + shift[0]);
        let (y0, y1) = (self.wall - shift[3], self.stock[1] - self.wall + shift[2]);
        let r = self.corner_radius;
        // Corners: centre and start angle, counter-clockwise.
        let corners =
            [(x1 - r, y0 + r, -FRAC_PI_2), (x1 - r, y1 - r, 0.0), (x0 + r, y1 - r, FRAC_PI_2), (x0 + r, y0 + r, PI)];
        let mut pts = Vec::new();
        for (k, &(cx, cy, a0)) in corners.iter().enumerate() {
            let (px, py) = (cx + r * a0.cos(), cy + r * a0.sin());
            // The straight side that ends at this corner, from the previous corner's end.
            let (qx, qy) = {
                let (pcx, pcy, pa) = corners[(k + 3) % 4];
                (pcx + r * (pa + FRAC_PI_2).cos(), pcy + r * (pa + FRAC_PI_2).sin())
            };
            #[allow(clippy::cast_precision_loss, reason = "small counts")]
            let n = self.side_points as f64;
            for i in 0..self.side_points {
                #[allow(clippy::cast_precision_loss, reason = "small counts")]
                let t = i as f64 / n;
                pts.push((qx + (px - qx) * t, qy + (py - qy) * t));
            }
            for i in 0..self.corner_points {
                #[allow(clippy::cast_precision_loss, reason = "small counts")]
                let a = a0 + FRAC_PI_2 * i as f64 / self.corner_points as f64;
                pts.push((cx + r * a.cos(), cy + r * a.sin()));
            }
        }
        pts
    }
}

/// The closed pocket: flanks lofted through `rings + 1` outlines from the
/// bottom (a tilted dome) to the stock top, each side leaning by its wall
/// angle; the bottom capped by concentric rings, the top by a fan. The stock
/// is the block `[0, stock]`.
///
/// # Errors
/// [`PartError::BadParameter`] naming the parameter and its range.
pub fn closed_pocket(params: &PocketParams) -> Result<TestPart, PartError> {
    params.validate()?;
    let mut b = Builder::default();
    let top = params.stock[2];
    let mut rings = Vec::new();
    for k in 0..=params.rings {
        #[allow(clippy::cast_precision_loss, reason = "small counts")]
        let s = k as f64 / params.rings as f64;
        let ring =
            params.outline(s).into_iter().map(|(x, y)| Point3::new(x, y, params.bottom(x, y) * (1.0 - s) + top * s));
        rings.push(b.ring(ring));
    }
    for w in rings.windows(2) {
        b.band(&w[0], &w[1], true, |_| FaceTag::Flank);
    }
    let (cx, cy) = (0.5 * params.stock[0], 0.5 * params.stock[1]);
    let down = Vec3::new(0.0, 0.0, -1.0);
    let base: Vec<Point3> = rings[0].iter().map(|&i| b.vertices[i]).collect();
    let mut outer = rings[0].clone();
    for f in [0.75, 0.5, 0.25] {
        let inner = base.iter().map(|p| {
            let (x, y) = (cx + (p.x - cx) * f, cy + (p.y - cy) * f);
            Point3::new(x, y, params.bottom(x, y))
        });
        let inner = b.ring(inner);
        b.band_towards(&outer, &inner, FaceTag::Bottom, |_| down);
        outer = inner;
    }
    b.fan(Point3::new(cx, cy, params.bottom(cx, cy)), &outer, FaceTag::Bottom, &down);
    let lid = rings[params.rings].clone();
    b.fan(Point3::new(cx, cy, top), &lid, FaceTag::Top, &Vec3::z());
    b.finish(Aabb3 { min: Point3::origin(), max: Point3::new(params.stock[0], params.stock[1], params.stock[2]) })
}
