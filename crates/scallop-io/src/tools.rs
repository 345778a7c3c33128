//! The tool library (`tool_library = "tools.toml"` in a job, docs/job.md "Tool
//! library"): numbered cutters with their shank, holder stack and cutting
//! data, which job operations reference by number (`tool = 3`). Unknown keys
//! are errors with their line; every error names the tool's line and the fix.
//!
//! ```
//! use scallop_io::tools::parse_tool_library;
//! let lib = parse_tool_library(r#"
//! [[tool]]
//! number = 3
//! shape = "ball"
//! diameter = 6
//! flutes = 2
//! flute_length = 18
//! vc = 150     # m/min
//! fz = 0.04    # mm per tooth
//! "#).unwrap();
//! let t = lib.get(3).unwrap();
//! let n = t.spindle_speed().unwrap(); // 1000 vc / (pi D)
//! assert!((n - 1000.0 * 150.0 / (std::f64::consts::PI * 6.0)).abs() < 1e-9);
//! assert!((t.feed().unwrap() - 0.04 * 2.0 * n).abs() < 1e-9);
//! ```

use serde::Deserialize;

use crate::job::{CutterSpec, HolderSpec, JobError, ShapeWord, check_cutter, key_at, line_of};

/// A tool library: tools by number.
#[derive(Debug, Clone, PartialEq)]
pub struct ToolLibrary {
    /// The tools in file order, with the 1-based line of their `[[tool]]` header.
    pub tools: Vec<(ToolSpec, usize)>,
}

#[derive(Debug, Clone, Deserialize)]
struct RawLibrary {
    #[serde(default)]
    tool: Vec<ToolSpec>,
}

/// `[[tool]]`: one cutter, its shank and holder, and its cutting data.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct ToolSpec {
    /// The number jobs use (`tool = 3`) and the program's `T3 M6`.
    pub number: u32,
    /// Description, e.g. `"ball D6 carbide 2F"`.
    #[serde(default)]
    pub name: String,
    /// `flat`, `ball`, `bull` or `cone`.
    pub shape: ShapeWord,
    /// Cutting diameter D (mm); for a cone, the diameter at the top of the cone.
    pub diameter: f64,
    /// Corner radius r (mm, bull only).
    pub corner_radius: Option<f64>,
    /// Included tip angle (degrees, cone only; 90 for a 90° V cutter).
    pub angle_deg: Option<f64>,
    /// Number of teeth (flutes).
    pub flutes: u32,
    /// Flute (cutting) length (mm).
    pub flute_length: f64,
    /// Shank diameter (mm; default D).
    pub shank_diameter: Option<f64>,
    /// Shank length above the flutes (mm; default the flute length).
    pub shank_length: Option<f64>,
    /// Holder stack, bottom segment first (`[[tool.holder]]`).
    #[serde(default)]
    pub holder: Vec<HolderSpec>,
    /// Cutting speed Vc (m/min); the spindle speed is `1000 Vc / (pi D)`.
    pub vc: Option<f64>,
    /// Spindle speed (1/min), instead of `vc`.
    pub spindle: Option<f64>,
    /// Feed per tooth f_z (mm); the feed is `f_z * flutes * n` (mm/min).
    pub fz: Option<f64>,
    /// Largest axial depth of cut a_p (mm).
    pub max_ap: Option<f64>,
    /// Largest radial engagement a_e (mm).
    pub max_ae: Option<f64>,
}

impl ToolSpec {
    /// The spindle speed n (1/min): `spindle`, else `1000 Vc / (pi D)` from the
    /// nominal diameter; `None` without cutting speed data.
    #[must_use]
    pub fn spindle_speed(&self) -> Option<f64> {
        self.spindle.or_else(|| self.vc.map(|vc| 1000.0 * vc / (std::f64::consts::PI * self.diameter)))
    }

    /// The feed (mm/min): `f_z * flutes * n`; `None` without `fz` or a spindle speed.
    #[must_use]
    pub fn feed(&self) -> Option<f64> {
        Some(self.fz? * f64::from(self.flutes) * self.spindle_speed()?)
    }

    /// The cutter as a job's `[cutter]` table.
    #[must_use]
    pub fn cutter(&self) -> CutterSpec {
        CutterSpec {
            shape: self.shape,
            diameter: self.diameter,
            corner_radius: self.corner_radius,
            flute_length: Some(self.flute_length),
            angle_deg: self.angle_deg,
            shank_diameter: self.shank_diameter,
            shank_length: self.shank_length,
            holder: self.holder.clone(),
        }
    }
}

impl ToolLibrary {
    /// The tool numbered `number`.
    #[must_use]
    pub fn get(&self, number: u32) -> Option<&ToolSpec> {
        self.tools.iter().map(|(t, _)| t).find(|t| t.number == number)
    }

