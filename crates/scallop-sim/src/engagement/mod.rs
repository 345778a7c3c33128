//! The engagement of a 2.5D pocket program, measured on the material it
//! leaves, not taken from its planner (docs/simulation.md, "Engagement").
//!
//! The engagement angle `phi` at a tool position is the arc of the tool's
//! periphery (the circle of radius `R` about the tool centre) that lies in
//! uncut material. The material is the pocket's inside ([`Pocket`]); the path
//! is resampled every [`EngagementOptions::sample_step`] along its moves at
//! cutting depth, and at each sample the front half of the periphery (the
//! half the tool moves into) is probed at half of
//! [`EngagementOptions::angle_samples`] points. A probed point is uncut when
//! it lies in the pocket and outside every disc of radius `R` swept by the
//! moves before it. Every probe is decided exactly: the tool's own last
//! [`EngagementOptions::recent_factor`]` x R` of path (and more, see below)
//! against the moves themselves, older moves through a raster (cells of side
//! [`EngagementOptions::resolution`]) whose flags settle the cells wholly
//! inside a swept disc or wholly outside all of them and send the others to
//! an exact test against the moves that reach the cell (`raster.rs`).
//!
//! The raster is updated in fixed blocks of samples
//! ([`crate::tol::ENGAGEMENT_BLOCK`]): a block sees the raster of the moves
//! that ended `recent_factor R` before its first sample, and every later move
//! directly; the samples of a block are evaluated in parallel, so the figures
//! do not depend on the thread count.
//!
//! A straight cut at radial depth `ae` beside a cleared area reads
//! `arccos(1 - ae / R)` ([`engagement_angle`]) within
//! [`EngagementOptions::angle_bound`]. The reachable area left uncut is
//! counted on the raster's cells.

mod pocket;
mod raster;
mod stock;

use rayon::prelude::*;
use scallop_geom::Point2;
use scallop_toolpath::{MoveKind, Toolpath};

use crate::SimError;
use crate::tol::{
    ENGAGEMENT_ARC_SAGITTA as ARC_SAGITTA, ENGAGEMENT_BLOCK, ENGAGEMENT_CONTACT, ENGAGEMENT_DESCENT as DESCENT,
};
pub use pocket::Pocket;
pub(crate) use pocket::segment_distance;
use raster::Raster;
pub use stock::stock_engagement;

/// The engagement angle (rad) of a straight cut at radial depth `ae` (mm) by a
/// tool of `radius` (mm): `arccos(1 - ae / R)` (`ae` clamped to `0..=2R`).
///
/// ```
/// let phi = scallop_sim::engagement_angle(1.2, 3.0); // ae = 0.2 D
/// assert!((phi.to_degrees() - 53.13).abs() < 0.01);
/// ```
#[must_use]
pub fn engagement_angle(ae: f64, radius: f64) -> f64 {
    (1.0 - (ae / radius).clamp(0.0, 2.0)).acos()
}

/// Knobs of [`pocket_engagement`]; every length in mm, angles in rad.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EngagementOptions {
    /// Cell side of the raster of older cuts and of the pocket (0.05 mm).
    pub resolution: f64,
    /// Distance between samples along the path (0.1 mm).
    pub sample_step: f64,
    /// Points probed on the tool's whole periphery per sample (720: every
    /// 0.5 deg); the front half's are probed.
    pub angle_samples: usize,
    /// The tool's own last `recent_factor x R` of path is tested exactly (2.2).
    pub recent_factor: f64,
    /// A sample below this angle cuts air (2 deg).
    pub air_angle: f64,
    /// A sample at or above this angle is a full slot (170 deg).
    pub slot_angle: f64,
    /// Over-engagement: above `over_factor x target` (1.2).
    pub over_factor: f64,
    /// Moves whose ends lie at or below this height (mm) cut; `None`: every
    /// move but rapids and retracts.
    pub cut_below: Option<f64>,
    /// Tool discs reaching beyond a wall by more than this are a gouge (0.02 mm).
    pub gouge_tolerance: f64,
    /// Tool centres count for the reachable area only this far inside the
    /// centre region (0.05 mm): the walls' strip of that width is not owed.
    pub uncut_margin: f64,
    /// Samples whose tool centre has not yet left the disc of
    /// `entry_factor x R` about the point where the tool reached cutting
    /// depth belong to the entry and are reported apart (2.0).
    pub entry_factor: f64,
}

