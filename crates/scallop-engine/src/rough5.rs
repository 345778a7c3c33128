//! `kind = "rough5"` job operations (docs/job.md, docs/rough5.md): 5-axis
//! roughing of a test part by guide curves, planned by `scallop-rough5`,
//! proven on a tri-dexel stock (gouges, rapids into stock, shank and holder
//! collisions are errors), put through the machine's kinematics (joint limits
//! checked) and posted in TCP form (Siemens 840D `TRAORI`, Fanuc `G43.4`,
//! Heidenhain `M128`/`TCPM`, ...), read back and replayed against the CL path,
//! with the machine's time model. The `scallop rough5` command and `scallop run`
//! share these functions.

use scallop_cutter::Cutter;
use scallop_guides::GuideSettings;
use scallop_machine::program::{ClRecord, MachineProgram, Motion, ProgramOptions, records_of, to_program};
use scallop_machine::time::{path_time, rapid_time};
use scallop_machine::{Joints, Kinematics, Machine};
use scallop_parts::{FaceTag, TestPart};
use scallop_post::{Dialect, OutputMode, PostParams, check_replay, program_text, replay};
use scallop_rough5::{
    PathDynamics, Proof, ProofFace, ProofSettings, Rough5Plan, Rough5Settings, plan_rough5_in, prove_with_faces,
};
use scallop_toolpath::Toolpath;
use serde::Serialize;

use crate::EngineError;

/// Times of a machine program (s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProgramTime {
    /// Feed and rapid time.
    pub total: f64,
    /// Feed runs by the look-ahead model.
    pub feed: f64,
    /// Feed runs at the programmed feeds alone.
    pub floor: f64,
    /// Rapids, per axis stop to stop.
    pub rapid: f64,
    /// Peak speed of each joint over the feed runs (mm/s or deg/s).
    pub peak: [f64; 5],
    /// Time lost to each joint's velocity, acceleration and jerk limits.
    pub lost: [f64; 5],
}

/// The machine-aware time of a program's blocks `(motion, joints, feed)`: feed
/// runs (maximal sequences of non-rapid blocks, with the block before as their
/// start) by the look-ahead model; rapids per axis, stop to stop.
///
/// # Errors
/// The time model refuses a run (a feed that is not positive).
pub fn program_time(
    kin: &Kinematics,
    blocks: &[(Motion, Joints, f64)],
) -> Result<ProgramTime, scallop_machine::MachineError> {
    let mut t = ProgramTime { total: 0.0, feed: 0.0, floor: 0.0, rapid: 0.0, peak: [0.0; 5], lost: [0.0; 5] };
    let mut k = 1;
    while k < blocks.len() {
        if blocks[k].0 == Motion::Rapid {
            t.rapid += rapid_time(kin.machine(), &blocks[k - 1].1, &blocks[k].1);
            k += 1;
            continue;
        }
        let start = k - 1;
        while k < blocks.len() && blocks[k].0 != Motion::Rapid {
            k += 1;
        }
        let joints: Vec<Joints> = blocks[start..k].iter().map(|b| b.1).collect();
        let feeds: Vec<f64> = blocks[start + 1..k].iter().map(|b| b.2).collect();
        let r = path_time(kin, &joints, &feeds)?;
        t.feed += r.total;
        t.floor += r.feed_time;
        for i in 0..5 {
            t.peak[i] = t.peak[i].max(r.axis_peak_speed[i]);
            t.lost[i] += r.axis_time_lost[i];
        }
    }
    t.total = t.feed + t.rapid;
    Ok(t)
}