    /// The tool numbers, in file order.
    #[must_use]
    pub fn numbers(&self) -> Vec<u32> {
        self.tools.iter().map(|(t, _)| t.number).collect()
    }
}

/// Why a tool library is unusable.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ToolError {
    /// Syntax, unknown key, missing key or wrong type (line and column included).
    #[error("{0}")]
    Toml(String),
    /// Keys that name no setting, all of them, with their lines.
    #[error("unknown keys {}: check their spelling against docs/job.md (Tool library)", keys.join(", "))]
    UnknownKeys {
        /// Each key's dotted path, with its line when found.
        keys: Vec<String>,
    },
    /// Two tools with one number.
    #[error("line {line}: tool {number} is defined twice (first at line {first}): give each tool its own number")]
    Duplicate {
        /// The number.
        number: u32,
        /// The second definition's line.
        line: usize,
        /// The first definition's line.
        first: usize,
    },
    /// A value that makes no sense.
    #[error("line {line}: tool {number}: `{key}` = {value}: {fix}")]
    Value {
        /// The `[[tool]]` header's line.
        line: usize,
        /// The tool number.
        number: u32,
        /// The key.
        key: &'static str,
        /// The value given.
        value: String,
        /// What to do.
        fix: &'static str,
    },
}

/// The 1-based lines of the `[[tool]]` headers.
fn tool_lines(text: &str) -> Vec<usize> {
    text.lines().enumerate().filter(|(_, l)| l.trim_start().starts_with("[[tool]]")).map(|(i, _)| i + 1).collect()
}

/// Parses and checks a tool library.
///
/// # Errors
/// [`ToolError`] naming the line and the fix.
pub fn parse_tool_library(text: &str) -> Result<ToolLibrary, ToolError> {
    let toml_error = |e: toml::de::Error| {
        let message = e.to_string().trim_end().to_string();
        match e.span().and_then(|span| key_at(text, span.start)) {
            Some(key) => ToolError::Toml(format!("`{key}`: {message}")),
            None => ToolError::Toml(message),
        }
    };
    let de = toml::Deserializer::parse(text).map_err(toml_error)?;
    let mut unknown = Vec::new();
    let raw: RawLibrary =
        serde_ignored::deserialize(de, |path| unknown.push(path.to_string().replace(".?", ""))).map_err(toml_error)?;
    if !unknown.is_empty() {
        let keys = unknown
            .iter()
            .map(|path| match line_of(text, path) {
                Some(line) => format!("`{path}` (line {line})"),
                None => format!("`{path}`"),
            })
            .collect();
        return Err(ToolError::UnknownKeys { keys });
    }
    let lines = tool_lines(text);
    let mut tools: Vec<(ToolSpec, usize)> = Vec::with_capacity(raw.tool.len());
    for (k, tool) in raw.tool.into_iter().enumerate() {
        let line = lines.get(k).copied().unwrap_or(0);
        if let Some((_, first)) = tools.iter().find(|(t, _)| t.number == tool.number) {
            return Err(ToolError::Duplicate { number: tool.number, line, first: *first });
        }
        check_tool(&tool).map_err(|e| match e {
            JobError::Value { key, value, fix } => ToolError::Value { line, number: tool.number, key, value, fix },
            other => ToolError::Toml(format!("line {line}: tool {}: {other}", tool.number)),
        })?;
        tools.push((tool, line));
    }
    Ok(ToolLibrary { tools })
}

/// The checks of one tool: its cutter as a job's, then its cutting data.
fn check_tool(tool: &ToolSpec) -> Result<(), JobError> {
    let bad = |key, value: f64, fix| Err(JobError::Value { key, value: value.to_string(), fix });
    check_cutter(&tool.cutter())?;
    if tool.flutes == 0 || tool.flutes > 64 {
        return Err(JobError::Value { key: "flutes", value: tool.flutes.to_string(), fix: "give 1 to 64 teeth" });
    }
    if tool.vc.is_some() && tool.spindle.is_some() {
        return Err(JobError::Value {
            key: "vc",
            value: "given with spindle".into(),
            fix: "give either the cutting speed vc (m/min) or the spindle speed (1/min)",
        });
    }
    for (key, v) in
        [("vc", tool.vc), ("spindle", tool.spindle), ("fz", tool.fz), ("max_ap", tool.max_ap), ("max_ae", tool.max_ae)]
    {
        if let Some(v) = v
            && !(v.is_finite() && v > 0.0)
        {
            return bad(key, v, "must be a finite number > 0 (vc m/min, spindle 1/min, fz, max_ap, max_ae mm)");
        }
    }
    if let Some(n) = tool.spindle_speed()
        && n > MAX_SPINDLE
    {
        return bad("vc", n, "the spindle speed it gives is over 200 000 1/min: check vc (m/min) and the diameter");
    }
    Ok(())
}