impl Default for EngagementOptions {
    fn default() -> Self {
        EngagementOptions {
            resolution: 0.05,
            sample_step: 0.1,
            angle_samples: 720,
            recent_factor: 2.2,
            air_angle: 2f64.to_radians(),
            slot_angle: 170f64.to_radians(),
            over_factor: 1.2,
            cut_below: None,
            gouge_tolerance: 0.02,
            uncut_margin: 0.05,
            entry_factor: 2.0,
        }
    }
}

impl EngagementOptions {
    /// The largest error (rad) of a measured angle made of one arc: every
    /// probe is decided exactly, so only the probes' spacing counts, one
    /// step (`2 pi / angle_samples`) at each end of the arc.
    #[must_use]
    pub fn angle_bound(&self) -> f64 {
        2.0 * std::f64::consts::TAU / self.angle_samples as f64
    }

    fn check(&self, radius: f64) -> Result<(), SimError> {
        let positive = [
            ("tool radius", radius),
            ("resolution", self.resolution),
            ("sample step", self.sample_step),
            ("recent factor", self.recent_factor),
            ("over factor", self.over_factor),
        ];
        for (what, value) in positive {
            if !(value.is_finite() && value > 0.0) {
                return Err(SimError::BadEngagement { what, value });
            }
        }
        let non_negative = [
            ("air angle", self.air_angle),
            ("slot angle", self.slot_angle),
            ("gouge tolerance", self.gouge_tolerance),
            ("uncut margin", self.uncut_margin),
            ("entry factor", self.entry_factor),
        ];
        for (what, value) in non_negative {
            if !(value.is_finite() && value >= 0.0) {
                return Err(SimError::BadEngagement { what, value });
            }
        }
        if !(8..=1_000_000).contains(&self.angle_samples) {
            return Err(SimError::BadEngagement { what: "angle samples (8 to 1e6)", value: self.angle_samples as f64 });
        }
        Ok(())
    }
}

/// What [`pocket_engagement`] measured. Lengths mm, angles rad, areas mm^2.
#[derive(Debug, Clone, PartialEq)]
pub struct EngagementReport {
    /// The target angle the figures compare with.
    pub target: f64,
    /// Samples on cutting moves outside entries (the population of the
    /// percentiles).
    pub samples: usize,
    /// Median engagement.
    pub p50: f64,
    /// 95th percentile.
    pub p95: f64,
    /// 99th percentile.
    pub p99: f64,
    /// Largest engagement outside entries.
    pub max: f64,
    /// Where the largest engagement is, and its move.
    pub max_at: Option<(Point2, usize)>,
    /// Largest engagement inside entries.
    pub entry_max: f64,
    /// Length above `over_factor x target` (outside entries).
    pub over_length: f64,
    /// Length at or above the slot angle (outside entries).
    pub slot_length: f64,
    /// XY length of the moves at cutting depth that cut (some sample at or
    /// above the air angle).
    pub cutting_length: f64,
    /// Length of the cutting moves' samples below the air angle.
    pub air_length: f64,
    /// XY length of the moves at cutting depth that cut nothing (every
    /// sample below the air angle): tool-down links through cleared area.
    pub link_length: f64,
    /// Times the tool left cutting depth.
    pub retracts: usize,
    /// Times the tool reached cutting depth.
    pub entries: usize,
    /// How far the tool reached beyond a wall (mm; negative: the least
    /// clearance), and where (tool centre, move).
    pub max_penetration: f64,
    /// Where the largest penetration is.
    pub penetration_at: Option<(Point2, usize)>,
    /// Pocket area on the raster.
    pub pocket_area: f64,
    /// Area of the pocket's opening by the tool disc (less the walls' margin).
    pub reachable_area: f64,
    /// Reachable area left uncut by the whole program.
    pub uncut_area: f64,
    /// The largest engagement of each move of the program (0 where none).
    pub move_phi: Vec<f64>,
}

