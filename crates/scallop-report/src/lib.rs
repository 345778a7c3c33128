//! Reports people look at: a self-contained HTML page with a WebGL viewer
//! ([`html::report_html`]), a deterministic software render as PNG
//! ([`render::render`]) and a glTF 2.0 binary export ([`glb::scene_glb`]) of
//! the part, the stock and the toolpath.
//!
//! Everything starts from a [`ReportData`]: the commands fill it
//! ([`ReportData::from_finishing`] for `scallop run` and `scallop demo`,
//! [`ReportData::from_job`] for jobs of several operations, the CLI for
//! `scallop simulate`), and each writer turns it into bytes.
//!
//! ```
//! use scallop_geom::Point3;
//! use scallop_mesh::TriMesh;
//! use scallop_report::{ReportData, glb, html, render};
//! let p = |x, y, z| Point3::new(x, y, z);
//! let (mesh, _) = TriMesh::from_soup(&[[p(0., 0., 0.), p(10., 0., 0.), p(0., 10., 2.)]]).unwrap();
//! let mut data = ReportData::new("a triangle");
//! data.part = Some(mesh);
//! let page = html::report_html(&data);
//! assert!(page.starts_with("<!DOCTYPE html>"));
//! let png = render::render(&data, 64, 48).to_png();
//! assert_eq!(&png[1..4], b"PNG");
//! let glb = glb::scene_glb(&data).unwrap();
//! assert_eq!(&glb[..4], b"glTF");
//! ```
//!
//! # Hooks for later commands
//! `scallop optimize` fills [`ReportData::zones`] (a zone per move, the
//! zones' names and times: the viewer colours by zone and the page plots the
//! per-zone times) and [`ReportData::convergence`] (one curve per run of the
//! optimiser, plotted as lines). Both are optional; the page shows what is there.
//!
//! # Invariants
//! - Never touches files, never prints, never reads a clock: every writer
//!   returns a `String` or bytes.
//! - Deterministic: the same data give the same bytes.
//! - Numbers in the page come from the full data; only the 3D display of a
//!   long toolpath is decimated ([`tol::MAX_DISPLAY_VERTICES`]).

mod finishing;
pub mod glb;
pub mod html;
mod job;
pub mod png;
pub mod render;
pub mod svg;
pub use scallop_geom::tol::report as tol;

use scallop_geom::{Aabb3, Point3};
use scallop_mesh::TriMesh;
use scallop_toolpath::{MoveKind, Toolpath};

/// Why a report could not be made. Each message names the place and the fix.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ReportError {
    /// The scene is larger than a glTF buffer can address (4 GiB).
    #[error("the scene needs {bytes} bytes, more than a GLB buffer holds (4 GiB); simplify the toolpath or the mesh")]
    TooLarge {
        /// Bytes needed.
        bytes: u64,
    },
    /// An array of per-move values whose length is not the number of moves.
    #[error("`{field}` has {len} values for {moves} moves; give one value per move")]
    PerMoveLength {
        /// The field of [`ReportData`].
        field: &'static str,
        /// Its length.
        len: usize,
        /// The number of moves.
        moves: usize,
    },
}

/// One line of the key figures or settings table.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// What it is ("machining time, look-ahead").
    pub label: String,
    /// The value.
    pub value: FigureValue,
}

/// The value of a [`Figure`].
#[derive(Debug, Clone, PartialEq)]
pub enum FigureValue {
    /// A number shown with `decimals` decimals and a unit; the page keeps the
    /// full value in a `data-value` attribute.
    Number {
        /// The value.
        value: f64,
        /// Decimals shown.
        decimals: usize,
        /// Unit ("s", "mm", "" for counts).
        unit: String,
    },
    /// Text as it is.
    Text(String),
}

impl Figure {
    /// A number.
    #[must_use]
    pub fn number(label: &str, value: f64, decimals: usize, unit: &str) -> Figure {
        Figure { label: label.into(), value: FigureValue::Number { value, decimals, unit: unit.into() } }
    }

    /// A count.
    #[must_use]
    #[allow(clippy::cast_precision_loss, reason = "counts far below 2^52")]
    pub fn count(label: &str, value: usize) -> Figure {
        Figure::number(label, value as f64, 0, "")
    }

    /// Text.
    #[must_use]
    pub fn text(label: &str, text: impl Into<String>) -> Figure {
        Figure { label: label.into(), value: FigureValue::Text(text.into()) }
    }

    /// The value as shown in the page.
    #[must_use]
    pub fn shown(&self) -> String {
        match &self.value {
            FigureValue::Number { value, decimals, unit } => {
                let v = format!("{:.*}", *decimals, value + 0.0);
                if unit.is_empty() { v } else { format!("{v} {unit}") }
            }
            FigureValue::Text(t) => t.clone(),
        }
    }
}

/// Feeds and times per move (one entry per move of the toolpath; the first
/// move has no start and gets zeros).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PathTiming {
    /// Name of the time model ("look-ahead (b)").
    pub model: String,
    /// Duration of each move (s).
    pub durations: Vec<f64>,
    /// Commanded feed of each move (mm/min).
    pub commanded: Vec<f64>,
    /// Highest feed reached on each move in the model (mm/min).
    pub achieved: Vec<f64>,
}

