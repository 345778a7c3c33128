//! Machines as a job names them (docs/job.md, "Machine"): a 3-axis mill ([`Mill`],
//! three linear axes, no rotary) or a 5-axis [`Machine`], behind one type,
//! [`Described`], that gives what 3-axis work needs of either: the linear axes' travel
//! and dynamics, the controller's dialect and tool changer, the largest spindle speed,
//! and the check that a program stays inside the travel.
//!
//! ```
//! use scallop_geom::Point3;
//! use scallop_machine::Described;
//! let m = Described::builtin("grbl-3axis")?;
//! assert!(!m.nc().tool_changer && m.max_spindle_speed().is_some());
//! assert!(m.check_travel([Point3::new(0.0, 0.0, 5.0)]).is_ok());
//! let err = m.check_travel([Point3::new(0.0, 0.0, 500.0)]).unwrap_err().to_string();
//! assert!(err.contains("axis Z") && err.contains("part_frame.origin"), "{err}");
//! assert!(Described::builtin("mx330").is_ok()); // the 5-axis machines too
//! # Ok::<(), scallop_machine::MachineError>(())
//! ```

use scallop_geom::Point3;
use scallop_geom::nalgebra::Isometry3;

use crate::desc::{self, AxisKind, ChainSide, RawMachine};
use crate::error::MachineError;
use crate::{Axis, Dynamics, Machine, Nc, tol};

/// The 3-axis descriptions shipped in `machines/`, by short name.
const BUILTIN_3AXIS: &[(&str, &str)] = &[
    ("generic-3axis", include_str!("../../../machines/generic-3axis.toml")),
    ("linuxcnc-3axis", include_str!("../../../machines/linuxcnc-3axis.toml")),
    ("fanuc-3axis", include_str!("../../../machines/fanuc-3axis.toml")),
    ("grbl-3axis", include_str!("../../../machines/grbl-3axis.toml")),
];

/// A 3-axis mill: three linear axes (no rotary), their strokes and dynamics, the part
/// frame (where the part's zero sits in machine coordinates), the spindle's largest
/// speed and the controller.
///
/// # Invariants
/// - Exactly 3 linear axes with independent unit directions, stored sorted by name.
/// - Every stroke has `min < max`; every dynamic limit is positive and finite.
#[derive(Clone, Debug, PartialEq)]
pub struct Mill {
    name: String,
    source: String,
    axes: Vec<Axis>,
    part_frame: Isometry3<f64>,
    gauge_point: Point3,
    max_spindle_speed: Option<f64>,
    nc: Nc,
}

impl Mill {
    /// The machine's name.
    #[must_use]
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Checks a description of three linear axes (chains optional: every axis on
    /// the tool side when absent; no spindle geometry needed).
    fn validate(raw: &RawMachine) -> Result<Mill, MachineError> {
        let max_spindle_speed = desc::check_schema_and_spindle(raw)?;
        let names: Vec<&String> = raw.axes.keys().collect();
        if names.len() != 3 || raw.axes.values().any(|a| a.kind != AxisKind::Linear) {
            return Err(MachineError::Unsupported {
                place: "axes".into(),
                what: format!("a machine of {} axes", names.len()),
                fix: "describe 3 linear axes (a mill) or 3 linear and 2 rotary axes (5-axis)".into(),
            });
        }
        let axes = names.iter().map(|n| desc::axis_of(raw, n)).collect::<Result<Vec<_>, _>>()?;
        desc::check_dynamics_keys(raw)?;
        desc::check_linear_independence(&axes)?;
        if let Some(a) = raw.spindle_tool_axis() {
            desc::unit_direction(a, "spindle.tool_axis")?;
        }
        let gauge_point = match raw.spindle_gauge_point() {
            Some(g) => desc::point_in_range(g, "spindle.gauge_point")?,
            None => Point3::origin(),
        };
        let part_frame = desc::part_frame_of(raw.part_frame.as_ref())?;
        desc::check_controller(&raw.nc, &crate::Tcp::default())?;
        Ok(Mill {
            name: raw.name.clone(),
            source: raw.source.clone(),
            axes,
            part_frame,
            gauge_point,
            max_spindle_speed,
            nc: raw.nc.clone(),
        })
    }
}

/// A machine description of either kind.
#[derive(Clone, Debug, PartialEq)]
pub enum Described {
    /// Three linear axes.
    ThreeAxis(Mill),
    /// Three linear and two rotary axes.
    FiveAxis(Machine),
}

impl Described {
    /// Parses and validates a `scallop.machine/1` description of a 3-axis mill (three
    /// linear axes; `chains` and `spindle` geometry optional) or a 5-axis machine.
    ///
    /// # Errors
    /// [`MachineError`] naming the line or the field and the fix.
    pub fn from_toml_str(text: &str) -> Result<Described, MachineError> {
        let raw = desc::parse_raw(text)?;
        if raw.axes.values().any(|a| a.kind == AxisKind::Rotary) {
            Machine::from_toml_str(text).map(Described::FiveAxis)
        } else {
            Mill::validate(&raw).map(Described::ThreeAxis)
        }
    }