impl EngagementReport {
    /// Link length as a share of all feed length at cutting depth.
    #[must_use]
    pub fn link_share(&self) -> f64 {
        let all = self.cutting_length + self.link_length;
        if all > 0.0 { self.link_length / all } else { 0.0 }
    }

    /// Air length as a share of the cutting moves' length.
    #[must_use]
    pub fn air_share(&self) -> f64 {
        if self.cutting_length > 0.0 { self.air_length / self.cutting_length } else { 0.0 }
    }
}

/// A move at cutting depth, in XY, with its arc length span.
#[derive(Debug, Clone, Copy)]
struct Segment {
    a: Point2,
    b: Point2,
    /// Arc length at `b` along the moves at cutting depth.
    s1: f64,
    index: usize,
}

/// A sample: the tool centre, its arc length, its segment, its length share.
#[derive(Debug, Clone, Copy)]
struct Sample {
    at: Point2,
    /// The tool tip's height.
    z: f64,
    s: f64,
    segment: usize,
    weight: f64,
    entry: bool,
}

struct Track {
    segments: Vec<Segment>,
    samples: Vec<Sample>,
    entries: usize,
    retracts: usize,
}

fn is_cutting(path: &Toolpath, i: usize, cut_below: Option<f64>) -> bool {
    let m = path.moves();
    i > 0
        && !matches!(m[i].kind, MoveKind::Rapid | MoveKind::Retract)
        && cut_below.is_none_or(|z| m[i - 1].to.z <= z && m[i].to.z <= z)
}

/// The moves at cutting depth as segments and their samples.
fn track(path: &Toolpath, radius: f64, options: &EngagementOptions) -> Track {
    let xy = |i: usize| Point2::new(path.moves()[i].to.x, path.moves()[i].to.y);
    let mut t = Track { segments: Vec::new(), samples: Vec::new(), entries: 0, retracts: 0 };
    let (mut s, mut entry_point): (f64, Option<Point2>) = (0.0, None);
    let entry_radius = options.entry_factor * radius;
    for i in 1..path.moves().len() {
        let (cutting, before) = (is_cutting(path, i, options.cut_below), is_cutting(path, i - 1, options.cut_below));
        if !cutting {
            t.retracts += usize::from(before);
            continue;
        }
        let (from, to) = (path.moves()[i - 1].to, path.moves()[i].to);
        // An entry starts where the tool comes to cutting depth from a retract,
        // or where it starts descending at depth (a plunge, ramp or helix after
        // a tool-down link from the level above).
        let descends = |k: usize| path.moves()[k].to.z < path.moves()[k - 1].to.z - DESCENT;
        let descent_starts = descends(i) && !(i >= 2 && is_cutting(path, i - 1, options.cut_below) && descends(i - 1));
        if !before || descent_starts {
            t.entries += 1;
            entry_point = Some(xy(i - 1));
        }
        // An arc move (G2/G3) is followed along its chords within
        // `ARC_SAGITTA`, each a segment of the same move.
        let ends = path.arc(i).map_or_else(|| vec![to], |arc| arc.chords(&from, &to, ARC_SAGITTA));
        let mut a = xy(i - 1);
        let mut za = from.z;
        if descends(i) && Point2::new(to.x, to.y) == a {
            // A vertical plunge: one sample of no length at its bottom, so the
            // material it meets counts in the entries' largest engagement.
            t.segments.push(Segment { a, b: a, s1: s, index: i });
            let segment = t.segments.len() - 1;
            t.samples.push(Sample { at: a, z: to.z, s, segment, weight: 0.0, entry: true });
            continue;
        }
        for end in ends {
            let b = Point2::new(end.x, end.y);
            let length = (b - a).norm();
            t.segments.push(Segment { a, b, s1: s + length, index: i });
            // Whole numbers of steps (at most a path length over a positive step).
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
            let n = (length / options.sample_step).ceil() as usize;
            for k in 1..=n {
                let f = k as f64 / n as f64;
                let at = a + (b - a) * f;
                let entry = entry_point.is_some_and(|e| (at - e).norm() <= entry_radius);
                if !entry {
                    entry_point = None;
                }
                let segment = t.segments.len() - 1;
                let z = za + (end.z - za) * f;
                t.samples.push(Sample { at, z, s: s + length * f, segment, weight: length / n as f64, entry });
            }
            s += length;
            a = b;
            za = end.z;
        }
    }
    t
}

