//! The proof of a roughing program and its metrics (module L; spec 10.1):
//! the program cut on a tri-dexel stock of the block ([`DexelStock`], the
//! shank and holder checked against the in-process stock, rapids into stock
//! and collisions as errors), then along every Z ray of the stock, against
//! the volume to remove (a closed mesh):
//!
//! - V_r: the stock left inside the volume to remove, in % of its volume;
//! - the stock removed outside it (a gouge of the finished part, beyond the
//!   rounding of the rays), its volume and its longest piece along a ray;
//! - the removal rate (removed volume over the time given);
//! - L_HM: the share of the cutting path length (feeds, links and plunges,
//!   at the cutting feed or at the air feed of [`crate::air_moves`]) that
//!   removed nothing, and the share of it written at the air feed (checked as
//!   rapids, so they removed nothing);
//! - the minimum collision-free stick-out (L_outil): the shortest length of
//!   the tool out of its holder at which neither the shank nor the holder
//!   meets the in-process stock along the whole program, found during the
//!   same cut ([`scallop_sim::StickOut`]).

use rayon::prelude::*;
use scallop_cutter::Cutter;
use scallop_geom::Aabb3;
use scallop_mesh::TriMesh;
use scallop_sim::{DexelOptions, DexelPart, DexelStock, ToolMove};
use scallop_toolpath::{MoveKind, Toolpath};

use crate::Rough5Error;
use crate::faces::{FaceMetrics, ProofFace, face_metrics};

/// The metrics of a proven program.
#[derive(Debug, Clone, PartialEq)]
pub struct Proof {
    /// Volume to remove, measured on the rays (mm^3).
    pub volume_to_remove: f64,
    /// Stock left inside the volume to remove (mm^3).
    pub remaining_volume: f64,
    /// V_r: `remaining_volume` in % of `volume_to_remove`.
    pub remaining_percent: f64,
    /// Stock removed (mm^3).
    pub removed_volume: f64,
    /// Stock removed outside the volume to remove (mm^3).
    pub gouge_volume: f64,
    /// Longest piece removed outside it along one Z ray (mm).
    pub gouge_depth: f64,
    /// Where that piece is: its ray's x, y and the middle height of the
    /// piece of the ray outside the volume to remove that holds it (mm).
    pub gouge_at: Option<[f64; 3]>,
    /// Total length of the cutting moves (feeds, links, plunges), mm, the
    /// air moves ([`crate::is_air_move`]) included.
    pub cutting_length: f64,
    /// L_HM: % of the cutting length that removed nothing (the air moves
    /// included).
    pub air_percent: f64,
    /// Length of the air moves (feeds, links and plunges programmed faster
    /// than the cutting feed, [`crate::is_air_move`]), mm; each is checked as
    /// a rapid (an error if it removes material).
    pub air_move_length: f64,
    /// Fixed-axis sweeps the simulation cut.
    pub sweeps: usize,
    /// Rays per family of the stock.
    pub rays: [usize; 3],
    /// The minimum collision-free stick-out (mm; spec 10.1, L_outil): the
    /// shortest length out of the holder, the tool otherwise the same, at
    /// which the proof's shank and holder check passes, within
    /// [`scallop_sim::tol::STICK_OUT_TOL`] (the flute length when nothing
    /// above the flutes meets the stock).
    pub min_stick_out: f64,
    /// The move (index in the program) that asks for it, and the middle of
    /// the stock piece its shank or holder meets when a little shorter;
    /// `None` when the flutes alone suffice.
    pub min_stick_out_at: Option<(usize, [f64; 3])>,
    /// The metrics of the finished faces asked for ([`prove_with_faces`]).
    pub faces: Vec<FaceMetrics>,
}

impl Proof {
    /// Removal rate (mm^3/s) over `seconds`.
    #[must_use]
    pub fn removal_rate(&self, seconds: f64) -> f64 {
        if seconds > 0.0 { self.removed_volume / seconds } else { 0.0 }
    }
}

