//! Zone, surface and inter-zone time (finishing.md 7.4) over the jerk-limited
//! stop-to-stop model of `scallop_analysis::MachineLimits::segment_time` (7.1, 7.2).

use scallop_analysis::MachineLimits;
use scallop_geom::Point3;
use serde::{Deserialize, Serialize};

use super::ZonePlan;

/// How the tool goes from the last point of a zone to the first point of the
/// next one (finishing.md 7.4 \[DECISION\]); distances in the part frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum TransitionModel {
    /// Vertical retract to `max(z_end, z_start) + clearance`, a straight horizontal
    /// move, a vertical plunge: three stop-to-stop moves at `rapid_feed` (mm/s;
    /// `None`: the feed `V`) with the machine's `A` and `J`.
    RetractTraverse {
        /// `c` (mm) above the higher of the two points.
        clearance: f64,
        /// `V_rapid` (mm/s); `None` is the machine's feed `V` (the default, 13).
        rapid_feed: Option<f64>,
    },
    /// One straight 3D move from end to start at the feed `V`.
    Linear,
}

/// The inter-zone transition settings (a job key: default RetractTraverse, c =
/// 5 mm, `V_rapid = V`, no reorientation time; finishing.md 13).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Transitions {
    /// The move model.
    pub model: TransitionModel,
    /// `t_rot` (s) added to a transition between zones of different 3+2 orientations.
    pub reorientation_s: f64,
}

impl Default for Transitions {
    fn default() -> Self {
        Transitions {
            model: TransitionModel::RetractTraverse { clearance: 5.0, rapid_feed: None },
            reorientation_s: 0.0,
        }
    }
}

impl Transitions {
    /// Time (s) and length (mm) of the move from `from` to `to` (part frame).
    #[must_use]
    pub fn time(&self, from: &Point3, to: &Point3, machine: &MachineLimits) -> (f64, f64) {
        match self.model {
            TransitionModel::Linear => {
                let l = (to - from).norm();
                (machine.segment_time(l), l)
            }
            TransitionModel::RetractTraverse { clearance, rapid_feed } => {
                let rapid = MachineLimits { feed: rapid_feed.unwrap_or(machine.feed), ..*machine };
                let top = from.z.max(to.z) + clearance;
                let up = top - from.z;
                let across = (to.x - from.x).hypot(to.y - from.y);
                let down = top - to.z;
                let t = rapid.segment_time(up) + rapid.segment_time(across) + rapid.segment_time(down);
                (t, up.max(0.0) + across + down.max(0.0))
            }
        }
    }
}

/// The time of a sequence of zones (finishing.md 7.4).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SurfaceTime {
    /// Zones plus transitions (s).
    pub total_s: f64,
    /// Each zone's time, in the order given (s).
    pub per_zone: Vec<f64>,
    /// All transitions, reorientation included (s).
    pub transitions_s: f64,
    /// `L_cut + L_link` (mm), the thesis's path length.
    pub length_mm: f64,
    /// `L_cut` (mm).
    pub cut_length_mm: f64,
    /// `L_link` (mm).
    pub link_length_mm: f64,
    /// `L_trans` (mm).
    pub transition_length_mm: f64,
}

/// Surface time = sum of the zones' times + the transitions between consecutive
/// zones, in the order given (the spec's order is increasing label, which
/// [`super::plan_zones`] returns). Each zone starts at the start of its first pass.
///
/// ```
/// use scallop_geom::Point3;
/// use scallop_network::{Transitions, TransitionModel};
/// let m = scallop_analysis::MachineLimits::default();
/// let t = Transitions { model: TransitionModel::Linear, reorientation_s: 0.0 };
/// let (time, length) = t.time(&Point3::origin(), &Point3::new(3.0, 4.0, 0.0), &m);
/// assert_eq!(length, 5.0);
/// assert_eq!(time, m.segment_time(5.0));
/// ```
#[must_use]
pub fn surface_time(zones: &[ZonePlan], transitions: &Transitions, machine: &MachineLimits) -> SurfaceTime {
    let mut out = SurfaceTime {
        total_s: 0.0,
        per_zone: Vec::with_capacity(zones.len()),
        transitions_s: 0.0,
        length_mm: 0.0,
        cut_length_mm: 0.0,
        link_length_mm: 0.0,
        transition_length_mm: 0.0,
    };
    for (i, zone) in zones.iter().enumerate() {
        out.per_zone.push(zone.time_s);
        out.cut_length_mm += zone.cut_length_mm;
        out.link_length_mm += zone.link_length_mm;
        if i > 0 {
            let previous = &zones[i - 1];
            let (t, l) = transitions.time(&previous.end, &zone.start, machine);
            out.transitions_s += t;
            out.transition_length_mm += l;
            if previous.orientation != zone.orientation {
                out.transitions_s += transitions.reorientation_s;
            }
        }
    }
    out.length_mm = out.cut_length_mm + out.link_length_mm;
    out.total_s = out.per_zone.iter().sum::<f64>() + out.transitions_s;
    out
}

/// Length (mm) and time (s) of a pass: one stop-to-stop move per chain between
/// sharp corners (a direction change whose cosine is below `cos_sharp`).
pub(crate) fn pass_length_time(points: &[Point3], cos_sharp: f64, machine: &MachineLimits) -> (f64, f64) {
    let mut total = 0.0;
    let mut time = 0.0;
    let mut chain = 0.0;
    // The previous segment and its length.
    let mut previous: Option<(scallop_geom::Vec3, f64)> = None;
    for w in points.windows(2) {
        let v = w[1] - w[0];
        let l = v.norm();
        if l <= scallop_strategy::tol::ZERO_LENGTH {
            continue;
        }
        if let Some((p, pl)) = previous {
            // The turn's cosine (p / |p|) . (v / |v|) against cos_sharp, decided
            // without the six divisions unless within far more than the
            // rounding of either form (a few 1e-16 of |p| |v|): then the unit
            // directions as always.
            let (dot, scale) = (p.dot(&v), pl * l);
            let sharp = if (dot - cos_sharp * scale).abs() > 1e-12 * scale {
                dot < cos_sharp * scale
            } else {
                (p / pl).dot(&(v / l)) < cos_sharp
            };
            if sharp {
                time += machine.segment_time(chain);
                chain = 0.0;
            }
        }
        chain += l;
        total += l;
        previous = Some((v, l));
    }
    (total, time + machine.segment_time(chain))
}