    /// A shipped description by short name: the 3-axis mills `generic-3axis`,
    /// `linuxcnc-3axis`, `fanuc-3axis`, `grbl-3axis`, and the 5-axis machines of
    /// [`Machine::builtin_names`].
    ///
    /// # Errors
    /// [`MachineError::BadInput`] for an unknown name, listing the known ones.
    pub fn builtin(short_name: &str) -> Result<Described, MachineError> {
        match BUILTIN_3AXIS.iter().find(|(n, _)| *n == short_name) {
            Some((_, text)) => Self::from_toml_str(text),
            None if desc::BUILTIN.iter().any(|(n, _)| *n == short_name) => {
                Machine::builtin(short_name).map(Described::FiveAxis)
            }
            None => Err(MachineError::BadInput {
                place: "machine".into(),
                problem: format!("no shipped machine named `{short_name}`"),
                fix: format!("use one of {}, or a machine file (.toml)", Self::builtin_names().join(", ")),
            }),
        }
    }

    /// Short names accepted by [`Described::builtin`]: the 3-axis mills, then the
    /// 5-axis machines.
    ///
    /// ```
    /// let names = scallop_machine::Described::builtin_names();
    /// assert!(names.contains(&"linuxcnc-3axis") && names.contains(&"mx330"));
    /// ```
    #[must_use]
    pub fn builtin_names() -> Vec<&'static str> {
        BUILTIN_3AXIS.iter().chain(desc::BUILTIN).map(|(n, _)| *n).collect()
    }

    /// The machine's name.
    #[must_use]
    pub fn name(&self) -> &str {
        match self {
            Described::ThreeAxis(m) => &m.name,
            Described::FiveAxis(m) => m.name(),
        }
    }

    /// Where the values come from.
    #[must_use]
    pub fn source(&self) -> &str {
        match self {
            Described::ThreeAxis(m) => &m.source,
            Described::FiveAxis(m) => m.source(),
        }
    }

    /// The three linear axes, sorted by name.
    #[must_use]
    pub fn linear_axes(&self) -> &[Axis] {
        match self {
            Described::ThreeAxis(m) => &m.axes,
            Described::FiveAxis(m) => &m.axes()[..3],
        }
    }

    /// Controller conventions (dialect, tool changer, ...).
    #[must_use]
    pub fn nc(&self) -> &Nc {
        match self {
            Described::ThreeAxis(m) => &m.nc,
            Described::FiveAxis(m) => m.nc(),
        }
    }

    /// The largest spindle speed (1/min), when the description gives it.
    #[must_use]
    pub fn max_spindle_speed(&self) -> Option<f64> {
        match self {
            Described::ThreeAxis(m) => m.max_spindle_speed,
            Described::FiveAxis(m) => m.max_spindle_speed(),
        }
    }