/// Zones of a toolpath (filled by `scallop optimize`, and by jobs of several
/// operations with an operation per zone): a zone per move, the zones' names
/// and machining times.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Zones {
    /// What a zone is, for legends and titles ("zone", "operation").
    pub label: String,
    /// Zone index of each move (into `names`).
    pub of_move: Vec<u16>,
    /// Name of each zone.
    pub names: Vec<String>,
    /// Machining time of each zone (s).
    pub times_s: Vec<f64>,
}

/// One curve of a line plot (e.g. the best objective against evaluations).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Curve {
    /// Legend.
    pub name: String,
    /// Points (x, y).
    pub points: Vec<[f64; 2]>,
}

/// A convergence plot (filled by `scallop optimize`).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Convergence {
    /// Title of the plot.
    pub title: String,
    /// Label of the x axis.
    pub x_label: String,
    /// Label of the y axis.
    pub y_label: String,
    /// The curves.
    pub curves: Vec<Curve>,
}

/// A histogram over equal bins starting at 0.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Histogram {
    /// Title.
    pub title: String,
    /// Width of a bin (in `unit`).
    pub bin_width: f64,
    /// Counts per bin; when `last_is_overflow` the last bin counts everything above.
    pub counts: Vec<usize>,
    /// Whether the last bin counts the values above the range.
    pub last_is_overflow: bool,
    /// Unit of the values ("mm").
    pub unit: String,
}

/// A height map of `stock - part` (mm) on a regular grid (the simulated stock).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct DeviationMap {
    /// Centre of cell (0, 0) (mm).
    pub origin: [f64; 2],
    /// Cell size in x and y (mm).
    pub cell: [f64; 2],
    /// Cells in x.
    pub nx: usize,
    /// Cells in y.
    pub ny: usize,
    /// Row-major (x fastest) deviation, NaN where no part lies under the cell.
    pub values: Vec<f64>,
    /// Gouge tolerance (mm): below minus this a cell is a gouge.
    pub gouge_tolerance: f64,
}

impl DeviationMap {
    /// The deviation of the cell containing (x, y), if any part lies there.
    #[must_use]
    pub fn at(&self, x: f64, y: f64) -> Option<f64> {
        let fx = ((x - self.origin[0]) / self.cell[0]).round();
        let fy = ((y - self.origin[1]) / self.cell[1]).round();
        #[allow(clippy::cast_precision_loss, reason = "grid sizes far below 2^52")]
        let inside = fx >= 0.0 && fy >= 0.0 && fx < self.nx as f64 && fy < self.ny as f64;
        if !inside {
            return None;
        }
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "checked in range above")]
        let (i, j) = (fx as usize, fy as usize);
        self.values.get(j * self.nx + i).copied().filter(|v| v.is_finite())
    }

    /// The map with at most `max_cells` cells: square blocks of `k x k`
    /// cells (the smallest `k` that fits) become one cell centred on the
    /// block, holding the deepest value of the block when it is a gouge
    /// (below `-gouge_tolerance`), else the most material left; NaN only
    /// where no cell of the block lies over the part. Gouges and the largest
    /// material left thus survive the reduction.
    #[must_use]
    pub fn reduced(&self, max_cells: usize) -> DeviationMap {
        let mut k = 1usize;
        while self.nx.div_ceil(k) * self.ny.div_ceil(k) > max_cells.max(1) && k < self.nx.max(self.ny) {
            k += 1;
        }
        if k == 1 {
            return self.clone();
        }
        let (nx, ny) = (self.nx.div_ceil(k), self.ny.div_ceil(k));
        let mut values = vec![f64::NAN; nx * ny];
        for (j, row) in self.values.chunks(self.nx).enumerate() {
            for (i, &v) in row.iter().enumerate().filter(|(_, v)| v.is_finite()) {
                let out = &mut values[(j / k) * nx + i / k];
                let gouge = |x: f64| x < -self.gouge_tolerance;
                *out = if out.is_nan() {
                    v
                } else if gouge(v) || gouge(*out) {
                    out.min(v)
                } else {
                    out.max(v)
                };
            }
        }
        #[allow(clippy::cast_precision_loss, reason = "block sizes far below 2^52")]
        let half = 0.5 * (k - 1) as f64;
        #[allow(clippy::cast_precision_loss, reason = "block sizes far below 2^52")]
        let kf = k as f64;
        DeviationMap {
            origin: [self.origin[0] + half * self.cell[0], self.origin[1] + half * self.cell[1]],
            cell: [kf * self.cell[0], kf * self.cell[1]],
            nx,
            ny,
            values,
            gouge_tolerance: self.gouge_tolerance,
        }
    }
}