/// The arc of the front half of the periphery about `at` (the half the
/// tool moves into, along the current move from `from`) in uncut material:
/// probed points in the raster's uncut cells and outside every disc swept
/// along `older` moves and the current one. The back half lies in what the
/// tool has just cut; only its edge touches material, and no flute cuts there.
///
/// The front half lies exactly at `R` from `at` and beyond `R` from the rest
/// of the current move: it is uncut unless deeper than
/// [`ENGAGEMENT_CONTACT`] inside that move's disc. An older move is given
/// the contact margin the other way (a point within `R + ENGAGEMENT_CONTACT`
/// of it is cut), so that a pass that retraces an earlier one, ending where
/// it ended, reads no engagement on the earlier disc's edge.
fn periphery_arc(
    at: Point2,
    from: Point2,
    radius: f64,
    stock: (&Raster, &Pocket),
    older: &[(Point2, Point2)],
    n: usize,
) -> f64 {
    let step = std::f64::consts::PI / n as f64;
    let uncut = |theta: f64| {
        let q = at + scallop_geom::Vec2::new(theta.cos(), theta.sin()) * radius;
        stock.0.is_uncut(q, stock.1, radius)
            && segment_distance(q, from, at) >= radius - ENGAGEMENT_CONTACT
            && older.iter().all(|&(a, b)| segment_distance(q, a, b) > radius + ENGAGEMENT_CONTACT)
    };
    if at == from {
        // A vertical plunge: the half of the periphery with most material.
        let probes: Vec<bool> = (0..2 * n).map(|k| uncut((k as f64 + 0.5) * step)).collect();
        return half_window_max(&probes) as f64 * step;
    }
    let heading = (at.y - from.y).atan2(at.x - from.x);
    let count = (0..n).filter(|&k| uncut(heading - std::f64::consts::FRAC_PI_2 + (k as f64 + 0.5) * step)).count();
    count as f64 * step
}

/// The most `true` probes among `probes.len() / 2` consecutive ones, the
/// probes being equally spaced round a circle: the half circle with most
/// material, for a sample with no direction of motion (a vertical plunge).
pub(crate) fn half_window_max(probes: &[bool]) -> usize {
    let (total, half) = (probes.len(), probes.len() / 2);
    if half == 0 {
        return 0;
    }
    let mut count = probes[..half].iter().filter(|&&b| b).count();
    let mut best = count;
    for k in 0..total {
        count = count + usize::from(probes[(k + half) % total]) - usize::from(probes[k]);
        best = best.max(count);
    }
    best
}

