//! Controller dialects as data ([`Dialect`]), loadable from TOML, with built-ins
//! shipped as files in `crates/scallop-post/dialects/`.

use std::collections::BTreeMap;

use serde::Deserialize;

use crate::error::PostError;

/// Block syntax family.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Syntax {
    /// ISO 6983 words (`G1 X.. Y.. F..`): LinuxCNC, Fanuc, Sinumerik, grbl, Heidenhain ISO mode.
    #[default]
    Iso,
    /// Heidenhain plain language (`L X+.. Y+.. FMAX`), every line numbered from 0.
    Heidenhain,
}

/// How a feed move's duration is written when the rotaries move (spec 3.9).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FeedByTime {
    /// No inverse time: G94 with `F = L_ctrl / T` (the machine's `nc.g94_feed_norm`).
    #[default]
    None,
    /// `G93` inverse time (`F = 1/T` in 1/min, rounded down), back to `G94` before rapids and at the end.
    G93,
    /// Heidenhain `FT`: the block time in seconds (rounded up).
    BlockSeconds,
}

/// Tilted-work-plane codes (spec 3.13).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TiltedPlane {
    /// No tilted-plane code: 3+2 work is written in joint space with the rotaries held (spec 3.13 (a)).
    #[default]
    None,
    /// Fanuc `G68.2 X Y Z I J K` (Euler Z-X-Z) + `G53.1`, cancelled by `G69`.
    G68_2,
    /// Sinumerik `CYCLE800` axis by axis (X, then the new Y, then the new Z: mode 57), cancelled by `CYCLE800()`.
    Cycle800,
    /// Heidenhain `PLANE SPATIAL SPA SPB SPC TURN ... SEQ±`, cancelled by `PLANE RESET STAY`.
    PlaneSpatial,
}

/// How `G2`/`G3` arcs give their centre.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ArcWords {
    /// `I J K`: the centre as an offset from the start (incremental, the ISO default of
    /// LinuxCNC, Fanuc and grbl), two of them per plane (`G17` I J, `G18` I K, `G19` J K).
    #[default]
    Ijk,
    /// `R`: the radius (arcs under a half turn only, as written by scallop).
    Radius,
}

/// Line numbering (`N10`, `N20`, ... or Heidenhain's `0`, `1`, ...).
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LineNumbers {
    /// Text before the number (`N`, or empty for Heidenhain).
    pub prefix: String,
    /// First number.
    pub start: u64,
    /// Increment.
    pub step: u64,
}

/// Word templates for rotary axes written modulo 360 (`{axis}` and `{value}` are replaced).
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModuloWords {
    /// Shortest-path word (Sinumerik `{axis}=DC({value})`).
    pub shortest: String,
    /// Positive-direction word (Sinumerik `{axis}=ACP({value})`), for `modulo360_signed` axes.
    pub positive: String,
    /// Negative-direction word (Sinumerik `{axis}=ACN({value})`).
    pub negative: String,
}

/// TCP (tool centre point) on/off lines. Templates: `{tool}`, and `{machine_tcp_on}` /
/// `{machine_tcp_off}` for the codes of the machine description's `[tcp]` (LinuxCNC's
/// remapped M-codes are configuration-specific, never hard-coded).
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TcpCodes {
    /// Lines that switch TCP on (after the tool change).
    pub on: Vec<String>,
    /// Lines that switch it off (before the footer).
    pub off: Vec<String>,
}

fn four() -> usize {
    4
}
fn three() -> usize {
    3
}
fn five() -> usize {
    5
}
fn yes() -> bool {
    true
}
fn default_header_comments() -> Vec<String> {
    [
        "scallop {version}, program {program}, dialect {dialect}",
        "machine {machine}, output mode {mode}",
        "tool T{tool}, {tool_length}",
        "tolerances: path {tol_pos} mm, tool axis {tol_ang} deg",
        "predicted time {time}",
    ]
    .iter()
    .map(|s| (*s).to_string())
    .collect()
}

