//! A closed non-convex pocket with ribs (a look-alike of the closed pocket of
//! the aeronautical fitting of Jousselin 2020, Ch. 4 section 3, Fig. 4.5a,
//! whose CAD is not public).

use scallop_geom::{Aabb3, Point3};

use crate::{FaceTag, PartError, TestPart, build::Builder, check};

/// Parameters of [`fitting_pocket`] (mm, radians).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FittingParams {
    /// Stock block size (x, y, z); its lower corner is the origin.
    pub stock: [f64; 3],
    /// Height of the (flat) bottom.
    pub bottom_z: f64,
    /// Distance from the stock's sides to the pocket outline at the bottom.
    pub wall: f64,
    /// Rib thickness.
    pub rib: f64,
    /// Share of the pocket's width each rib reaches across (0 to 1).
    pub rib_reach: f64,
    /// Draft of every flank (the outline grows about its centre towards the top).
    pub draft: f64,
    /// Longest edge of an outline (longer edges are split).
    pub step: f64,
    /// Rings along the flanks.
    pub rings: usize,
}

impl Default for FittingParams {
    fn default() -> Self {
        FittingParams {
            stock: [140.0, 100.0, 30.0],
            bottom_z: 5.0,
            wall: 10.0,
            rib: 4.0,
            rib_reach: 0.6,
            draft: 3f64.to_radians(),
            step: 8.0,
            rings: 5,
        }
    }
}

impl FittingParams {
    fn validate(&self) -> Result<(), PartError> {
        for (name, v) in [("stock[0]", self.stock[0]), ("stock[1]", self.stock[1]), ("stock[2]", self.stock[2])] {
            check(name, v, 10.0, 1e4, "a stock size between 10 mm and 10 m")?;
        }
        check("bottom_z", self.bottom_z, 0.5, self.stock[2] - 1.0, "above the floor and 1 mm below the top")?;
        check("wall", self.wall, 1.0, 0.2 * self.stock[0].min(self.stock[1]), "1 mm to a fifth of the stock's width")?;
        check("rib", self.rib, 0.5, 0.1 * self.stock[0], "0.5 mm to a tenth of the stock's length")?;
        check("rib_reach", self.rib_reach, 0.1, 0.9, "0.1 to 0.9")?;
        check("draft", self.draft, 0.0, 0.2, "0 to 0.2 rad")?;
        check("step", self.step, 0.5, 1e4, "at least 0.5 mm")?;
        #[allow(clippy::cast_precision_loss, reason = "small counts")]
        check("rings", self.rings as f64, 1.0, 1000.0, "1 to 1000 rings")?;
        let grow = (self.stock[2] - self.bottom_z) * self.draft.tan();
        check("draft", grow, 0.0, 0.5 * self.wall, "a draft whose opening stays 1/2 wall inside the stock")
    }

    /// The bottom outline, counter-clockwise: the pocket rectangle with a rib
    /// from the -y side at 1/3 of the length and one from the +y side at 2/3.
    fn outline(&self) -> Vec<(f64, f64)> {
        let (x0, x1, y0, y1) = (self.wall, self.stock[0] - self.wall, self.wall, self.stock[1] - self.wall);
        let reach = self.rib_reach * (y1 - y0);
        let (r1, r2, h) = (x0 + (x1 - x0) / 3.0, x0 + 2.0 * (x1 - x0) / 3.0, 0.5 * self.rib);
        let corners = [
            (x0, y0),
            (r1 - h, y0),
            (r1 - h, y0 + reach),
            (r1 + h, y0 + reach),
            (r1 + h, y0),
            (x1, y0),
            (x1, y1),
            (r2 + h, y1),
            (r2 + h, y1 - reach),
            (r2 - h, y1 - reach),
            (r2 - h, y1),
            (x0, y1),
        ];
        let mut pts = Vec::new();
        for (k, &(ax, ay)) in corners.iter().enumerate() {
            let (bx, by) = corners[(k + 1) % corners.len()];
            let len = (bx - ax).hypot(by - ay);
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "validated positive lengths")]
            let n = (len / self.step).ceil().max(1.0) as usize;
            for i in 0..n {
                #[allow(clippy::cast_precision_loss, reason = "small counts")]
                let t = i as f64 / n as f64;
                pts.push((ax + (bx - ax) * t, ay + (by - ay) * t));
            }
        }
        pts
    }
}

/// The fitting pocket: a flat bottom under a non-convex outline with two ribs,
/// flanks lofted to the stock top with a draft (the outline scaled about the
/// pocket's centre so each wall leans by `draft` along the wider axis), caps
/// by ear clipping.
///
/// # Errors
/// [`PartError::BadParameter`] naming the parameter and its range.
pub fn fitting_pocket(params: &FittingParams) -> Result<TestPart, PartError> {
    params.validate()?;
    let (cx, cy) = (0.5 * params.stock[0], 0.5 * params.stock[1]);
    let depth = params.stock[2] - params.bottom_z;
    let half = 0.5 * (params.stock[0] - 2.0 * params.wall);
    let outline = params.outline();
    let mut b = Builder::default();
    let mut rings = Vec::new();
    for k in 0..=params.rings {
        #[allow(clippy::cast_precision_loss, reason = "small counts")]
        let s = k as f64 / params.rings as f64;
        let scale = 1.0 + s * depth * params.draft.tan() / half;
        let z = params.bottom_z + s * depth;
        rings.push(b.ring(outline.iter().map(|&(x, y)| Point3::new(cx + (x - cx) * scale, cy + (y - cy) * scale, z))));
    }
    for w in rings.windows(2) {
        b.band(&w[0], &w[1], true, |_| FaceTag::Flank);
    }
    b.cap(&rings[0], FaceTag::Bottom, -1.0);
    b.cap(&rings[params.rings], FaceTag::Top, 1.0);
    b.finish(Aabb3 { min: Point3::origin(), max: Point3::new(params.stock[0], params.stock[1], params.stock[2]) })
}