/// The engagement of every sample, in program order (see the module docs).
fn sample_angles(
    track: &Track,
    pocket: &Pocket,
    raster: &mut Raster,
    radius: f64,
    options: &EngagementOptions,
) -> Vec<f64> {
    let mut phi = Vec::with_capacity(track.samples.len());
    let mut stamped = 0;
    for block in track.samples.chunks(ENGAGEMENT_BLOCK) {
        let horizon = block[0].s - options.recent_factor * radius;
        while stamped < track.segments.len() && track.segments[stamped].s1 <= horizon {
            let g = track.segments[stamped];
            raster.stamp(g.a, g.b, radius);
            stamped += 1;
        }
        let raster = &*raster;
        let from = stamped;
        let angles: Vec<f64> = block
            .par_iter()
            .map(|sample| {
                let segments = &track.segments[from.min(sample.segment)..sample.segment];
                let older: Vec<(Point2, Point2)> = segments.iter().map(|g| (g.a, g.b)).collect();
                let current = track.segments[sample.segment].a;
                periphery_arc(sample.at, current, radius, (raster, pocket), &older, options.angle_samples / 2)
            })
            .collect();
        phi.extend(angles);
    }
    for g in &track.segments[stamped..] {
        raster.stamp(g.a, g.b, radius);
    }
    phi
}

/// The deepest reach of the tool beyond the walls over the samples and the
/// segments' ends: (depth, tool centre, move).
fn deepest(pocket: &Pocket, track: &Track, radius: f64) -> Option<(f64, Point2, usize)> {
    let points: Vec<(Point2, usize)> = track
        .samples
        .iter()
        .map(|s| (s.at, track.segments[s.segment].index))
        .chain(track.segments.iter().map(|g| (g.a, g.index)))
        .collect();
    points.par_iter().map(|&(p, index)| (pocket.penetration(p, radius), p, index)).reduce_with(|x, y| {
        match y.0.total_cmp(&x.0).then(x.2.cmp(&y.2)) {
            std::cmp::Ordering::Greater => y,
            _ => x,
        }
    })
}

/// Measures the engagement of `path` cutting the 2.5D `pocket` with a tool of
/// `radius` against the `target` angle (see the module docs), the links, the
/// entries and retracts, and the reachable area left uncut.
///
/// # Errors
/// [`SimError::BadEngagement`] for a bad option, raster errors
/// ([`SimError::TooManyCells`]), and [`SimError::PocketGouge`] when the tool
/// at cutting depth reaches beyond a wall (the pocket's or an island's) by
/// more than the gouge tolerance.
///
/// ```
/// use scallop_geom::{Point2, Point3};
/// use scallop_sim::{EngagementOptions, Pocket, engagement_angle, pocket_engagement};
/// use scallop_toolpath::{Move, MoveKind, Toolpath};
/// let square = |x0: f64, y0: f64, x1: f64, y1: f64| {
///     vec![Point2::new(x0, y0), Point2::new(x1, y0), Point2::new(x1, y1), Point2::new(x0, y1)]
/// };
/// let pocket = Pocket::new(vec![square(0.0, 0.0, 60.0, 40.0)]).unwrap();
/// // A slot along y = 20, then a pass 1.2 mm beside it (0.2 D of a 6 mm tool).
/// let mut path = Toolpath::new(1000.0);
/// for (y, x1) in [(20.0, 50.0), (21.2, 44.0)] {
///     path.push(Move::new(MoveKind::Rapid, Point3::new(10.0, y, 5.0)));
///     path.push(Move::new(MoveKind::Plunge, Point3::new(10.0, y, -1.0)));
///     path.push(Move::new(MoveKind::Feed, Point3::new(x1, y, -1.0)));
///     path.push(Move::new(MoveKind::Retract, Point3::new(x1, y, 5.0)));
/// }
/// let options = EngagementOptions::default();
/// let target = engagement_angle(1.2, 3.0);
/// let report = pocket_engagement(&pocket, 3.0, &path, target, &options).unwrap();
/// assert!((report.move_phi[2] - std::f64::consts::PI).abs() <= options.angle_bound()); // the slot
/// assert!((report.move_phi[6] - target).abs() <= options.angle_bound()); // the side cut
/// assert!((report.slot_length - 34.0).abs() <= options.sample_step); // 40 mm less the entry
/// assert_eq!((report.entries, report.retracts), (2, 2));
/// ```
pub fn pocket_engagement(
    pocket: &Pocket,
    radius: f64,
    path: &Toolpath,
    target: f64,
    options: &EngagementOptions,
) -> Result<EngagementReport, SimError> {
    options.check(radius)?;
    let mut raster = Raster::new(pocket, options.resolution)?;
    let track = track(path, radius, options);
    let deepest = deepest(pocket, &track, radius);
    if let Some((depth, at, index)) = deepest.filter(|d| d.0 > options.gouge_tolerance) {
        return Err(SimError::PocketGouge { depth, at, index, tolerance: options.gouge_tolerance });
    }
    let phi = sample_angles(&track, pocket, &mut raster, radius, options);
    let (material, reachable, uncut) = raster.opening_uncut(radius, options.uncut_margin);
    let cell_area = raster.cell_size() * raster.cell_size();
    let mut report = summarise(path, &track, &phi, target, options);
    report.max_penetration = deepest.map_or(f64::NEG_INFINITY, |d| d.0);
    report.penetration_at = deepest.map(|d| (d.1, d.2));
    report.pocket_area = material as f64 * cell_area;
    report.reachable_area = reachable as f64 * cell_area;
    report.uncut_area = uncut as f64 * cell_area;
    Ok(report)
}