/// Largest spindle speed accepted (1/min): above any milling spindle, so a
/// cutting speed given in m/s or a diameter in metres is caught.
pub const MAX_SPINDLE: f64 = 200_000.0;

#[cfg(test)]
#[allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]
mod tests {
    use super::*;

    const LIB: &str = "[[tool]]\nnumber = 1\nshape = \"flat\"\ndiameter = 10\nflutes = 3\nflute_length = 22\nvc = 200\nfz = 0.05\n\
        [[tool]]\nnumber = 4\nshape = \"cone\"\ndiameter = 6\nangle_deg = 90\nflutes = 2\nflute_length = 8\nspindle = 18000\nfz = 0.02\n\
        [[tool.holder]]\nlength = 40\ndiameter = 32\n";

    #[test]
    fn cutting_data_follow_the_formulas() {
        let lib = parse_tool_library(LIB).unwrap();
        assert_eq!(lib.numbers(), vec![1, 4]);
        let flat = lib.get(1).unwrap();
        let n = flat.spindle_speed().unwrap();
        assert!((n * std::f64::consts::PI * 10.0 / 1000.0 - 200.0).abs() < 1e-9);
        assert!((flat.feed().unwrap() - 0.05 * 3.0 * n).abs() < 1e-9);
        let cone = lib.get(4).unwrap();
        assert_eq!((cone.spindle_speed(), cone.holder.len()), (Some(18000.0), 1));
        assert!((cone.feed().unwrap() - 0.02 * 2.0 * 18000.0).abs() < 1e-9);
        assert_eq!(lib.tools[1].1, 9);
    }

    /// Jobs take a library tool's cutter, speed and feed where they give none.
    #[test]
    fn jobs_resolve_library_tools() {
        use crate::job::{parse_job, parse_job_with_tools};
        let lib = parse_tool_library(LIB).unwrap();
        let single = "tool_library = \"t.toml\"\n[part]\nbuiltin = \"choi\"\n[finishing]\nscallop_height = 0.01\n[output]\ntool = 1\n";
        let job = parse_job_with_tools(single, Some(&lib)).unwrap();
        assert_eq!((job.cutter.shape, job.cutter.diameter), (ShapeWord::Flat, 10.0));
        assert_eq!(job.operations[0].spindle, lib.get(1).unwrap().spindle_speed());
        // A library named but not read, and a job without cutter or library.
        assert!(parse_job(single).unwrap_err().to_string().contains("tool_library"));
        let err = parse_job(&single.replace("tool_library = \"t.toml\"\n", "")).unwrap_err().to_string();
        assert!(err.contains("cutter"), "{err}");
        // An operation with its own cutter keeps it (its number need not be in the library);
        // an operation's own spindle and feed win over the library's.
        let ops = "tool_library = \"t.toml\"\n[part]\nbuiltin = \"choi\"\n\
            [[operation]]\nkind = \"finish\"\ntool = 9\n[operation.cutter]\nshape = \"ball\"\ndiameter = 6\n[operation.finishing]\nscallop_height = 0.01\n\
            [[operation]]\nkind = \"finish\"\ntool = 4\nspindle = 9000\nfeed = 700\n[operation.finishing]\nscallop_height = 0.01\n";
        let job = parse_job_with_tools(ops, Some(&lib)).unwrap();
        assert_eq!((job.operations[0].cutter.diameter, job.operations[0].spindle), (6.0, None));
        let cone = &job.operations[1];
        assert_eq!(
            (cone.cutter.shape, cone.cutter.angle_deg, cone.spindle, cone.feed),
            (ShapeWord::Cone, Some(90.0), Some(9000.0), Some(700.0))
        );
        assert_eq!(cone.cutter.holder.len(), 1);
    }

    #[test]
    fn bad_libraries_name_the_line_and_the_key() {
        let cases = [
            (LIB.replace("diameter = 10", "diameter = -10"), "line 1: tool 1: `cutter.diameter`"),
            (LIB.replace("number = 4", "number = 1"), "line 9: tool 1 is defined twice (first at line 1)"),
            (LIB.replace("flutes = 3", "flutes = 0"), "`flutes`"),
            (LIB.replace("vc = 200", "vc = 200\nspindle = 9000"), "either the cutting speed"),
            (LIB.replace("fz = 0.05", "fz = -1"), "`fz`"),
            (LIB.replace("angle_deg = 90", "angle_deg = 190"), "line 9: tool 4: `cutter.angle_deg`"),
            (LIB.replace("vc = 200", "vc = 2000000"), "over 200 000"),
            (LIB.replace("fz = 0.05", "feed_per_tooth = 0.05"), "feed_per_tooth` (line 8)"),
            (LIB.replace("shape = \"flat\"", "shape = \"drill\""), "shape"),
        ];
        for (text, want) in cases {
            let err = parse_tool_library(&text).unwrap_err().to_string();
            assert!(err.contains(want), "{want}: {err}");
        }
    }
}
