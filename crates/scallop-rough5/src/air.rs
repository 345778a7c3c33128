//! Air moves (issue 18, item 3; docs/rough5.md, "Air moves"): the cutting
//! moves of a program (feeds, links, plunges) that lie wholly outside the
//! in-process stock, with a clearance around the tool, are written at a
//! named air feed instead of the cutting feed.
//!
//! The classification is conservative. The program is cut once on a
//! tri-dexel stock (the blank, or the stock box): the cutting moves that
//! remove nothing along its Z rays are the candidates. It is cut again, up
//! to each run of candidates (at most [`AIR_CHUNK`] moves); before such a
//! run is cut, the tool grown by the clearance c (every point
//! of the flutes' offset by c: a torus (R, r) becomes (R + c, r + c) with its
//! tip c lower along the axis, the flutes 2 c longer) is swept along each of
//! the run's moves, each alone, against the stock as it stands before the
//! run ([`DexelStock::probe`], nothing removed): a move whose grown sweep
//! meets no material of any ray (beyond the rays' epsilon) is air.
//! The stock before the run holds the stock before each of its moves, so a
//! move classified air meets no stock left by the moves before it, on the
//! rays, by at least c. A long straight move of one axis (an entry from
//! beside the stock, a retract leg) is first cut into pieces of at most
//! [`AIR_SPLIT`] mm, so its part in the air is found; consecutive pieces of
//! one move classified alike are joined again.
//!
//! An air move is written at [`AirSettings::feed`] as a `G1` (its kind kept):
//! the proof ([`crate::prove`]) checks every move programmed faster than the
//! cutting feed as it checks a rapid, so one that removes material is an
//! error.

use scallop_cutter::{Cutter, CutterShape};
use scallop_geom::Aabb3;
use scallop_mesh::TriMesh;
use scallop_sim::{DexelOptions, DexelPart, DexelStock, ToolMove};
use scallop_toolpath::{Move, MoveKind, Toolpath};

use crate::Rough5Error;

/// Longest run of candidate moves of the classification tested together
/// against the stock as it stood before the run (smaller is finer, and
/// slower).
pub const AIR_CHUNK: usize = 24;

/// Longest piece (mm) a long straight move of one tool axis is cut into
/// before it is classified.
pub const AIR_SPLIT: f64 = 2.0;

/// Settings of the air moves.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AirSettings {
    /// The feed of the air moves (mm/min), above the cutting feed.
    pub feed: f64,
    /// Clearance between the tool and the in-process stock for a move to be
    /// air (mm).
    pub clearance: f64,
    /// Spacing of the tri-dexel rays of the classification (mm).
    pub resolution: f64,
    /// Largest distance between the simulated and the true swept solid of a
    /// 5-axis move (mm), as [`crate::ProofSettings::axis_tolerance`].
    pub axis_tolerance: f64,
}

impl AirSettings {
    /// Air moves at `feed` (mm/min): a clearance of 1 mm, rays every 0.5 mm
    /// (the proof's), 5-axis moves within 0.05 mm.
    #[must_use]
    pub fn new(feed: f64) -> AirSettings {
        AirSettings { feed, clearance: 1.0, resolution: 0.5, axis_tolerance: 0.05 }
    }
}

/// What [`air_moves`] found.
#[derive(Debug, Clone, PartialEq)]
pub struct AirMoves {
    /// The program with its air moves at the air feed (long moves cut where
    /// they enter or leave the air).
    pub toolpath: Toolpath,
    /// Moves of `toolpath` at the air feed.
    pub moves: usize,
    /// Their length (mm).
    pub length: f64,
    /// Cutting moves of the input that were cut into pieces.
    pub split: usize,
    /// For each move of `toolpath`, the input move it is (a piece of).
    pub from: Vec<usize>,
}

/// The flutes of `cutter` grown by `c` (a superset of every point within `c`
/// of them), their tip `c` lower along the axis; no shank or holder.
///
/// # Errors
/// [`Rough5Error::BadSetting`] when the grown tool is refused.
pub fn grown_flutes(cutter: &Cutter, c: f64) -> Result<Cutter, Rough5Error> {
    let shape = match *cutter.shape() {
        CutterShape::Flat { radius } => CutterShape::Bull { radius: radius + c, corner: c },
        CutterShape::Ball { radius } => CutterShape::Ball { radius: radius + c },
        CutterShape::Bull { radius, corner } => CutterShape::Bull { radius: radius + c, corner: corner + c },
        // A cylinder holds the cone's offset.
        CutterShape::Cone { radius, .. } => CutterShape::Flat { radius: radius + c },
    };
    Cutter::new(shape, cutter.flute_length() + 2.0 * c)
        .map_err(|_| Rough5Error::BadSetting { name: "air.clearance", value: c })
}

/// One piece of a move of the input program.
#[derive(Debug, Clone, Copy)]
struct Piece {
    /// The input move.
    from: usize,
    tool: ToolMove,
    cutting: bool,
}