/// A controller dialect as data. Templates in `header`, `footer`, `tool_change`,
/// `length_offset`, `header_comments` and `tcp` take `{program}`, `{dialect}`,
/// `{machine}`, `{mode}`, `{tool}`, `{tool_length}`, `{tol_pos}`, `{tol_ang}`, `{time}`,
/// `{spindle}` and `{version}` (unknown names are left as written).
/// [`write_gcode`](crate::write_gcode) (3-axis toolpaths) uses only `name`, `decimals`,
/// `comment`, `header` and `footer`.
///
/// ```
/// let d = scallop_post::Dialect::builtin("siemens840d").unwrap();
/// assert_eq!(d.decimals, 4);
/// assert!(scallop_post::Dialect::builtin("fanuc").unwrap().tcp.is_some());
/// ```
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Dialect {
    /// Name, printed in the header.
    pub name: String,
    /// Block syntax.
    #[serde(default)]
    pub syntax: Syntax,
    /// Decimals of linear words (mm).
    pub decimals: usize,
    /// Decimals of rotary words (deg) and tilted-plane angles.
    #[serde(default = "four")]
    pub rotary_decimals: usize,
    /// Decimals of G94 feed words (mm/min), rounded down.
    #[serde(default)]
    pub feed_decimals: usize,
    /// Decimals of inverse-time words (G93 F rounded down; `FT` seconds rounded up).
    #[serde(default = "three")]
    pub inverse_time_decimals: usize,
    /// Write `+` before positive numbers (Heidenhain).
    #[serde(default)]
    pub explicit_plus: bool,
    /// Comment delimiters (`(` `)`, or `;` and an empty closer).
    pub comment: (String, String),
    /// Comment lines at the top (templates).
    #[serde(default = "default_header_comments")]
    pub header_comments: Vec<String>,
    /// Code lines before the first move (templates).
    #[serde(default)]
    pub header: Vec<String>,
    /// Code lines after the last move (templates).
    #[serde(default)]
    pub footer: Vec<String>,
    /// Tool change lines (templates); empty for controllers without a changer.
    #[serde(default)]
    pub tool_change: Vec<String>,
    /// Tool-length offset lines, written in joint and tilted-plane output when the machine
    /// applies the length in the controller (`tool_length_mode = "controller"`).
    #[serde(default)]
    pub length_offset: Vec<String>,
    /// Lines written before joint-space and tilted-plane output so that the controller is
    /// in its joint (identity) kinematics whatever state a previous program left it in
    /// (e.g. `["{machine_tcp_off}"]`: LinuxCNC's M429); empty lines are skipped. The
    /// reader takes them as TCP off.
    #[serde(default)]
    pub joint_kinematics: Vec<String>,
    /// Line numbering; `None` writes none.
    #[serde(default)]
    pub line_numbers: Option<LineNumbers>,
    /// Modal suppression: unchanged motion codes, axis words and feeds are not repeated.
    #[serde(default = "yes")]
    pub modal: bool,
    /// Word letter for a machine axis name when it differs (e.g. `{ C = "C" }`).
    #[serde(default)]
    pub axis_words: BTreeMap<String, String>,
    /// Most axes the controller drives (grbl: 3, i.e. X, Y, Z only).
    #[serde(default = "five")]
    pub max_axes: usize,
    /// Feed words of joint-space 5-axis blocks.
    #[serde(default)]
    pub feed_by_time: FeedByTime,
    /// Words of rotary axes declared `modulo360_*`; `None` writes `{axis}{value}` with value in [0, 360).
    #[serde(default)]
    pub modulo_words: Option<ModuloWords>,
    /// TCP codes; `None` when the controller has no TCP function.
    #[serde(default)]
    pub tcp: Option<TcpCodes>,
    /// Tilted-work-plane codes.
    #[serde(default)]
    pub tilted_plane: TiltedPlane,
    /// Centre words of `G2`/`G3` arcs ([`crate::write_fitted`]).
    #[serde(default)]
    pub arc_words: ArcWords,
    /// Decimals of linear words in inch programs (default `decimals + 1`: 0.00001 in
    /// = 0.000254 mm, the resolution of the 4-decimal mm words).
    #[serde(default)]
    pub inch_decimals: Option<usize>,
    /// Whether linear words and feeds are written in inches and in/min (`G20`); set
    /// by [`Dialect::in_inches`], never in a dialect file.
    #[serde(skip)]
    pub inch: bool,
}

const BUILTIN: &[(&str, &str)] = &[
    ("linuxcnc", include_str!("../dialects/linuxcnc.toml")),
    ("fanuc", include_str!("../dialects/fanuc.toml")),
    ("siemens840d", include_str!("../dialects/siemens840d.toml")),
    ("heidenhain", include_str!("../dialects/heidenhain.toml")),
    ("heidenhain-iso", include_str!("../dialects/heidenhain-iso.toml")),
    ("grbl", include_str!("../dialects/grbl.toml")),
];

impl Dialect {
    /// Plain RS-274 (LinuxCNC / Fanuc-compatible subset) in millimetres, 3 decimals: the
    /// 3-axis demo dialect.
    ///
    /// ```
    /// assert_eq!(scallop_post::Dialect::plain().decimals, 3);
    /// ```
    #[must_use]
    pub fn plain() -> Dialect {
        Dialect {
            name: "plain RS-274, mm".into(),
            syntax: Syntax::Iso,
            decimals: 3,
            rotary_decimals: 4,
            feed_decimals: 0,
            inverse_time_decimals: 3,
            explicit_plus: false,
            comment: ("(".into(), ")".into()),
            header_comments: default_header_comments(),
            header: vec!["G21 G90 G17 G94".into(), "G40 G49 G80".into()],
            footer: vec!["M5".into(), "M30".into()],
            tool_change: vec!["T{tool} M6".into()],
            length_offset: vec!["G43 H{tool}".into()],
            joint_kinematics: Vec::new(),
            line_numbers: None,
            modal: true,
            axis_words: BTreeMap::new(),
            max_axes: 5,
            feed_by_time: FeedByTime::G93,
            modulo_words: None,
            tcp: None,
            tilted_plane: TiltedPlane::None,
            arc_words: ArcWords::Ijk,
            inch_decimals: None,
            inch: false,
        }
    }