/// One block of a machine program and what sets its time
/// ([`block_times`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BlockTime {
    /// The block's index in the program.
    pub block: usize,
    /// The CL record (toolpath move) it comes from.
    pub cl_index: usize,
    /// A rapid (axis by axis, stop to stop).
    pub rapid: bool,
    /// Tip travel (mm).
    pub length_mm: f64,
    /// Programmed feed (mm/min; the rapid's: 0).
    pub feed_mm_min: f64,
    /// Its time by the time model (s).
    pub time_s: f64,
    /// The tip's travel at the programmed feed (s; a rapid: 0).
    pub at_feed_s: f64,
    /// The time at the velocity limits alone (s, at least `at_feed_s`; a
    /// rapid: its whole time).
    pub at_velocity_s: f64,
    /// What sets `at_velocity_s`: `feed`, `orientation` (the tool axis's turn
    /// at the NC's reference radius) or an axis's name (a rapid: the axis
    /// whose stop-to-stop profile is the longest).
    pub bound: String,
    /// Its time with the linear axes' velocity, acceleration and jerk limits
    /// lifted, the rotary axes' kept (s; a rapid: its time).
    pub rotary_only_s: f64,
    /// Its time with the rotary axes' limits lifted, the linear axes' kept.
    pub linear_only_s: f64,
}

/// Every block of `program` with its time and what sets it: the feed runs by
/// the look-ahead model ([`scallop_machine::time::path_time`]), the rapids
/// axis by axis, as [`program_time`] adds them up (the times sum to its
/// total). A feed block's time splits into the tip's travel at the
/// programmed feed, the rest of its velocity-limited time (the binding
/// axis's velocity or the orientation feed: [`scallop_machine::time::velocity_bound`]),
/// and what the acceleration and jerk limits add (`time_s - at_velocity_s`).
///
/// # Errors
/// The time model refuses a run (a feed that is not positive).
pub fn block_times(
    kin: &Kinematics,
    program: &MachineProgram,
) -> Result<Vec<BlockTime>, scallop_machine::MachineError> {
    use scallop_machine::AxisKind;
    use scallop_machine::time::{VelocityBound, path_time_lifting, rapid_bound, velocity_bound};
    let machine = kin.machine();
    let name = |i: usize| machine.axes().get(i).map_or_else(|| format!("axis {i}"), |a| a.name.clone());
    let b = &program.blocks;
    let mut out = Vec::with_capacity(b.len());
    let mut k = 1;
    while k < b.len() {
        let length = (b[k].pose.tip - b[k - 1].pose.tip).norm();
        if b[k].motion == Motion::Rapid {
            let t = rapid_time(machine, &b[k - 1].joints, &b[k].joints);
            out.push(BlockTime {
                block: k,
                cl_index: b[k].cl_index,
                rapid: true,
                length_mm: length,
                feed_mm_min: 0.0,
                time_s: t,
                at_feed_s: 0.0,
                at_velocity_s: t,
                bound: rapid_bound(machine, &b[k - 1].joints, &b[k].joints).map_or_else(|| "none".into(), name),
                rotary_only_s: t,
                linear_only_s: t,
            });
            k += 1;
            continue;
        }
        let start = k - 1;
        while k < b.len() && b[k].motion != Motion::Rapid {
            k += 1;
        }
        let joints: Vec<Joints> = b[start..k].iter().map(|x| x.joints).collect();
        let feeds: Vec<f64> = b[start + 1..k].iter().map(|x| x.feed).collect();
        let r = path_time(kin, &joints, &feeds)?;
        let group = |kind: AxisKind| -> Vec<usize> {
            machine.axes().iter().enumerate().filter(|(_, a)| a.kind == kind).map(|(i, _)| i).collect()
        };
        let rotary_only = path_time_lifting(kin, &joints, &feeds, &group(AxisKind::Linear))?;
        let linear_only = path_time_lifting(kin, &joints, &feeds, &group(AxisKind::Rotary))?;
        for (j, profile) in r.blocks.iter().enumerate() {
            let i = start + 1 + j;
            let (t_feed, t_vel, bound) = velocity_bound(kin, &b[i - 1].joints, &b[i].joints, b[i].feed);
            out.push(BlockTime {
                block: i,
                cl_index: b[i].cl_index,
                rapid: false,
                length_mm: (b[i].pose.tip - b[i - 1].pose.tip).norm(),
                feed_mm_min: b[i].feed,
                time_s: profile.time,
                at_feed_s: t_feed,
                at_velocity_s: t_vel,
                bound: match bound {
                    VelocityBound::Feed => "feed".into(),
                    VelocityBound::Orientation => "orientation".into(),
                    VelocityBound::Axis(a) => name(a),
                },
                rotary_only_s: rotary_only.blocks[j].time,
                linear_only_s: linear_only.blocks[j].time,
            });
        }
    }
    Ok(out)
}