/// Settings of [`prove`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProofSettings {
    /// Spacing of the tri-dexel rays (mm).
    pub resolution: f64,
    /// Largest distance between the simulated and the true swept solid of a
    /// 5-axis move (mm; [`DexelOptions::axis_tolerance`]).
    pub axis_tolerance: f64,
}

/// Length of the interval pieces of `a` inside `b` (both sorted, disjoint).
fn overlap(a: &[[f64; 2]], b: &[[f64; 2]]) -> f64 {
    let mut total = 0.0;
    for x in a {
        for y in b {
            total += (x[1].min(y[1]) - x[0].max(y[0])).max(0.0);
        }
    }
    total
}

/// The pieces of `a` inside `b` (both sorted, disjoint), sorted.
fn intersection(a: &[[f64; 2]], b: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let mut out = Vec::new();
    for x in a {
        for y in b {
            let (s, e) = (x[0].max(y[0]), x[1].min(y[1]));
            if e > s {
                out.push([s, e]);
            }
        }
    }
    out
}

/// `[lo, hi]` minus the sorted disjoint `a`.
fn complement(a: &[[f64; 2]], lo: f64, hi: f64) -> Vec<[f64; 2]> {
    let mut out = Vec::new();
    let mut from = lo;
    for x in a {
        if x[0] > from {
            out.push([from, x[0].min(hi)]);
        }
        from = from.max(x[1]);
    }
    if hi > from {
        out.push([from, hi]);
    }
    out
}