    /// The limits 3-axis motion can count on: for each of velocity, acceleration,
    /// jerk and rapid velocity, the smallest over the linear axes (mm/s, mm/s²,
    /// mm/s³, mm/s), since a move along any direction may load any axis fully.
    ///
    /// ```
    /// let d = scallop_machine::Described::builtin("generic-3axis").unwrap().linear_dynamics();
    /// assert!(d.vmax > 0.0 && d.amax > 0.0 && d.jmax > 0.0 && d.rapid >= d.vmax);
    /// ```
    #[must_use]
    pub fn linear_dynamics(&self) -> Dynamics {
        let axes = self.linear_axes();
        let min = |f: fn(&Dynamics) -> f64| axes.iter().map(|a| f(&a.dynamics)).fold(f64::INFINITY, f64::min);
        Dynamics { vmax: min(|d| d.vmax), amax: min(|d| d.amax), jmax: min(|d| d.jmax), rapid: min(|d| d.rapid) }
    }

    /// The NC words of the linear axes (mm, in [`Described::linear_axes`] order) that
    /// bring the tool tip to `p` (part frame) with the rotaries at zero: the part frame
    /// places `p` in the machine frame, and each axis covers its share of the distance
    /// from the gauge point (tool-side axes move the tool towards `p`, part-side axes
    /// move `p` to the tool); exact for mutually orthogonal linear directions.
    #[must_use]
    pub fn linear_words(&self, p: Point3) -> [f64; 3] {
        let (frame, gauge) = match self {
            Described::ThreeAxis(m) => (&m.part_frame, m.gauge_point),
            Described::FiveAxis(m) => (m.part_frame(), m.gauge_point()),
        };
        let offset = frame * p - gauge;
        let axes = self.linear_axes();
        std::array::from_fn(|i| {
            let side = if axes[i].side == ChainSide::Tool { 1.0 } else { -1.0 };
            axes[i].nc_sign * side * axes[i].direction.dot(&offset)
        })
    }

    /// Checks that the tool tip stays inside the linear axes' travel at every point
    /// (part frame, mm; the controller's tool-length offset is not counted).
    ///
    /// # Errors
    /// [`MachineError::OutOfTravel`] for the first axis (in name order) that leaves its
    /// stroke, with the program's extent on that axis and the fix.
    pub fn check_travel(&self, points: impl IntoIterator<Item = Point3>) -> Result<(), MachineError> {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in points {
            let w = self.linear_words(p);
            for i in 0..3 {
                lo[i] = lo[i].min(w[i]);
                hi[i] = hi[i].max(w[i]);
            }
        }
        for (i, axis) in self.linear_axes().iter().enumerate() {
            let Some((min, max)) = axis.limits else { continue };
            if lo[i] > hi[i] || (lo[i] >= min - tol::LIMIT_SLACK && hi[i] <= max + tol::LIMIT_SLACK) {
                continue;
            }
            let value = if lo[i] < min - tol::LIMIT_SLACK { lo[i] } else { hi[i] };
            let fix = if hi[i] - lo[i] > max - min {
                format!(
                    "the program spans {:.3} mm on {}, more than the travel ({:.3} mm): cut the part in several \
                     setups, lower the clearance or the stock, or choose a machine with more travel",
                    hi[i] - lo[i],
                    axis.name,
                    max - min
                )
            } else {
                format!(
                    "the program spans {:.3} to {:.3} mm on {}: move the part zero (`part_frame.origin` of the \
                     machine file, where the job's origin sits in machine coordinates) by {:.3} mm along {}",
                    lo[i],
                    hi[i],
                    axis.name,
                    if value < min { min - lo[i] } else { max - hi[i] },
                    axis.name
                )
            };
            return Err(MachineError::OutOfTravel { axis: axis.name.clone(), value, min, max, fix });
        }
        Ok(())
    }
}