/// The machine time of the blocks labelled alike ([`time_breakdown`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TimeShare {
    /// The label (for `scallop rough5`: the move's role and kind).
    pub label: String,
    /// Blocks.
    pub blocks: usize,
    /// Tip travel (mm).
    pub length_mm: f64,
    /// Machine time (s).
    pub time_s: f64,
    /// The tip's travel at the programmed feeds (s).
    pub at_feed_s: f64,
    /// The velocity-limited time beyond the feed, by what sets it (s): an
    /// axis's name or `orientation`; the rapids' whole time by their slowest axis.
    pub velocity_s: Vec<(String, f64)>,
    /// What the acceleration and jerk limits add (s).
    pub dynamics_s: f64,
    /// What the rotary axes' limits cost (s): the time less that with their
    /// limits lifted (a marginal figure: where both groups bind, the two
    /// costs overlap; it can be slightly negative, since lifting a group's
    /// limits shortens the blocks where only that group moves, and the
    /// look-ahead then slows down into them).
    pub rotary_axes_s: f64,
    /// What the linear axes' limits cost (s), likewise.
    pub linear_axes_s: f64,
}

/// Sums `blocks` by `label(cl_index)`, in the order the labels first occur.
#[must_use]
pub fn time_breakdown(blocks: &[BlockTime], label: &dyn Fn(usize) -> String) -> Vec<TimeShare> {
    let mut shares: Vec<TimeShare> = Vec::new();
    for b in blocks {
        let l = label(b.cl_index);
        let k = match shares.iter().position(|s| s.label == l) {
            Some(k) => k,
            None => {
                shares.push(TimeShare {
                    label: l,
                    blocks: 0,
                    length_mm: 0.0,
                    time_s: 0.0,
                    at_feed_s: 0.0,
                    velocity_s: Vec::new(),
                    dynamics_s: 0.0,
                    rotary_axes_s: 0.0,
                    linear_axes_s: 0.0,
                });
                shares.len() - 1
            }
        };
        let s = &mut shares[k];
        s.blocks += 1;
        s.length_mm += b.length_mm;
        s.time_s += b.time_s;
        s.at_feed_s += b.at_feed_s;
        s.dynamics_s += b.time_s - b.at_velocity_s;
        s.rotary_axes_s += b.time_s - b.linear_only_s;
        s.linear_axes_s += b.time_s - b.rotary_only_s;
        let extra = b.at_velocity_s - b.at_feed_s;
        if extra > 0.0 {
            match s.velocity_s.iter_mut().find(|(n, _)| *n == b.bound) {
                Some((_, t)) => *t += extra,
                None => s.velocity_s.push((b.bound.clone(), extra)),
            }
        }
    }
    shares
}

/// A toolpath on a 5-axis machine: its CL records, the joint-space program
/// (joint limits checked, branches and poles handled) and its time.
#[derive(Debug, Clone)]
pub struct OnMachine {
    /// The CL records of the toolpath.
    pub records: Vec<ClRecord>,
    /// The joint-space program.
    pub program: MachineProgram,
    /// Its machine-aware time.
    pub time: ProgramTime,
}

