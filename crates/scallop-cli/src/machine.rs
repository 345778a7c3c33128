//! The machine a job names (`machine = "..."` or `[machine] description = "..."`,
//! docs/job.md, "Machine"): loaded by shipped name or from a file, its kinematics put
//! into the job, its dialect the default one, spindle speeds checked against its
//! largest, and the program checked against its travel.

use std::path::Path;

use scallop_geom::Point3;
use scallop_io::job::JobFile;
use scallop_machine::{Described, Machine};

use crate::{CliResult, Failure};

/// A machine by shipped name or by TOML file (a relative path taken from `folder`:
/// the job file's folder, or the working folder for `--machine`); `what` names the
/// flag or key in messages. Unknown names list the shipped ones.
pub(crate) fn load_described(name: &str, folder: &Path, what: &str) -> CliResult<Described> {
    let path = folder.join(name);
    if name.ends_with(".toml") || path.is_file() {
        let text = crate::input::read_text(&path, "the file")?;
        Described::from_toml_str(&text).map_err(|e| Failure::rejected(format!("{} ({what}): {e}", path.display())))
    } else {
        Described::builtin(name).map_err(|_| {
            Failure::rejected(format!(
                "{what} = \"{name}\": no shipped machine of that name; give one of {} or a machine file (.toml, \
                 docs/machine.md)",
                Described::builtin_names().join(", ")
            ))
        })
    }
}

/// A 5-axis machine by shipped name or file, for `post --machine` and `[setup] machine`:
/// a 3-axis description is refused naming the 5-axis ones.
pub(crate) fn load_five_axis(name: &str, folder: &Path, what: &str) -> CliResult<Machine> {
    let is_file = name.ends_with(".toml") || folder.join(name).is_file();
    if !is_file && Described::builtin(name).is_err() {
        return Err(Failure::rejected(format!(
            "{what} = \"{name}\": no shipped 5-axis machine of that name; give one of {} or a machine file (.toml, \
             docs/machine.md)",
            Machine::builtin_names().join(", ")
        )));
    }
    match load_described(name, folder, what)? {
        Described::FiveAxis(m) => Ok(m),
        Described::ThreeAxis(m) => Err(Failure::rejected(format!(
            "{what} = \"{name}\": `{}` is a 3-axis machine and this needs a 5-axis one; give one of {} or a 5-axis \
             machine file (3-axis machines are named by a job's `machine` key, docs/job.md)",
            m.name(),
            Machine::builtin_names().join(", ")
        ))),
    }
}

/// The machine `spec` names, if any (relative paths from `folder`, the job file's).
pub(crate) fn job_machine(spec: &JobFile, folder: &Path) -> CliResult<Option<Described>> {
    spec.machine.description.as_deref().map(|name| load_described(name, folder, "machine")).transpose()
}

/// The shipped post dialect of a machine's controller, for 3-axis output (a Heidenhain
/// control gets its ISO mode, the 3-axis writer's syntax; a plain ISO control Fanuc's words).
fn dialect_name(d: scallop_machine::Dialect) -> &'static str {
    use scallop_machine::Dialect as D;
    match d {
        D::Iso | D::Fanuc => "fanuc",
        D::Linuxcnc => "linuxcnc",
        D::Siemens840d => "siemens840d",
        D::Heidenhain => "heidenhain-iso",
        D::Grbl => "grbl",
    }
}

/// Puts the named machine into the job: its acceleration, jerk and rapid rate
/// (the smallest over the linear axes), the feeds capped at its largest feed
/// velocity, its dialect where `[output]` gives none, and every spindle speed
/// checked against its largest: a speed from the tool library's cutting data is
/// clamped (and a feed from the same data scaled with it, keeping the feed per
/// tooth), a speed the job gives is refused. Returns notes for what was changed.
pub(crate) fn apply(spec: &mut JobFile, m: &Described) -> CliResult<Vec<String>> {
    let mut notes = Vec::new();
    let d = m.linear_dynamics();
    spec.machine.acceleration = d.amax / 1000.0; // mm/s² -> m/s²
    spec.machine.jerk = d.jmax / 1000.0; // mm/s³ -> m/s³
    spec.machine.rapid = d.rapid * 60.0 / 1000.0; // mm/s -> m/min
    let vmax = d.vmax * 60.0; // mm/s -> mm/min
    if spec.machine.feed * 1000.0 > vmax && spec.operations.iter().any(|o| o.feed.is_none()) {
        notes.push(format!(
            "machine.feed {} m/min capped at machine `{}`'s largest feed, {:.0} mm/min",
            spec.machine.feed,
            m.name(),
            vmax
        ));
        spec.machine.feed = vmax / 1000.0;
    }
    if spec.output.dialect.is_none() {
        spec.output.dialect = Some(dialect_name(m.nc().dialect).to_string());
    }
    let output_spindle = spec.output.spindle;
    for (k, op) in spec.operations.iter_mut().enumerate() {
        let place = format!("operation {} (`{}`)", k + 1, op.name);
        if let Some(max) = m.max_spindle_speed() {
            let n = op.spindle.unwrap_or(output_spindle);
            if n > max && op.spindle_from_library {
                let scale = max / n;
                notes.push(format!(
                    "{place}: spindle {n:.0} 1/min from the tool library's cutting data clamped to machine `{}`'s \
                     largest, {max:.0} 1/min{}",
                    m.name(),
                    if op.feed_from_library { " (its feed scaled by the same factor, keeping f_z)" } else { "" }
                ));
                op.spindle = Some(max);
                if op.feed_from_library {
                    op.feed = op.feed.map(|f| f * scale);
                }
            } else if n > max {
                return Err(Failure::rejected(format!(
                    "{place}: spindle {n:.0} 1/min is above machine `{}`'s largest speed, {max:.0} 1/min \
                     (spindle.max_speed of its file): refused; give at most {max:.0} (`spindle` of the operation or \
                     [output] spindle), or take the speed from the tool library (clamped there)",
                    m.name()
                )));
            }
        }
        if let Some(f) = op.feed
            && f > vmax
        {
            notes.push(format!("{place}: feed {f:.0} mm/min capped at machine `{}`'s largest, {vmax:.0}", m.name()));
            op.feed = Some(vmax);
        }
    }
    Ok(notes)
}

/// Gives a machine without a tool changer a manual change: a comment naming the
/// tool and a pause (`M0`) instead of the dialect's `T.. M6`.
pub(crate) fn manual_tool_change(dialect: &mut scallop_post::Dialect, m: &Described) {
    if !m.nc().tool_changer {
        let (open, close) = (&dialect.comment.0, &dialect.comment.1);
        dialect.tool_change = vec![format!("{open}tool change: load tool {{tool}}, then resume{close}"), "M0".into()];
    }
}

/// Checks the program's tool-tip positions against the machine's travel.
pub(crate) fn check_travel(m: &Described, points: impl IntoIterator<Item = Point3>) -> CliResult<()> {
    m.check_travel(points).map_err(|e| Failure::rejected(format!("machine `{}`: {e}", m.name())))
}