    /// The same dialect writing inch programs (3-axis output, [`crate::write_fitted`]):
    /// `G20` in place of the header's `G21` (or first, when it has none), linear words
    /// with `inch_decimals` (default one more than in mm), feeds in in/min with one more
    /// decimal. Units inside stay mm: the writer converts.
    ///
    /// ```
    /// let d = scallop_post::Dialect::builtin("fanuc").unwrap().in_inches().unwrap();
    /// assert!(d.inch && d.header.iter().any(|h| h.starts_with("G20 ")) && d.decimals == 5);
    /// assert!(scallop_post::Dialect::builtin("heidenhain").unwrap().in_inches().is_err());
    /// ```
    ///
    /// # Errors
    /// [`PostError::Unsupported`] for the Heidenhain plain-language syntax (its
    /// `BEGIN PGM .. MM` programs are written in mm only).
    pub fn in_inches(&self) -> Result<Dialect, PostError> {
        if self.syntax != Syntax::Iso {
            return Err(PostError::Unsupported {
                dialect: self.name.clone(),
                what: "an inch program".into(),
                fix: "use millimetres (output.units = \"mm\") or an ISO dialect".into(),
            });
        }
        let mut d = self.clone();
        let mut replaced = false;
        for h in &mut d.header {
            let words: Vec<&str> = h.split_whitespace().collect();
            if words.contains(&"G21") {
                *h = words.iter().map(|w| if *w == "G21" { "G20" } else { w }).collect::<Vec<_>>().join(" ");
                replaced = true;
            }
        }
        if !replaced {
            let at = d.header.iter().take_while(|h| *h == "%" || h.starts_with('O')).count();
            d.header.insert(at, "G20".into());
        }
        d.decimals = self.inch_decimals.unwrap_or(self.decimals + 1);
        d.feed_decimals = self.feed_decimals + 1;
        d.name = format!("{}, inch", self.name);
        d.inch = true;
        Ok(d)
    }

    /// Parses a dialect from TOML (the fields of [`Dialect`]; see `docs/post.md`).
    ///
    /// ```
    /// let d = scallop_post::Dialect::from_toml_str("name = \"x\"\ndecimals = 3\ncomment = [\"(\", \")\"]").unwrap();
    /// assert_eq!(d.max_axes, 5);
    /// ```
    ///
    /// # Errors
    /// [`PostError::Dialect`] with the TOML reader's message.
    pub fn from_toml_str(text: &str) -> Result<Dialect, PostError> {
        toml::from_str(text).map_err(|e| PostError::Dialect { problem: e.to_string() })
    }

    /// A shipped dialect: `linuxcnc`, `fanuc`, `siemens840d`, `heidenhain` (plain
    /// language), `heidenhain-iso`, `grbl`; `plain` is [`Dialect::plain`].
    ///
    /// ```
    /// for n in scallop_post::Dialect::builtin_names() {
    ///     assert!(scallop_post::Dialect::builtin(n).is_ok());
    /// }
    /// ```
    ///
    /// # Errors
    /// [`PostError::Dialect`] for an unknown name.
    pub fn builtin(name: &str) -> Result<Dialect, PostError> {
        if name == "plain" {
            return Ok(Dialect::plain());
        }
        let text = BUILTIN.iter().find(|(n, _)| *n == name).map(|(_, t)| *t).ok_or_else(|| PostError::Dialect {
            problem: format!("no shipped dialect named `{name}` (use one of {:?})", Self::builtin_names()),
        })?;
        Self::from_toml_str(text)
    }

    /// Names accepted by [`Dialect::builtin`].
    ///
    /// ```
    /// assert!(scallop_post::Dialect::builtin_names().contains(&"grbl"));
    /// ```
    #[must_use]
    pub fn builtin_names() -> Vec<&'static str> {
        std::iter::once("plain").chain(BUILTIN.iter().map(|(n, _)| *n)).collect()
    }

    /// The dialect a machine description names in `nc.dialect` (`iso` is `fanuc`).
    ///
    /// ```
    /// let m = scallop_machine::Machine::builtin("ucp710").unwrap();
    /// assert_eq!(scallop_post::Dialect::for_machine(&m).name, "Siemens Sinumerik 840D");
    /// ```
    #[must_use]
    pub fn for_machine(machine: &scallop_machine::Machine) -> Dialect {
        use scallop_machine::Dialect as D;
        let name = match machine.nc().dialect {
            D::Iso | D::Fanuc => "fanuc",
            D::Linuxcnc => "linuxcnc",
            D::Siemens840d => "siemens840d",
            D::Heidenhain => "heidenhain",
            D::Grbl => "grbl",
        };
        // INVARIANT: every shipped dialect file parses (tested).
        Self::builtin(name).unwrap_or_else(|_| Dialect::plain())
    }

    /// The word letter of a machine axis.
    #[must_use]
    pub fn axis_word<'a>(&'a self, axis: &'a str) -> &'a str {
        self.axis_words.get(axis).map_or(axis, String::as_str)
    }
}