/// The toolpath through the machine's kinematics and its time model.
///
/// # Errors
/// [`EngineError::Output`] when the machine cannot run the program (a joint
/// limit, an interpolation that leaves the path), naming the block.
pub fn on_machine(kin: &Kinematics, path: &Toolpath) -> Result<OnMachine, EngineError> {
    let name = kin.machine().name().to_string();
    let records = records_of(path);
    let program = to_program(kin, &records, None, &ProgramOptions::default()).map_err(|e| EngineError::Output {
        what: format!("the program on {name}: {e}"),
        fix: "another machine, or a smaller angular step (rough5.max_angle_step_deg, rough5.max_azimuth_step_deg)"
            .into(),
    })?;
    let blocks: Vec<_> = program.blocks.iter().map(|b| (b.motion, b.joints, b.feed)).collect();
    let time = program_time(kin, &blocks)
        .map_err(|e| EngineError::Output { what: format!("time model on {name}: {e}"), fix: "report it".into() })?;
    Ok(OnMachine { records, program, time })
}

/// The words of a TCP program.
#[derive(Debug, Clone, PartialEq)]
pub struct TcpWords {
    /// Program name or number.
    pub program: String,
    /// Tool number.
    pub tool: u32,
    /// Tool length the kinematics use (mm).
    pub tool_length: f64,
    /// Spindle speed (1/min).
    pub spindle: f64,
}

/// A posted 5-axis program.
#[derive(Debug, Clone)]
pub struct Posted {
    /// The program text.
    pub text: String,
    /// Its blocks (after subdivision).
    pub blocks: usize,
    /// Largest tip deviation of the replayed program from the CL path (mm).
    pub replay_tip_deviation: f64,
    /// Its machine-aware time.
    pub time: ProgramTime,
    /// Time lost to each axis's limits (s), by axis name.
    pub axis_time_lost: Vec<(String, f64)>,
    /// Every block's time and what sets it ([`block_times`]).
    pub block_times: Vec<BlockTime>,
}

/// The toolpath through the machine (joint limits checked) and the dialect in
/// TCP form (`TRAORI` on the 840D), read back and replayed against the CL path.
///
/// # Errors
/// [`EngineError::Output`]: the machine refuses the program, the dialect has
/// no TCP form (grbl), or the program read back leaves the CL path.
pub fn post_tcp(kin: &Kinematics, path: &Toolpath, dialect: &Dialect, words: &TcpWords) -> Result<Posted, EngineError> {
    let run = on_machine(kin, path)?;
    let options = ProgramOptions::default();
    let params = PostParams {
        program: words.program.clone(),
        mode: OutputMode::Tcp,
        tool: words.tool,
        tool_length: words.tool_length,
        spindle: words.spindle,
        tol_pos: options.tol_pos,
        tol_ang: options.tol_ang,
        predicted_time: Some(run.time.total),
    };
    let output = |what: String| EngineError::Output { what, fix: "another dialect (output.dialect)".into() };
    let text =
        program_text(&run.program, kin, dialect, &params).map_err(|e| output(format!("{}: {e}", dialect.name)))?;
    let replayed = replay(&text, dialect, kin).map_err(|e| output(format!("our output does not read back: {e}")))?;
    let trip = check_replay(&replayed, &run.records, kin, dialect, options.tol_pos, options.tol_ang)
        .map_err(|e| output(format!("the program does not replay to the CL path: {e}")))?;
    let axis_time_lost = kin.machine().axes().iter().zip(run.time.lost).map(|(a, t)| (a.name.clone(), t)).collect();
    let block_times = block_times(kin, &run.program)
        .map_err(|e| EngineError::Output { what: format!("time model: {e}"), fix: "report it".into() })?;
    Ok(Posted {
        text,
        blocks: run.program.blocks.len(),
        replay_tip_deviation: trip.max_tip_deviation,
        time: run.time,
        axis_time_lost,
        block_times,
    })
}

