//! A small deterministic software rasteriser: the part shaded (z-buffer,
//! flat Lambert shading, two-sided), the stock's edges and the toolpath drawn
//! on top, seen by a fixed isometric orthographic camera fitted to the
//! bounds. Pure f64 arithmetic in a fixed order, no threads: the same data
//! give the same bytes.
//!
//! ```
//! use scallop_report::{ReportData, render};
//! let empty = render::render(&ReportData::new("nothing"), 8, 8);
//! assert!(empty.pixels.chunks(3).all(|p| p == render::BACKGROUND));
//! ```

use scallop_geom::{Aabb3, Point3, Vec3};

use crate::png::Image;
use crate::{KIND_COLOURS, ReportData, kind_index, tol};

/// Background colour.
pub const BACKGROUND: [u8; 3] = [255, 255, 255];
/// Base colour of the part before shading.
pub const PART_COLOUR: [f64; 3] = [170.0, 185.0, 205.0];
/// Colour of the stock's edges.
pub const STOCK_COLOUR: [u8; 3] = [150, 150, 150];

/// The fixed camera: looks along `-(1, -1, 1)` (from the front right, above),
/// Z up on the screen, orthographic, scaled so that the bounds fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    right: Vec3,
    up: Vec3,
    forward: Vec3,
    centre: [f64; 2],
    scale: f64,
    size: [f64; 2],
}

impl Camera {
    /// The isometric camera for an image of `width` x `height` pixels fitted
    /// to `bounds` (all eight corners inside, with [`tol::RENDER_MARGIN`]).
    #[must_use]
    #[allow(clippy::cast_precision_loss, reason = "image sides far below 2^52")]
    pub fn isometric(bounds: &Aabb3, width: usize, height: usize) -> Camera {
        let forward = Vec3::new(-1.0, 1.0, -1.0).normalize();
        let right = forward.cross(&Vec3::z()).normalize();
        let up = right.cross(&forward);
        let mut cam =
            Camera { right, up, forward, centre: [0.0, 0.0], scale: 1.0, size: [width as f64, height as f64] };
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for k in 0..8 {
            let p = Point3::new(
                if k & 1 == 0 { bounds.min.x } else { bounds.max.x },
                if k & 2 == 0 { bounds.min.y } else { bounds.max.y },
                if k & 4 == 0 { bounds.min.z } else { bounds.max.z },
            );
            let s = [p.coords.dot(&right), p.coords.dot(&up)];
            for a in 0..2 {
                lo[a] = lo[a].min(s[a]);
                hi[a] = hi[a].max(s[a]);
            }
        }
        cam.centre = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])];
        let usable = 1.0 - 2.0 * tol::RENDER_MARGIN;
        let span = [(hi[0] - lo[0]).max(f64::MIN_POSITIVE), (hi[1] - lo[1]).max(f64::MIN_POSITIVE)];
        cam.scale = (usable * cam.size[0] / span[0]).min(usable * cam.size[1] / span[1]);
        if !cam.scale.is_finite() || cam.scale <= 0.0 {
            cam.scale = 1.0;
        }
        cam
    }

    /// Pixel coordinates (x right, y down; pixel centres at `k + 0.5`) and
    /// depth (larger is farther) of a point.
    #[must_use]
    pub fn project(&self, p: &Point3) -> [f64; 3] {
        let x = (p.coords.dot(&self.right) - self.centre[0]) * self.scale + 0.5 * self.size[0];
        let y = 0.5 * self.size[1] - (p.coords.dot(&self.up) - self.centre[1]) * self.scale;
        [x, y, p.coords.dot(&self.forward)]
    }

    /// Pixels per millimetre.
    #[must_use]
    pub fn pixels_per_mm(&self) -> f64 {
        self.scale
    }

    /// The direction the camera looks along.
    #[must_use]
    pub fn forward(&self) -> Vec3 {
        self.forward
    }
}