/// Classifies the cutting moves of `path` (feeds, links, plunges) against
/// the in-process stock of `cutter` in `stock` (the box, or the closed
/// `blank` in it) and writes those that lie in the air, by
/// [`AirSettings::clearance`], at [`AirSettings::feed`]. Rapids and retracts
/// are kept as they are.
///
/// # Errors
/// [`Rough5Error::BadSetting`] for a feed not above the cutting feed, a
/// non-positive clearance, resolution or tolerance;
/// [`Rough5Error::Simulation`] when the stock or a move is refused.
pub fn air_moves(
    path: &Toolpath,
    cutter: &Cutter,
    (stock, blank): (&Aabb3, Option<&TriMesh>),
    settings: &AirSettings,
) -> Result<AirMoves, Rough5Error> {
    let s = settings;
    if !(s.feed.is_finite() && s.feed > path.feed) {
        return Err(Rough5Error::BadSetting { name: "air.feed", value: s.feed });
    }
    for (name, value) in
        [("air.clearance", s.clearance), ("air.resolution", s.resolution), ("air.axis_tolerance", s.axis_tolerance)]
    {
        if !(value.is_finite() && value > 0.0) {
            return Err(Rough5Error::BadSetting { name, value });
        }
    }
    let sim = |e: scallop_sim::SimError| Rough5Error::Simulation(e.to_string());
    let grown = grown_flutes(cutter, s.clearance)?;
    let moves = path.moves();
    // The pieces: long straight cutting moves of one axis cut into pieces.
    let mut pieces: Vec<Piece> = Vec::with_capacity(moves.len());
    let mut split = 0;
    for (i, m) in moves.iter().enumerate() {
        let axis = path.axis(i);
        let cutting = matches!(m.kind, MoveKind::Feed | MoveKind::Link | MoveKind::Plunge);
        let whole = Piece { from: i, tool: ToolMove { kind: m.kind, tip: m.to, axis, arc: path.arc(i) }, cutting };
        let from = i.checked_sub(1).map(|k| (moves[k].to, path.axis(k)));
        match from {
            Some((a, axis_a)) if cutting && axis_a == axis && path.arc(i).is_none() => {
                let n = ((m.to - a).norm() / AIR_SPLIT).ceil().max(1.0) as usize;
                if n > 1 {
                    split += 1;
                }
                for k in 1..=n {
                    let tip = if k == n { m.to } else { a + (m.to - a) * (k as f64 / n as f64) };
                    pieces.push(Piece { tool: ToolMove { tip, ..whole.tool }, ..whole });
                }
            }
            _ => pieces.push(whole),
        }
    }
    let blank = blank.map(DexelPart::new);
    let mut dexels = match &blank {
        Some(b) => DexelStock::from_solid(*stock, s.resolution, b),
        None => DexelStock::new(*stock, s.resolution),
    }
    .map_err(sim)?;
    let options = DexelOptions { axis_tolerance: s.axis_tolerance, check_collisions: false, max_stick_out: None };
    let tools: Vec<ToolMove> = pieces.iter().map(|p| p.tool).collect();
    // The candidates: cutting pieces that remove nothing along the Z rays when the
    // whole program is cut (a piece that removes material is no air move).
    let removed = dexels.clone().cut(cutter, &tools, &options).map_err(sim)?.removed_by_move;
    let candidate: Vec<bool> = pieces.iter().zip(&removed).map(|(p, r)| p.cutting && *r <= 0.0).collect();
    let mut air = vec![false; pieces.len()];
    let mut start = 1;
    while start < pieces.len() {
        // Each list starts with the piece before it: the tool placed where it stands.
        let end = if candidate[start] {
            // A run of candidates, at most AIR_CHUNK, probed against the stock before it.
            let mut end = start;
            while end < pieces.len() && candidate[end] && end - start < AIR_CHUNK {
                end += 1;
            }
            let probe: Vec<ToolMove> =
                tools[start - 1..end].iter().map(|t| ToolMove { tip: t.tip - t.axis * s.clearance, ..*t }).collect();
            let depth = dexels.probe(&grown, &probe, &options).map_err(sim)?;
            for (k, d) in depth.iter().enumerate().skip(1) {
                air[start - 1 + k] = *d == 0.0;
            }
            end
        } else {
            (start..pieces.len()).find(|&k| candidate[k]).unwrap_or(pieces.len())
        };
        dexels.cut(cutter, &tools[start - 1..end], &options).map_err(sim)?;
        start = end;
    }
    // The program again: consecutive pieces of one move classified alike joined.
    let mut out = Toolpath::new(path.feed);
    out.plunge_feed = path.plunge_feed;
    let (mut count, mut length) = (0, 0.0);
    let mut from = Vec::with_capacity(moves.len());
    let mut k = 0;
    while k < pieces.len() {
        let p = pieces[k];
        let mut last = k;
        while last + 1 < pieces.len() && pieces[last + 1].from == p.from && air[last + 1] == air[k] {
            last += 1;
        }
        let tip = pieces[last].tool.tip;
        if air[k] {
            count += 1;
            let before = if k == 0 { tip } else { pieces[k - 1].tool.tip };
            length += (tip - before).norm();
        }
        out.set_feed_from(if air[k] { Some(s.feed) } else { path.feed_override(p.from) });
        let m = Move::new(moves[p.from].kind, tip);
        match p.tool.arc {
            // An arc is never split.
            Some(arc) => out.push_arc_with_axis(m, p.tool.axis, arc),
            _ => out.push_with_axis(m, p.tool.axis),
        }
        from.push(p.from);
        k = last + 1;
    }
    out.set_feed_from(None);
    Ok(AirMoves { toolpath: out, moves: count, length, split, from })
}

/// Whether move `index` of `path` is an air move: a feed, link or plunge
/// programmed faster than the path's cutting feed.
#[must_use]
pub fn is_air_move(path: &Toolpath, index: usize) -> bool {
    let kind = path.moves()[index].kind;
    matches!(kind, MoveKind::Feed | MoveKind::Link | MoveKind::Plunge)
        && path.feed_override(index).is_some_and(|f| f > path.feed)
}