/// The metrics of a 5-axis roughing program (spec 10.1, docs/rough5.md).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Rough5Metrics {
    /// Volume to remove, on the proof's rays (mm^3).
    pub volume_to_remove_mm3: f64,
    /// Stock left inside it (mm^3).
    pub remaining_volume_mm3: f64,
    /// V_r (% of the volume to remove).
    pub remaining_percent: f64,
    /// Stock removed (mm^3).
    pub removed_volume_mm3: f64,
    /// Stock removed outside the volume to remove (mm^3).
    pub gouge_volume_mm3: f64,
    /// Its longest piece along one Z ray (mm).
    pub gouge_depth_mm: f64,
    /// Cutting length (dm).
    pub path_length_dm: f64,
    /// L_HM: % of the cutting length that removed nothing (air moves
    /// included).
    pub out_of_material_percent: f64,
    /// % of the cutting length written at the air feed (moves outside the
    /// in-process stock by a clearance, `scallop_rough5::air_moves`; part of
    /// L_HM): L_HM at the cutting feed is the difference.
    pub air_feed_percent: f64,
    /// Moves written at the air feed.
    pub air_moves: usize,
    /// Machine time (s); the time at the programmed feeds without a machine program.
    pub machining_time_s: f64,
    /// Time lost to each axis's velocity, acceleration and jerk limits (s).
    pub axis_time_lost_s: Vec<(String, f64)>,
    /// Feed time (s).
    pub feed_time_s: f64,
    /// Rapid time (s).
    pub rapid_time_s: f64,
    /// Time at the programmed feeds (s).
    pub estimated_time_at_feed_s: f64,
    /// Removal rate (mm^3/s) over the machining time.
    pub removal_rate_mm3_s: f64,
    /// Removal rate in % of the volume to remove per second.
    pub removal_rate_percent_s: f64,
    /// The minimum collision-free stick-out (mm; spec 10.1, L_outil): the
    /// shortest length out of the holder at which the proof's shank and
    /// holder check passes (`scallop_rough5::Proof::min_stick_out`).
    pub min_stick_out_mm: f64,
    /// The move (index in the program) that asks for it; `None` when the
    /// flutes alone suffice.
    pub min_stick_out_move: Option<usize>,
    /// Where its shank or holder meets the stock when a little shorter (mm).
    pub min_stick_out_at_mm: Option<[f64; 3]>,
    /// The finished faces' deviation from the allowance and crest heights
    /// (measured by [`run_rough5`]; empty otherwise).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub faces: Vec<FaceReport>,
}

/// The metrics of one finished face (spec 10.1): the thickness left measured
/// along the face's normal on the proof's tri-dexel stock, at one sample per
/// sub-triangle of at most the ray spacing (`scallop_rough5::face_metrics`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FaceReport {
    /// `bottom` or `flanks`.
    pub face: &'static str,
    /// Its area (mm^2).
    pub area_mm2: f64,
    /// Samples measured.
    pub samples: usize,
    /// Samples within a tool radius of the other face (corners).
    pub corner_samples: usize,
    /// Deviation from the allowance (thickness left less the allowance, mm),
    /// the whole face: minimum, first quartile, median, third quartile, maximum.
    pub deviation_quartiles_mm: [f64; 5],
    /// The same outside the corners (within a tool radius of the other face, a
    /// ray along the normal may run through that face's allowance shell).
    pub deviation_quartiles_outside_corners_mm: [f64; 5],
    /// Crest height (thickness above the allowance, mm), corners excluded: maximum.
    pub crest_max_mm: f64,
    /// Area-weighted mean.
    pub crest_mean_mm: f64,
    /// Area-weighted standard deviation.
    pub crest_sigma_mm: f64,
}