/// Cuts `path` with `cutter` on a tri-dexel stock of `stock` (`settings`)
/// and measures it against `volume` (the volume to remove, closed, outward
/// normals). `progress(done, total)` as [`DexelStock::cut_with_progress`].
///
/// # Errors
/// [`Rough5Error::Simulation`] for a refused stock, a rapid into the stock
/// (an air move, [`crate::is_air_move`], that removes material counts as
/// one) or a shank or holder collision.
pub fn prove(
    path: &Toolpath,
    cutter: &Cutter,
    stock: &Aabb3,
    volume: &TriMesh,
    settings: &ProofSettings,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Proof, Rough5Error> {
    prove_from_blank(path, cutter, stock, None, volume, settings, progress)
}

/// As [`prove`], the stock being the closed `blank` inside the box `stock`
/// when one is given ([`DexelStock::from_solid`]: a turned blank), the whole
/// box otherwise; material removed outside the blank is no gouge (there was
/// none).
///
/// # Errors
/// As [`prove`]; an open blank is a refused stock.
pub fn prove_from_blank(
    path: &Toolpath,
    cutter: &Cutter,
    stock: &Aabb3,
    blank: Option<&TriMesh>,
    volume: &TriMesh,
    settings: &ProofSettings,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Proof, Rough5Error> {
    prove_with_faces(path, cutter, (stock, blank), volume, &[], settings, progress)
}

/// As [`prove_from_blank`] (the stock box and the blank as a pair), with the
/// metrics of the finished `faces` measured on the stock left
/// ([`face_metrics`](crate::face_metrics): the deviation from the allowance
/// and the crest heights; spec 10.1).
///
/// # Errors
/// As [`prove`]; an open blank is a refused stock.
pub fn prove_with_faces(
    path: &Toolpath,
    cutter: &Cutter,
    (stock, blank): (&Aabb3, Option<&TriMesh>),
    volume: &TriMesh,
    faces: &[ProofFace<'_>],
    settings: &ProofSettings,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Proof, Rough5Error> {
    let sim = |e: scallop_sim::SimError| Rough5Error::Simulation(e.to_string());
    let blank = blank.map(DexelPart::new);
    let mut dexels = match &blank {
        Some(b) => DexelStock::from_solid(*stock, settings.resolution, b),
        None => DexelStock::new(*stock, settings.resolution),
    }
    .map_err(sim)?;
    // An air move is checked as a rapid: material it removes is an error.
    let moves: Vec<ToolMove> = ToolMove::from_toolpath(path)
        .into_iter()
        .enumerate()
        .map(|(i, m)| if crate::is_air_move(path, i) { ToolMove { kind: MoveKind::Rapid, ..m } } else { m })
        .collect();
    // The search up to the tool's own stick-out: the proof passes only if that one is free.
    let options = DexelOptions {
        axis_tolerance: settings.axis_tolerance,
        check_collisions: true,
        max_stick_out: Some(cutter.flute_length() + cutter.shank_length()),
    };
    let report = dexels.cut_with_progress(cutter, &moves, &options, progress).map_err(sim)?;
    report.check().map_err(sim)?;
    let part = DexelPart::new(volume);
    let (nu, nv) = dexels.grid(2);
    let cell = dexels.cell_size();
    let area = cell[0] * cell[1];
    let eps = dexels.eps();
    let (lo, hi) = (stock.min.z, stock.max.z);
    // Per row of rays: (volume to remove, left in it, removed outside, deepest, its x, y, z).
    let rows: Vec<[f64; 7]> = (0..nv)
        .into_par_iter()
        .map(|iv| {
            let mut acc = [0.0; 7];
            for iu in 0..nu {
                let o = dexels.ray_origin(2, iu, iv);
                let pocket: Vec<[f64; 2]> =
                    part.intervals(&o, 2).iter().map(|s| [s.0.max(lo), s.1.min(hi)]).filter(|s| s[1] > s[0]).collect();
                let material = dexels.intervals(2, iu, iv);
                let mut removed = complement(&material, lo, hi);
                if let Some(b) = &blank {
                    let start: Vec<[f64; 2]> = b.intervals(&o, 2).iter().map(|s| [s.0, s.1]).collect();
                    removed = intersection(&removed, &start);
                }
                acc[0] += pocket.iter().map(|s| s[1] - s[0]).sum::<f64>();
                acc[1] += overlap(&material, &pocket);
                for piece in complement(&pocket, lo, hi) {
                    let out = overlap(&removed, &[piece]);
                    if out > eps {
                        acc[2] += out;
                        if out > acc[3] {
                            acc[3] = out;
                            [acc[4], acc[5], acc[6]] = [o.x, o.y, 0.5 * (piece[0] + piece[1])];
                        }
                    }
                }
            }
            acc
        })
        .collect();
    let sum = |k: usize| rows.iter().map(|r| r[k]).sum::<f64>() * area;
    let (to_remove, left) = (sum(0), sum(1));
    let (mut cutting, mut air, mut air_moves) = (0.0, 0.0, 0.0);
    let moves = path.moves();
    for (i, m) in moves.iter().enumerate().skip(1) {
        if matches!(m.kind, MoveKind::Feed | MoveKind::Link | MoveKind::Plunge) {
            let len = (m.to - moves[i - 1].to).norm();
            if crate::is_air_move(path, i) {
                air_moves += len;
            }
            cutting += len;
            if report.removed_by_move[i] <= eps * area {
                air += len;
            }
        }
    }
    Ok(Proof {
        volume_to_remove: to_remove,
        remaining_volume: left,
        remaining_percent: if to_remove > 0.0 { 100.0 * left / to_remove } else { 0.0 },
        removed_volume: report.removed_volume,
        gouge_volume: sum(2),
        gouge_depth: rows.iter().map(|r| r[3]).fold(0.0, f64::max),
        gouge_at: rows.iter().filter(|r| r[3] > 0.0).max_by(|a, b| a[3].total_cmp(&b[3])).map(|r| [r[4], r[5], r[6]]),
        cutting_length: cutting,
        air_percent: if cutting > 0.0 { 100.0 * air / cutting } else { 0.0 },
        air_move_length: air_moves,
        sweeps: report.sweeps,
        rays: [dexels.grid(0).0 * dexels.grid(0).1, dexels.grid(1).0 * dexels.grid(1).1, nu * nv],
        min_stick_out: report.min_stick_out.map_or(cutter.flute_length(), |s| s.length),
        min_stick_out_at: report
            .min_stick_out
            .and_then(|s| s.limit)
            .map(|(id, at)| (id.index as usize, [at.x, at.y, at.z])),
        faces: faces.iter().map(|f| face_metrics(&dexels, &part, f, settings.resolution)).collect(),
    })
}