/// Renders the part, the stock's edges and the toolpath (coloured by move
/// kind, on top) into a `width` x `height` RGB image.
#[must_use]
pub fn render(data: &ReportData, width: usize, height: usize) -> Image {
    let mut img = Image::new(width, height, BACKGROUND);
    let Some(bounds) = data.bounds() else { return img };
    if width == 0 || height == 0 {
        return img;
    }
    let cam = Camera::isometric(&bounds, width, height);
    if let Some(mesh) = &data.part {
        let mut depth = vec![f64::INFINITY; width * height];
        // Light from the viewer's upper left, fixed in the camera frame.
        let light = (-cam.forward + 0.5 * cam.up - 0.3 * cam.right).normalize();
        for tri in mesh.triangles() {
            let v = tri.map(|i| mesh.vertices()[i as usize]);
            let n = (v[1] - v[0]).cross(&(v[2] - v[0]));
            let len = n.norm();
            if len <= 0.0 {
                continue;
            }
            let shade = tol::AMBIENT + (1.0 - tol::AMBIENT) * (n.dot(&light) / len).abs();
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "clamped to 0..=255")]
            let rgb = PART_COLOUR.map(|c| (c * shade).round().clamp(0.0, 255.0) as u8);
            fill_triangle(&mut img, &mut depth, v.map(|p| cam.project(&p)), rgb);
        }
    }
    if let Some(stock) = &data.stock {
        let corner = |k: usize| {
            Point3::new(
                if k & 1 == 0 { stock.min.x } else { stock.max.x },
                if k & 2 == 0 { stock.min.y } else { stock.max.y },
                if k & 4 == 0 { stock.min.z } else { stock.max.z },
            )
        };
        for a in 0..8usize {
            for bit in [1usize, 2, 4] {
                if a & bit == 0 {
                    line(&mut img, cam.project(&corner(a)), cam.project(&corner(a | bit)), STOCK_COLOUR);
                }
            }
        }
    }
    if let Some(path) = &data.toolpath {
        for w in path.moves().windows(2) {
            let rgb = KIND_COLOURS[usize::from(kind_index(w[1].kind))];
            line(&mut img, cam.project(&w[0].to), cam.project(&w[1].to), rgb);
        }
    }
    img
}

/// Fills a projected triangle with depth test; pixel centres inside or on an edge are covered.
#[allow(
    clippy::cast_possible_truncation,
    clippy::cast_sign_loss,
    clippy::cast_precision_loss,
    reason = "pixel ranges clamped to the image"
)]
fn fill_triangle(img: &mut Image, depth: &mut [f64], p: [[f64; 3]; 3], rgb: [u8; 3]) {
    let area = (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]);
    if !(area.is_finite() && area != 0.0) {
        return;
    }
    let (w, h) = (img.width as f64, img.height as f64);
    let x0 = p.iter().map(|q| q[0]).fold(f64::INFINITY, f64::min).floor().clamp(0.0, w);
    let x1 = p.iter().map(|q| q[0]).fold(f64::NEG_INFINITY, f64::max).ceil().clamp(0.0, w);
    let y0 = p.iter().map(|q| q[1]).fold(f64::INFINITY, f64::min).floor().clamp(0.0, h);
    let y1 = p.iter().map(|q| q[1]).fold(f64::NEG_INFINITY, f64::max).ceil().clamp(0.0, h);
    let edge = |a: &[f64; 3], b: &[f64; 3], x: f64, y: f64| (b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0]);
    for py in y0 as usize..y1 as usize {
        let y = py as f64 + 0.5;
        for px in x0 as usize..x1 as usize {
            let x = px as f64 + 0.5;
            let l0 = edge(&p[1], &p[2], x, y) / area;
            let l1 = edge(&p[2], &p[0], x, y) / area;
            let l2 = edge(&p[0], &p[1], x, y) / area;
            if l0 < 0.0 || l1 < 0.0 || l2 < 0.0 {
                continue;
            }
            let z = l0 * p[0][2] + l1 * p[1][2] + l2 * p[2][2];
            let k = py * img.width + px;
            if z < depth[k] {
                depth[k] = z;
                img.set(px, py, rgb);
            }
        }
    }
}

/// Draws a one-pixel line between two projected points (no depth test: on top).
#[allow(
    clippy::cast_possible_truncation,
    clippy::cast_sign_loss,
    clippy::cast_precision_loss,
    reason = "steps bounded by the image diagonal; pixels checked against the image"
)]
fn line(img: &mut Image, a: [f64; 3], b: [f64; 3], rgb: [u8; 3]) {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    if !(dx.is_finite() && dy.is_finite()) {
        return;
    }
    let limit = 4.0 * (img.width + img.height) as f64;
    let steps = dx.abs().max(dy.abs()).ceil().min(limit).max(1.0) as usize;
    for s in 0..=steps {
        let t = s as f64 / steps as f64;
        let (x, y) = ((a[0] + dx * t).floor(), (a[1] + dy * t).floor());
        if x >= 0.0 && y >= 0.0 {
            img.set(x as usize, y as usize, rgb);
        }
    }
}