/// The metrics of a plan, its proof and, when the machine took it, its posted
/// program (without one, the time at the programmed feeds).
#[must_use]
pub fn rough5_metrics(plan: &Rough5Plan, proof: &Proof, posted: Option<&Posted>) -> Rough5Metrics {
    let (t, feed, rapid) =
        posted.map_or((plan.estimated_time, plan.estimated_time, 0.0), |p| (p.time.total, p.time.feed, p.time.rapid));
    Rough5Metrics {
        volume_to_remove_mm3: proof.volume_to_remove,
        remaining_volume_mm3: proof.remaining_volume,
        remaining_percent: proof.remaining_percent,
        removed_volume_mm3: proof.removed_volume,
        gouge_volume_mm3: proof.gouge_volume,
        gouge_depth_mm: proof.gouge_depth,
        path_length_dm: proof.cutting_length / 100.0,
        out_of_material_percent: proof.air_percent,
        air_feed_percent: if proof.cutting_length > 0.0 {
            100.0 * proof.air_move_length / proof.cutting_length
        } else {
            0.0
        },
        air_moves: plan.air.map_or(0, |a| a.moves),
        machining_time_s: t,
        axis_time_lost_s: posted.map_or_else(Vec::new, |p| p.axis_time_lost.clone()),
        feed_time_s: feed,
        rapid_time_s: rapid,
        estimated_time_at_feed_s: plan.estimated_time,
        removal_rate_mm3_s: proof.removal_rate(t),
        removal_rate_percent_s: if t > 0.0 { (100.0 - proof.remaining_percent) / t } else { 0.0 },
        min_stick_out_mm: proof.min_stick_out,
        min_stick_out_move: proof.min_stick_out_at.map(|a| a.0),
        min_stick_out_at_mm: proof.min_stick_out_at.map(|a| a.1),
        faces: proof
            .faces
            .iter()
            .map(|f| FaceReport {
                face: f.name,
                area_mm2: f.area,
                samples: f.samples,
                corner_samples: f.corner_samples,
                deviation_quartiles_mm: f.deviation_quartiles,
                deviation_quartiles_outside_corners_mm: f.deviation_quartiles_outside_corners,
                crest_max_mm: f.crest_max,
                crest_mean_mm: f.crest_mean,
                crest_sigma_mm: f.crest_sigma,
            })
            .collect(),
    }
}

/// The settings of `scallop rough5` (docs/rough5.md,
/// [`Rough5Settings::new`]) for a part, a tool radius, a_p, a_e and a feed
/// (mm/min): voxel 1 mm, a 0.5 mm flank allowance, the levels down to the
/// part's bottom.
///
/// # Errors
/// The part has no bottom faces.
pub fn rough5_settings(
    part: &TestPart,
    tool_radius: f64,
    (ap, ae): (f64, f64),
    feed: f64,
) -> Result<Rough5Settings, EngineError> {
    let bottom = part.faces(&[FaceTag::Bottom])?;
    let guides = GuideSettings {
        tool_radius,
        flank_allowance: 0.5,
        axial_step: ap,
        radial_step: ae,
        voxel: 1.0,
        depth: part.stock.max.z - bottom.bounds().min.z,
    };
    Ok(Rough5Settings::new(guides, feed))
}

/// The tool tip's dynamics along a path with the axis fixed on `machine`
/// ([`PathDynamics`], for [`Rough5Settings::entry_dynamics`]): the smallest
/// acceleration and jerk of its linear axes (a helix's circle runs on them
/// whatever its plane) and the controller's corner tolerance; `None` for a
/// machine without linear axes.
///
/// ```
/// let m = scallop_machine::Machine::builtin("ucp710").unwrap();
/// let d = scallop_engine::path_dynamics(&m).unwrap();
/// assert_eq!((d.acceleration, d.jerk, d.corner_tolerance), (2100.0, 5000.0, 0.1));
/// ```
#[must_use]
pub fn path_dynamics(machine: &Machine) -> Option<PathDynamics> {
    let linear: Vec<_> =
        machine.axes().iter().filter(|a| a.kind == scallop_machine::AxisKind::Linear).map(|a| a.dynamics).collect();
    (!linear.is_empty()).then(|| PathDynamics {
        acceleration: linear.iter().map(|d| d.amax).fold(f64::INFINITY, f64::min),
        jerk: linear.iter().map(|d| d.jmax).fold(f64::INFINITY, f64::min),
        corner_tolerance: machine.nc().corner_tolerance,
    })
}