/// The nearest-rank `q` quantile of sorted values (0 when empty).
fn quantile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return 0.0;
    }
    // Ranks below the sample count: exact conversions.
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let rank = ((q * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len());
    sorted[rank - 1]
}

/// The figures from the samples' angles.
fn summarise(
    path: &Toolpath,
    track: &Track,
    phi: &[f64],
    target: f64,
    options: &EngagementOptions,
) -> EngagementReport {
    let mut move_phi = vec![0.0f64; path.moves().len()];
    for (s, &p) in track.samples.iter().zip(phi) {
        let m = &mut move_phi[track.segments[s.segment].index];
        *m = m.max(p);
    }
    let link = |s: &Sample| move_phi[track.segments[s.segment].index] < options.air_angle;
    let mut counted = Vec::new();
    let mut r = EngagementReport {
        target,
        samples: 0,
        p50: 0.0,
        p95: 0.0,
        p99: 0.0,
        max: 0.0,
        max_at: None,
        entry_max: 0.0,
        over_length: 0.0,
        slot_length: 0.0,
        cutting_length: 0.0,
        air_length: 0.0,
        link_length: 0.0,
        retracts: track.retracts,
        entries: track.entries,
        max_penetration: 0.0,
        penetration_at: None,
        pocket_area: 0.0,
        reachable_area: 0.0,
        uncut_area: 0.0,
        move_phi: Vec::new(),
    };
    for (s, &p) in track.samples.iter().zip(phi) {
        if link(s) {
            r.link_length += s.weight;
            continue;
        }
        r.cutting_length += s.weight;
        if p < options.air_angle {
            r.air_length += s.weight;
        }
        if s.entry {
            r.entry_max = r.entry_max.max(p);
            continue;
        }
        counted.push(p);
        if p > r.max || r.max_at.is_none() {
            r.max = p;
            r.max_at = Some((s.at, track.segments[s.segment].index));
        }
        if p > options.over_factor * target {
            r.over_length += s.weight;
        }
        if p >= options.slot_angle {
            r.slot_length += s.weight;
        }
    }
    counted.sort_by(f64::total_cmp);
    r.samples = counted.len();
    (r.p50, r.p95, r.p99) = (quantile(&counted, 0.5), quantile(&counted, 0.95), quantile(&counted, 0.99));
    r.move_phi = move_phi;
    r
}