/// Everything a report shows. Each part is optional: a writer shows what is there.
#[derive(Debug, Clone, Default)]
pub struct ReportData {
    /// Title of the page ("finishing the built-in choi surface").
    pub title: String,
    /// The command that made it ("scallop run job.toml").
    pub command: String,
    /// The part as a mesh (the tessellation for surfaces).
    pub part: Option<TriMesh>,
    /// The stock box.
    pub stock: Option<Aabb3>,
    /// The toolpath.
    pub toolpath: Option<Toolpath>,
    /// Rapid rate for the nominal timing when `timing` is absent (mm/min).
    pub rapid_rate: f64,
    /// Feeds and times per move from a time model.
    pub timing: Option<PathTiming>,
    /// Zones (filled by `scallop optimize`).
    pub zones: Option<Zones>,
    /// Simulated deviation of the stock from the part.
    pub deviation: Option<DeviationMap>,
    /// Key figures (times, lengths, passes, scallop, gouges, collisions).
    pub figures: Vec<Figure>,
    /// The job's settings.
    pub settings: Vec<Figure>,
    /// The verified scallop heights.
    pub histogram: Option<Histogram>,
    /// Convergence plots (filled by `scallop optimize`).
    pub convergence: Vec<Convergence>,
    /// The simulated engagement of each move over its operation's target
    /// (`None` for a move not measured: rapids, finishing operations); the
    /// toolpath's "engagement" colouring.
    pub engagement: Option<Vec<Option<f64>>>,
}

impl ReportData {
    /// An empty report with a title.
    #[must_use]
    pub fn new(title: &str) -> ReportData {
        ReportData { title: title.into(), rapid_rate: tol::NOMINAL_RAPID_RATE, ..ReportData::default() }
    }

    /// The box around the part, the stock and the toolpath (`None` when empty).
    #[must_use]
    pub fn bounds(&self) -> Option<Aabb3> {
        let mut points: Vec<Point3> = Vec::new();
        if let Some(m) = &self.part {
            let b = m.bounds();
            points.extend([b.min, b.max]);
        }
        if let Some(s) = &self.stock {
            points.extend([s.min, s.max]);
        }
        if let Some(t) = &self.toolpath {
            points.extend(t.moves().iter().map(|m| m.to));
        }
        Aabb3::from_points(points)
    }

    /// Checks that per-move arrays have one value per move.
    ///
    /// # Errors
    /// [`ReportError::PerMoveLength`] naming the array.
    pub fn check(&self) -> Result<(), ReportError> {
        let moves = self.toolpath.as_ref().map_or(0, |t| t.moves().len());
        let mut arrays: Vec<(&'static str, usize)> = Vec::new();
        if let Some(t) = &self.timing {
            arrays.extend([
                ("timing.durations", t.durations.len()),
                ("timing.commanded", t.commanded.len()),
                ("timing.achieved", t.achieved.len()),
            ]);
        }
        if let Some(z) = &self.zones {
            arrays.push(("zones.of_move", z.of_move.len()));
        }
        match arrays.into_iter().find(|(_, len)| *len != moves) {
            Some((field, len)) => Err(ReportError::PerMoveLength { field, len, moves }),
            None => Ok(()),
        }
    }

    /// Duration of each move (s): from `timing` when given, else the nominal
    /// time at the commanded feeds (rapids at `rapid_rate`).
    #[must_use]
    pub fn move_durations(&self) -> Vec<f64> {
        let Some(path) = &self.toolpath else { return Vec::new() };
        if let Some(t) = self.timing.as_ref().filter(|t| t.durations.len() == path.moves().len()) {
            return t.durations.clone();
        }
        let moves = path.moves();
        let mut out = vec![0.0; moves.len()];
        for (k, w) in moves.windows(2).enumerate() {
            let feed = commanded_feed(path, w[1].kind, self.rapid_rate);
            if feed > 0.0 {
                out[k + 1] = (w[1].to - w[0].to).norm() / (feed / 60.0);
            }
        }
        out
    }
}

/// The commanded feed of a move of `kind` (mm/min).
#[must_use]
pub fn commanded_feed(path: &Toolpath, kind: MoveKind, rapid_rate: f64) -> f64 {
    match kind {
        MoveKind::Feed | MoveKind::Link => path.feed,
        MoveKind::Plunge => path.plunge_feed,
        MoveKind::Rapid | MoveKind::Retract => rapid_rate,
    }
}

/// Index of a move kind in the viewer's legend (rapid, plunge, feed, link, retract).
#[must_use]
pub fn kind_index(kind: MoveKind) -> u8 {
    match kind {
        MoveKind::Rapid => 0,
        MoveKind::Plunge => 1,
        MoveKind::Feed => 2,
        MoveKind::Link => 3,
        MoveKind::Retract => 4,
    }
}

/// Colours of the move kinds, in [`kind_index`] order (sRGB).
pub const KIND_COLOURS: [[u8; 3]; 5] = [[220, 40, 40], [240, 150, 20], [30, 90, 200], [20, 160, 80], [200, 60, 200]];

/// Names of the move kinds, in [`kind_index`] order.
pub const KIND_NAMES: [&str; 5] = ["rapid", "plunge", "feed", "link", "retract"];