/// A 5-axis roughing operation of a job.
#[derive(Debug, Clone)]
pub struct Rough5Job {
    /// How messages name the part.
    pub part_name: String,
    /// The part: the volume to remove with its faces, the stock box and blank.
    pub part: TestPart,
    /// The tool, with its shank and holder.
    pub tool: Cutter,
    /// The planning settings.
    pub settings: Rough5Settings,
    /// The proof's settings; its `axis_tolerance` is also the gouge allowed.
    pub proof: ProofSettings,
    /// The 5-axis machine.
    pub machine: Machine,
    /// The dialect.
    pub dialect: Dialect,
    /// The program's words.
    pub words: TcpWords,
}

/// Where [`run_rough5`] is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Rough5Step {
    /// Planning: levels done of all.
    Planning {
        /// Done.
        done: usize,
        /// All.
        total: usize,
    },
    /// Proving: bands of the tri-dexel stock done of all.
    Proving {
        /// Done.
        done: usize,
        /// All.
        total: usize,
    },
    /// Through the machine and the post.
    Posting,
}

/// A planned, proven and posted 5-axis roughing operation.
#[derive(Debug, Clone)]
pub struct Rough5Output {
    /// The plan (toolpath, levels, passes).
    pub plan: Rough5Plan,
    /// The tri-dexel proof.
    pub proof: Proof,
    /// The posted program.
    pub posted: Posted,
    /// Its metrics.
    pub metrics: Rough5Metrics,
}

/// Plans, proves and posts a 5-axis roughing operation.
///
/// # Errors
/// The planner refuses (settings, a part without passes); the proof finds a
/// rapid into stock, a shank or holder collision
/// ([`EngineError::Rough5`]) or stock removed outside the volume to remove
/// deeper than the proof's tolerance ([`EngineError::Rough5Gouge`], with its
/// place); the machine or the post refuses the program ([`EngineError::Output`]).
pub fn run_rough5(job: &Rough5Job, progress: &(dyn Fn(Rough5Step) + Sync)) -> Result<Rough5Output, EngineError> {
    let part = &job.part;
    let (bottom, flanks) = (part.faces(&[FaceTag::Bottom])?, part.faces(&[FaceTag::Flank])?);
    // The entries are chosen against the machine's dynamics unless the job set them.
    let settings = Rough5Settings {
        entry_dynamics: job.settings.entry_dynamics.or_else(|| path_dynamics(&job.machine)),
        ..job.settings
    };
    let plan =
        plan_rough5_in(&bottom, &flanks, (&part.stock, part.blank.as_ref()), &job.tool, &settings, &|done, total| {
            progress(Rough5Step::Planning { done, total });
        })?;
    let corner = job.settings.guides.tool_radius;
    let faces = [
        ProofFace { name: "bottom", mesh: &bottom, others: &flanks, allowance: job.settings.bottom_allowance, corner },
        ProofFace {
            name: "flanks",
            mesh: &flanks,
            others: &bottom,
            allowance: job.settings.guides.flank_allowance,
            corner,
        },
    ];
    let proof = prove_with_faces(
        &plan.toolpath,
        &job.tool,
        (&part.stock, part.blank.as_ref()),
        &part.mesh,
        &faces,
        &job.proof,
        &|done, total| progress(Rough5Step::Proving { done, total }),
    )?;
    if proof.gouge_depth > job.proof.axis_tolerance {
        let [x, y, z] = proof.gouge_at.unwrap_or_default();
        return Err(EngineError::Rough5Gouge {
            volume: proof.gouge_volume,
            depth: proof.gouge_depth,
            x,
            y,
            z,
            tolerance: job.proof.axis_tolerance,
        });
    }
    progress(Rough5Step::Posting);
    let kin = Kinematics::new(&job.machine, job.words.tool_length);
    let posted = post_tcp(&kin, &plan.toolpath, &job.dialect, &job.words)?;
    let metrics = rough5_metrics(&plan, &proof, Some(&posted));
    Ok(Rough5Output { plan, proof, posted, metrics })
}
