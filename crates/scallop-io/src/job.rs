//! The job file (`scallop run JOB.toml`): what to machine, with what, how
//! finely. The schema is documented in `docs/job.md`; unknown keys are errors,
//! so a misspelt key is never silently ignored.
//!
//! ```
//! use scallop_io::job::parse_job;
//! let job = parse_job(r#"
//! [part]
//! builtin = "choi"
//! [cutter]
//! shape = "bull"
//! diameter = 10
//! corner_radius = 2
//! [finishing]
//! scallop_height = 0.01
//! "#).unwrap();
//! assert_eq!(job.cutter.diameter, 10.0);
//! assert!(parse_job("[part]\nbuiltin = \"choi\"\ncolour = 3\n").unwrap_err().to_string().contains("colour"));
//! ```

use serde::Deserialize;

use crate::tools::ToolLibrary;

/// A job file: a part, a stock and operations in order. A job without
/// `[[operation]]` is one finishing operation given by `[cutter]` and
/// `[finishing]`.
#[derive(Debug, Clone, PartialEq)]
pub struct JobFile {
    /// The part.
    pub part: PartSpec,
    /// The cutter of the first operation.
    pub cutter: CutterSpec,
    /// The finishing settings of the first operation.
    pub finishing: FinishingSpec,
    /// The stock; `None`: the part's box grown by the largest cutter radius,
    /// 1 mm below and above the part.
    pub stock: Option<StockSpec>,
    /// The operations in machining order (at least one).
    pub operations: Vec<OperationSpec>,
    /// Whether the file lists `[[operation]]`s (else it is a one-operation job
    /// of `[cutter]` and `[finishing]`).
    pub operation_list: bool,
    /// Tolerances (mm).
    pub tolerances: TolerancesSpec,
    /// Machine limits, and the machine description the job names, if any.
    pub machine: MachineSpec,
    /// Stock simulation that proves the program.
    pub verify: VerifySpec,
    /// Zone-optimisation study (`scallop optimize`).
    pub optimize: Option<OptimizeSpec>,
    /// How the program is written.
    pub output: OutputSpec,
    /// 3+2 setup (indexed rotaries); absent for 3-axis work.
    pub setup: Option<SetupSpec>,
    /// The tool library (`tool_library`, relative to the job file), if named.
    pub tool_library: Option<String>,
}

/// The file as written, before the operations are normalised.
#[derive(Debug, Clone, Deserialize)]
struct RawJob {
    part: PartSpec,
    cutter: Option<CutterSpec>,
    finishing: Option<FinishingSpec>,
    stock: Option<StockSpec>,
    #[serde(default)]
    operation: Vec<OperationSpec>,
    #[serde(default)]
    tolerances: TolerancesSpec,
    #[serde(default, deserialize_with = "machine_field")]
    machine: MachineSpec,
    #[serde(default)]
    verify: VerifySpec,
    #[serde(default)]
    optimize: Option<OptimizeSpec>,
    #[serde(default)]
    output: OutputSpec,
    setup: Option<SetupSpec>,
    tool_library: Option<String>,
}

/// `[stock]`: a box given by its corners, or margins around the part's box
/// (mm). Corners and margins exclude each other.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct StockSpec {
    /// Lowest corner `[x, y, z]` (part frame).
    pub min: Option<[f64; 3]>,
    /// Highest corner `[x, y, z]`.
    pub max: Option<[f64; 3]>,
    /// Margin around the part's box in X and Y (default: the largest cutter radius).
    pub margin: Option<f64>,
    /// Stock above the part's top (default 1).
    pub top: Option<f64>,
    /// Stock below the part's bottom (default 1).
    pub bottom: Option<f64>,
}

/// What an operation does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum OperationKind {
    /// Finishing with a guaranteed scallop height (`[operation.finishing]`).
    Finish,
    /// Z-level roughing from the stock (`[operation.roughing]`).
    Rough,
    /// Rest roughing (`[operation.roughing]`): z-level roughing of only the
    /// material the earlier operations left (docs/roughing.md); never the
    /// first operation.
    Rest,
    /// 5-axis roughing by guide curves of a test part (`[operation.rough5]`,
    /// docs/rough5.md), proven on a tri-dexel stock.
    Rough5,
}

/// `[[operation]]`: one operation with its own cutter, tool and spindle.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct OperationSpec {
    /// What it does.
    pub kind: OperationKind,
    /// How the program and the report name it (default: `operation N`).
    #[serde(default)]
    pub name: String,
    /// Tool number in the program (default: `output.tool`, else the operation's number).
    pub tool: Option<u32>,
    /// Spindle speed (1/min; default `output.spindle`).
    pub spindle: Option<f64>,
    /// Whether `spindle` comes from the tool library's cutting data (not the job).
    #[serde(skip)]
    pub spindle_from_library: bool,
    /// Whether `feed` comes from the tool library's cutting data (not the job).
    #[serde(skip)]
    pub feed_from_library: bool,
    /// `[operation.cutter]`; left out when `tool` names a tool of the job's
    /// tool library, which gives it ([`CutterSpec::unset`] until then).
    #[serde(default = "CutterSpec::unset")]
    pub cutter: CutterSpec,
    /// Feed (mm/min; default: the tool library's `f_z * flutes * n`, else `machine.feed`).
    pub feed: Option<f64>,
    /// `[operation.finishing]` (finish operations; absent on rough
    /// operations, where it reads as [`FinishingSpec::absent`]).
    #[serde(default = "FinishingSpec::absent")]
    pub finishing: FinishingSpec,
    /// `[operation.roughing]` (rough operations only).
    pub roughing: Option<RoughingSpec>,
    /// `[operation.rough5]` (rough5 operations only).
    pub rough5: Option<Rough5Spec>,
}

/// `[operation.rough5]`: 5-axis roughing by guide curves (docs/rough5.md).
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct Rough5Spec {
    /// Axial depth of cut a_p between levels (mm).
    pub ap: f64,
    /// Radial engagement a_e between passes (mm).
    pub ae: f64,
    /// Material left on the flanks (mm, default 0.5).
    #[serde(default = "default_rough5_allowance")]
    pub stock_to_leave: f64,
    /// Material left on the bottom (mm; default `stock_to_leave`).
    pub stock_to_leave_axial: Option<f64>,
    /// Tool-axis variant: `guides` (default), `zero` or `optimised`.
    #[serde(default = "default_tilt")]
    pub tilt: TiltWord,
    /// Voxel size of the level fields (mm, default 1).
    #[serde(default = "default_one")]
    pub voxel: f64,
    /// Spacing of the CL points along a pass (mm, default 1).
    #[serde(default = "default_one")]
    pub step: f64,
    /// Largest tool-axis change between CL points (degrees, default 2).
    #[serde(default = "default_angle_step")]
    pub max_angle_step_deg: f64,
    /// Largest change of the axis's azimuth about Z between CL points (degrees, default 5).
    #[serde(default = "default_azimuth_step")]
    pub max_azimuth_step_deg: f64,
    /// Teeth z of the tool: with `feed_per_tooth` and the spindle speed, the
    /// feed z f_z N when the operation gives no `feed`.
    pub teeth: Option<u32>,
    /// Feed per tooth f_z (mm).
    pub feed_per_tooth: Option<f64>,
    /// Tool length the kinematics use (mm; default: flutes, shank and holder).
    pub tool_length: Option<f64>,
    /// Tri-dexel ray spacing of the proof (mm, default 0.5).
    #[serde(default = "default_dexel_resolution")]
    pub resolution: f64,
    /// Largest deviation of the simulated 5-axis sweeps from the true ones (mm, default 0.05).
    #[serde(default = "default_sim_tolerance")]
    pub sim_tolerance: f64,
    /// Collision corrections of Ch. 3 §3 (docs/rough5.md): `true` for step 1
    /// (the planar correction), or a list of steps, `["planar", "spatial"]`
    /// (step 2: an upper level's limit curve); default none.
    #[serde(default)]
    pub correction: CorrectionSpec,
    /// How the runs are entered: `auto` (default), `helix`, `ramp` or `side`
    /// (docs/rough5.md, "Entries").
    #[serde(default = "default_entry")]
    pub entry: EntryWord,
    /// Per-pass weights (spec module H; docs/rough5.md, "Per-pass weights"):
    /// `[beta, phi, tau]` (bounds, fluidity, pitch) of the optimised
    /// orientation of the passes that leave the finished faces' stock (the
    /// bottom level's passes and each level's limit passes), with the
    /// interval [0, 30] deg and the target 10 deg, as `scallop rough5
    /// --limit-weights`; three finite numbers >= 0, not with `tilt = "zero"`.
    pub limit_weights: Option<Vec<f64>>,
    /// Whether the feeds, links and plunges that lie outside the in-process
    /// stock by `air_clearance` are written at `air_feed` (docs/rough5.md,
    /// "Air moves"; default true, as `scallop rough5`).
    #[serde(default = "default_true")]
    pub air_moves: bool,
    /// Feed of the air moves (mm/min, default 30000, above the cutting feed).
    #[serde(default = "default_air_feed")]
    pub air_feed: f64,
    /// Clearance between the tool and the in-process stock for a move to be
    /// an air move (mm, default 1).
    #[serde(default = "default_one")]
    pub air_clearance: f64,
}

fn default_true() -> bool {
    true
}

fn default_air_feed() -> f64 {
    30_000.0
}

/// `rough5.correction`: the step-1 switch, or the list of steps.
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(untagged)]
pub enum CorrectionSpec {
    /// `true`: step 1 (the planar correction) alone; `false`: none.
    Switch(bool),
    /// The steps, e.g. `["planar", "spatial"]`.
    Steps(Vec<CorrectionWord>),
}

impl Default for CorrectionSpec {
    fn default() -> Self {
        CorrectionSpec::Switch(false)
    }
}

impl CorrectionSpec {
    /// Whether step 1 (the planar correction, Eq. 3.31) is asked for.
    #[must_use]
    pub fn planar(&self) -> bool {
        match self {
            CorrectionSpec::Switch(on) => *on,
            CorrectionSpec::Steps(steps) => steps.contains(&CorrectionWord::Planar),
        }
    }

    /// Whether step 2 (an upper level's limit curve, Eq. 3.32) is asked for.
    #[must_use]
    pub fn spatial(&self) -> bool {
        matches!(self, CorrectionSpec::Steps(steps) if steps.contains(&CorrectionWord::Spatial))
    }
}

fn default_entry() -> EntryWord {
    EntryWord::Auto
}

fn default_rough5_allowance() -> f64 {
    0.5
}
fn default_tilt() -> TiltWord {
    TiltWord::Guides
}
fn default_one() -> f64 {
    1.0
}
fn default_angle_step() -> f64 {
    2.0
}
fn default_azimuth_step() -> f64 {
    5.0
}
fn default_dexel_resolution() -> f64 {
    0.5
}
fn default_sim_tolerance() -> f64 {
    0.05
}

/// `[operation.roughing]`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct RoughingSpec {
    /// Depth between levels (mm).
    pub stepdown: f64,
    /// Radial depth of cut as a fraction of the cutter diameter, in (0, 0.5].
    pub stepover: f64,
    /// Material left on the walls (mm, default 0).
    #[serde(default)]
    pub stock_to_leave: f64,
    /// Material left on the floors (mm; default `stock_to_leave`).
    pub stock_to_leave_axial: Option<f64>,
    /// Clearing pattern (`offset` or `adaptive`).
    #[serde(default = "default_rough_pattern")]
    pub pattern: RoughPatternWord,
    /// `climb` (default) or `conventional`.
    #[serde(default = "default_milling")]
    pub direction: MillingWord,
}

fn default_rough_pattern() -> RoughPatternWord {
    RoughPatternWord::Offset
}

fn default_milling() -> MillingWord {
    MillingWord::Climb
}

/// `[output]`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct OutputSpec {
    /// Controller dialect: `linuxcnc`, `plain`, `fanuc`, `grbl`, `siemens840d`,
    /// `heidenhain-iso` (checked by the caller against the shipped dialects); `None`: the
    /// named machine's (`nc.dialect`), else `linuxcnc` ([`OutputSpec::dialect_or`]).
    #[serde(default)]
    pub dialect: Option<String>,
    /// `G2`/`G3` arcs within a quarter of the path tolerance (default false).
    #[serde(default)]
    pub arc_fitting: bool,
    /// Program name or number.
    #[serde(default = "default_program")]
    pub program: String,
    /// Tool number (0: no tool change).
    #[serde(default)]
    pub tool: u32,
    /// Spindle speed (1/min; 0: no spindle word).
    #[serde(default)]
    pub spindle: f64,
    /// Units of the program: `mm` (default, `G21`) or `in` (`G20`, 3-axis output).
    #[serde(default = "default_units")]
    pub units: UnitsWord,
}

impl OutputSpec {
    /// The dialect the job gives, else `machine` (the named machine's), else `linuxcnc`.
    ///
    /// ```
    /// let o = scallop_io::job::OutputSpec::default();
    /// assert_eq!((o.dialect_or(Some("grbl")), o.dialect_or(None)), ("grbl", "linuxcnc"));
    /// ```
    #[must_use]
    pub fn dialect_or<'a>(&'a self, machine: Option<&'a str>) -> &'a str {
        self.dialect.as_deref().or(machine).unwrap_or("linuxcnc")
    }
}
fn default_program() -> String {
    "1".into()
}

impl Default for OutputSpec {
    fn default() -> Self {
        OutputSpec {
            dialect: None,
            arc_fitting: false,
            program: default_program(),
            tool: 0,
            spindle: 0.0,
            units: default_units(),
        }
    }
}

/// `[setup]`: 3+2 work.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct SetupSpec {
    /// Rotation of the part into the frame where the tool is vertical, degrees about the
    /// fixed X, then Y, then Z axes (`R = Rz Ry Rx`).
    pub rotation_deg: [f64; 3],
    /// Machine description whose kinematics give the rotary words (e.g. `linuxcnc-xyzac-trt`).
    pub machine: String,
    /// Tool length the kinematics use (mm; 0 when the controller applies it).
    #[serde(default)]
    pub tool_length: f64,
}

/// `[part]`: one of `file` (mesh or surface file, relative to the job file),
/// `builtin` or `test_part`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct PartSpec {
    /// Mesh (.stl .obj .ply .3mf) or surface (.toml) file.
    pub file: Option<String>,
    /// Built-in surface name (`choi`, `rubio`).
    pub builtin: Option<String>,
    /// A test part of 5-axis roughing (`pocket`, `impeller`, `fitting`): the
    /// volume to remove with its bottom, flank and top faces, its stock box
    /// and blank (`scallop-parts`); for `kind = "rough5"` operations.
    pub test_part: Option<TestPartWord>,
    /// Unit of mesh coordinates: `mm` (default) or `in`.
    #[serde(default = "default_units")]
    pub units: UnitsWord,
}

fn default_units() -> UnitsWord {
    UnitsWord::Mm
}

/// A closed set of words in a job file, read as an enum: a word outside the
/// set is a parse error naming the line and the words allowed.
macro_rules! word_enum {
    ($(#[$doc:meta])* $name:ident { $($(#[$vdoc:meta])* $variant:ident = $word:literal),+ $(,)? }) => {
        $(#[$doc])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
        pub enum $name {
            $($(#[$vdoc])* #[serde(rename = $word)] $variant),+
        }
        impl $name {
            /// The word of the job file.
            #[must_use]
            pub fn word(self) -> &'static str {
                match self { $($name::$variant => $word),+ }
            }
        }
    };
}

word_enum! {
    /// `part.units`.
    UnitsWord { /// Millimetres.
        Mm = "mm", /// Inches.
        In = "in", /// Metres.
        M = "m", /// Centimetres.
        Cm = "cm" }
}
word_enum! {
    /// `cutter.shape`.
    ShapeWord { /// Ball end.
        Ball = "ball", /// Flat end.
        Flat = "flat", /// Bull-nose (toroidal).
        Bull = "bull", /// Cone (V) cutter.
        Cone = "cone" }
}
word_enum! {
    /// `part.test_part`.
    TestPartWord { /// The closed pocket (100 x 100 x 35 mm, drafts and undercuts).
        Pocket = "pocket", /// The impeller channel between two blades.
        Impeller = "impeller", /// The fitting pocket with two ribs.
        Fitting = "fitting" }
}
word_enum! {
    /// `rough5.tilt`.
    TiltWord { /// Tool axis +Z on every level (the zero-tilt baseline).
        Zero = "zero", /// From the path curve to the tilt curve on the level above (SPU).
        Guides = "guides", /// Guide curves with the optimised reparameterisation of each pass.
        Optimised = "optimised" }
}
word_enum! {
    /// A step of `rough5.correction`.
    CorrectionWord { /// Step 1: the axis turned in its correction plane, the pitch kept (Eq. 3.31).
        Planar = "planar", /// Step 2: on the offset levels, the axis turned through an upper level's limit curve (Eq. 3.32).
        Spatial = "spatial" }
}
word_enum! {
    /// `rough5.entry`.
    EntryWord { /// A helix where it fits, else from the stock's side, else a ramp, else a plunge.
        Auto = "auto", /// A helix where it fits, else a ramp, else a plunge.
        Helix = "helix", /// A ramp along a closed run, else a plunge.
        Ramp = "ramp", /// From the stock's side where a run starts within reach of it, else a ramp, else a plunge.
        Side = "side" }
}
word_enum! {
    /// `finishing.pattern`.
    PatternWord { /// Back and forth.
        Zigzag = "zigzag", /// Always the same way.
        OneWay = "one-way" }
}
word_enum! {
    /// `roughing.pattern`.
    RoughPatternWord { /// Contour-parallel offsets.
        Offset = "offset", /// Contour-parallel offsets, looped where a ring would slot.
        OffsetLoops = "offset-loops", /// Engagement-controlled (adaptive) clearing.
        Adaptive = "adaptive" }
}
word_enum! {
    /// `roughing.direction`.
    MillingWord { /// Climb milling.
        Climb = "climb", /// Conventional milling.
        Conventional = "conventional", /// Both ways: adaptive passes climb and conventional in turn.
        Both = "both" }
}
word_enum! {
    /// `finishing.strategy`.
    StrategyWord { /// Steep-and-shallow on a mesh part, parallel planes on a parametric one.
        Auto = "auto", /// Parallel planes, drop-cutter planner with a measured scallop.
        Parallel = "parallel", /// Parallel planes by the network planner.
        Network = "network", /// Isoparametric passes.
        Isoparametric = "isoparametric", /// Parallel planes on shallow triangles, waterline levels on steep ones.
        SteepShallow = "steep-shallow" }
}
word_enum! {
    /// `finishing.iso_direction`.
    IsoWord { /// Along u.
        U = "u", /// Along v.
        V = "v" }
}
word_enum! {
    /// `finishing.lead`.
    LeadWord { /// Straight plunges.
        None = "none", /// Arc leads.
        Arc = "arc", /// Ramp leads.
        Ramp = "ramp" }
}
word_enum! {
    /// `optimize.formulation`.
    FormulationWord { /// A direction per zone.
        ThreeAxis = "3axis", /// An orientation per zone.
        ThreePlusTwo = "3+2", /// 3+2 with the PCA heuristic orientation.
        Heuristic = "heuristic" }
}
word_enum! {
    /// `optimize.surrogate`.
    SurrogateWord { /// None.
        None = "none", /// S3.
        S3 = "s3", /// S4.
        S4 = "s4" }
}
word_enum! {
    /// `optimize.transition`.
    TransitionWord { /// Retract, traverse, plunge.
        Retract = "retract", /// One straight move.
        Linear = "linear" }
}
word_enum! {
    /// `optimize.barrier`.
    BarrierWord { /// Progressive barrier.
        Progressive = "progressive", /// Extreme barrier.
        Extreme = "extreme" }
}

/// `[cutter]`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct CutterSpec {
    /// `ball`, `flat` or `bull`.
    pub shape: ShapeWord,
    /// Diameter D (mm).
    pub diameter: f64,
    /// Corner radius r of a bull-nose (mm).
    pub corner_radius: Option<f64>,
    /// Flute length (mm); default 4 D.
    pub flute_length: Option<f64>,
    /// Included tip angle of a cone (degrees, 0 < angle < 180; cone only).
    pub angle_deg: Option<f64>,
    /// Shank diameter (mm; default D).
    pub shank_diameter: Option<f64>,
    /// Shank length above the flutes (mm; default the flute length).
    pub shank_length: Option<f64>,
    /// Holder stack, bottom segment first.
    #[serde(default)]
    pub holder: Vec<HolderSpec>,
}

impl CutterSpec {
    /// The cutter of an operation that gives none: to be taken from the tool
    /// library (its diameter is NaN, which no file can mean for a cutter).
    #[must_use]
    pub fn unset() -> CutterSpec {
        CutterSpec {
            shape: ShapeWord::Flat,
            diameter: f64::NAN,
            corner_radius: None,
            flute_length: None,
            angle_deg: None,
            shank_diameter: None,
            shank_length: None,
            holder: Vec::new(),
        }
    }

    /// Whether this is [`CutterSpec::unset`].
    #[must_use]
    pub fn is_unset(&self) -> bool {
        self.diameter.is_nan()
    }
}

/// One solid of a holder stack: a cylinder of `diameter`, or a frustum to
/// `top_diameter` (mm).
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct HolderSpec {
    /// Height (mm).
    pub length: f64,
    /// Diameter at the bottom (mm).
    pub diameter: f64,
    /// Diameter at the top (mm; default `diameter`).
    pub top_diameter: Option<f64>,
}

/// `[finishing]`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct FinishingSpec {
    /// Largest scallop height sh (mm).
    pub scallop_height: f64,
    /// Feed direction: `"auto"` (the PCA steepest slope for a bull-nose or flat
    /// cutter, the principal direction for a ball) or an angle from +X in degrees.
    #[serde(default)]
    pub direction: DirectionSpec,
    /// `zigzag` (default) or `one-way`.
    #[serde(default = "default_pattern")]
    pub pattern: PatternWord,
    /// Longest forward step between drop-cutter samples (mm).
    #[serde(default = "default_max_step")]
    pub max_step: f64,
    /// `auto` (default: `steep-shallow` on a mesh part without a `[setup]`, else
    /// `parallel`), `parallel` (parallel vertical planes, drop-cutter planner with a measured
    /// scallop), `network` (parallel planes by the fast network planner, parametric parts)
    /// `isoparametric` (parametric parts) or `steep-shallow` (parallel planes on
    /// shallow triangles, waterline levels on steep ones).
    #[serde(default = "default_strategy")]
    pub strategy: StrategyWord,
    /// Steep-and-shallow: the slope (degrees from the horizontal) from which
    /// waterline levels finish instead of parallel planes; default from the
    /// cutter and sh (`scallop_strategy::SteepShallow::default_for`).
    #[serde(default)]
    pub steep_threshold_deg: Option<f64>,
    /// Isoparametric passes along `u` (default) or `v`.
    #[serde(default = "default_iso")]
    pub iso_direction: IsoWord,
    /// Lead-in/lead-out at plunges and retracts: `none` (default), `arc` or `ramp`.
    #[serde(default = "default_lead")]
    pub lead: LeadWord,
    /// Radius of arc leads (mm).
    #[serde(default = "default_lead_size")]
    pub lead_radius: f64,
    /// Length of ramp leads (mm).
    #[serde(default = "default_lead_size")]
    pub lead_length: f64,
    /// Angle of ramp leads above the pass's tangent (degrees).
    #[serde(default = "default_lead_angle")]
    pub lead_angle_deg: f64,
}

impl FinishingSpec {
    /// The settings read where no finishing table is given (a rough
    /// operation): the scallop height is NaN, so no finishing can run on them.
    #[must_use]
    pub fn absent() -> FinishingSpec {
        FinishingSpec {
            scallop_height: f64::NAN,
            direction: DirectionSpec::Auto,
            pattern: default_pattern(),
            max_step: default_max_step(),
            strategy: default_strategy(),
            steep_threshold_deg: None,
            iso_direction: default_iso(),
            lead: default_lead(),
            lead_radius: default_lead_size(),
            lead_length: default_lead_size(),
            lead_angle_deg: default_lead_angle(),
        }
    }
}

fn default_strategy() -> StrategyWord {
    StrategyWord::Auto
}
fn default_iso() -> IsoWord {
    IsoWord::U
}
fn default_lead() -> LeadWord {
    LeadWord::None
}
fn default_lead_size() -> f64 {
    2.0
}
fn default_lead_angle() -> f64 {
    15.0
}

fn default_pattern() -> PatternWord {
    PatternWord::Zigzag
}

fn default_max_step() -> f64 {
    0.5
}

/// A feed direction.
#[derive(Debug, Clone, PartialEq, Deserialize, Default)]
#[serde(untagged)]
pub enum DirectionSpec {
    /// `"auto"`.
    Named(String),
    /// Degrees from +X.
    Degrees(f64),
    /// Not given: auto.
    #[default]
    #[serde(skip)]
    Auto,
}

/// `[tolerances]` (mm).
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct TolerancesSpec {
    /// Largest deviation of the motion from the ideal CL surface.
    #[serde(default = "default_path")]
    pub path: f64,
    /// Largest allowed penetration into the part.
    #[serde(default)]
    pub gouge: f64,
}

fn default_path() -> f64 {
    0.01
}

impl Default for TolerancesSpec {
    fn default() -> Self {
        TolerancesSpec { path: default_path(), gouge: 0.0 }
    }
}

/// `[machine]`: the spec's units (m/min, m/s², m/s³) and mm; or `machine = "NAME"`
/// (a shipped machine or a machine file relative to the job file), the same as
/// `[machine]` with `description = "NAME"` and the other keys at their defaults.
/// With a description, the machine file gives acceleration, jerk and rapid (giving
/// them here too is an error); `feed` and `clearance` stay the job's.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct MachineSpec {
    /// The machine description (shipped name or file), if named.
    #[serde(default)]
    pub description: Option<String>,
    /// Feed V (m/min).
    #[serde(default = "default_feed")]
    pub feed: f64,
    /// Acceleration A (m/s²).
    #[serde(default = "default_acceleration")]
    pub acceleration: f64,
    /// Jerk J (m/s³).
    #[serde(default = "default_jerk")]
    pub jerk: f64,
    /// Rapid rate (m/min).
    #[serde(default = "default_rapid")]
    pub rapid: f64,
    /// Clearance above the part's top (mm).
    #[serde(default = "default_clearance")]
    pub clearance: f64,
}

fn default_feed() -> f64 {
    5.0
}
fn default_acceleration() -> f64 {
    6.0
}
fn default_jerk() -> f64 {
    40.0
}
fn default_rapid() -> f64 {
    30.0
}
fn default_clearance() -> f64 {
    5.0
}

impl Default for MachineSpec {
    fn default() -> Self {
        MachineSpec {
            description: None,
            feed: default_feed(),
            acceleration: default_acceleration(),
            jerk: default_jerk(),
            rapid: default_rapid(),
            clearance: default_clearance(),
        }
    }
}

/// `machine = "NAME"` or a `[machine]` table (read through the job's unknown-key
/// tracking, so a misspelt key inside the table is still reported).
fn machine_field<'de, D: serde::Deserializer<'de>>(de: D) -> Result<MachineSpec, D::Error> {
    struct Field;
    impl<'de> serde::de::Visitor<'de> for Field {
        type Value = MachineSpec;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("a machine name or file (`machine = \"linuxcnc-3axis\"`) or a [machine] table")
        }
        fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<MachineSpec, E> {
            Ok(MachineSpec { description: Some(v.to_string()), ..MachineSpec::default() })
        }
        fn visit_map<A: serde::de::MapAccess<'de>>(self, map: A) -> Result<MachineSpec, A::Error> {
            let raw = RawMachineTable::deserialize(serde::de::value::MapAccessDeserializer::new(map))?;
            if let Some(name) = &raw.description {
                for (key, v) in [("acceleration", raw.acceleration), ("jerk", raw.jerk), ("rapid", raw.rapid)] {
                    if let Some(v) = v {
                        return Err(serde::de::Error::custom(format!(
                            "[machine] gives {key} = {v} and description = \"{name}\": the machine file gives \
                             acceleration, jerk and rapid; remove {key} (or remove description to use [machine] alone)"
                        )));
                    }
                }
            }
            let d = MachineSpec::default();
            Ok(MachineSpec {
                description: raw.description,
                feed: raw.feed.unwrap_or(d.feed),
                acceleration: raw.acceleration.unwrap_or(d.acceleration),
                jerk: raw.jerk.unwrap_or(d.jerk),
                rapid: raw.rapid.unwrap_or(d.rapid),
                clearance: raw.clearance.unwrap_or(d.clearance),
            })
        }
    }
    /// `[machine]` as written.
    #[derive(Deserialize)]
    struct RawMachineTable {
        description: Option<String>,
        feed: Option<f64>,
        acceleration: Option<f64>,
        jerk: Option<f64>,
        rapid: Option<f64>,
        clearance: Option<f64>,
    }
    de.deserialize_any(Field)
}

/// `[verify]`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct VerifySpec {
    /// Stock cell size (mm).
    #[serde(default = "default_resolution")]
    pub resolution: f64,
}

fn default_resolution() -> f64 {
    0.1
}

impl Default for VerifySpec {
    fn default() -> Self {
        VerifySpec { resolution: default_resolution() }
    }
}

/// `[optimize]`: a zone-optimisation study (`scallop optimize`, finishing.md 12).
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct OptimizeSpec {
    /// `"3axis"`, `"3+2"` or `"heuristic"`.
    pub formulation: FormulationWord,
    /// Smallest number of clusters K (default 2).
    #[serde(default = "default_k_min")]
    pub k_min: i64,
    /// Largest number of clusters K (default 10; at least 2).
    #[serde(default = "default_k_max")]
    pub k_max: i64,
    /// Black-box-equivalent evaluations per K (default 1000).
    #[serde(default = "default_budget")]
    pub budget: f64,
    /// Static surrogate ordering the poll: `"none"`, `"s3"` (default) or `"s4"`.
    #[serde(default = "default_surrogate")]
    pub surrogate: SurrogateWord,
    /// Cost of one surrogate evaluation in black-box evaluations: a ratio
    /// (deterministic; default 0.05) or `"measured"` (timed; not reproducible).
    #[serde(default)]
    pub surrogate_cost: SurrogateCostSpec,
    /// Seed of the poll directions (default 0).
    #[serde(default)]
    pub seed: u64,
    /// Start weights of the clustering pseudo-metric, each in [0, 1] (default all 1).
    #[serde(default = "default_omega")]
    pub omega: [f64; 4],
    /// Clustering grid `[N_u, N_v]` of the black box (default `[80, 80]`).
    #[serde(default = "default_grid")]
    pub grid: [i64; 2],
    /// Clustering grid of the surrogates (default `[40, 40]`).
    #[serde(default = "default_surrogate_grid")]
    pub surrogate_grid: [i64; 2],
    /// Machining-mesh step of the black box (mm, default 0.5).
    #[serde(default = "default_step")]
    pub step: f64,
    /// Machining-mesh step of surrogate S4 (mm, default 5).
    #[serde(default = "default_surrogate_step")]
    pub surrogate_step: f64,
    /// Scallop height of surrogate S4 (mm, default 0.1).
    #[serde(default = "default_surrogate_sh")]
    pub surrogate_scallop_height: f64,
    /// Inter-zone transition: `"retract"` (default: retract, traverse, plunge)
    /// or `"linear"` (one straight move).
    #[serde(default = "default_transition")]
    pub transition: TransitionWord,
    /// Retract height above the higher end of a transition (mm, default 5).
    #[serde(default = "default_clearance")]
    pub transition_clearance: f64,
    /// Quadratic-model search step (default: on for 3-axis only, as in the thesis).
    #[serde(default)]
    pub model_search: Option<bool>,
    /// Constraint handling: `"progressive"` (default) or `"extreme"`.
    #[serde(default = "default_barrier")]
    pub barrier: BarrierWord,
}

/// `optimize.surrogate_cost`: a number or `"measured"`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(untagged)]
pub enum SurrogateCostSpec {
    /// A fixed ratio.
    Ratio(f64),
    /// `"measured"`.
    Named(String),
}

impl Default for SurrogateCostSpec {
    fn default() -> Self {
        SurrogateCostSpec::Ratio(0.05)
    }
}

fn default_k_min() -> i64 {
    2
}
fn default_k_max() -> i64 {
    10
}
fn default_budget() -> f64 {
    1000.0
}
fn default_surrogate() -> SurrogateWord {
    SurrogateWord::S3
}
fn default_omega() -> [f64; 4] {
    [1.0; 4]
}
fn default_grid() -> [i64; 2] {
    [80, 80]
}
fn default_surrogate_grid() -> [i64; 2] {
    [40, 40]
}
fn default_step() -> f64 {
    0.5
}
fn default_surrogate_step() -> f64 {
    5.0
}
fn default_surrogate_sh() -> f64 {
    0.1
}
fn default_transition() -> TransitionWord {
    TransitionWord::Retract
}
fn default_barrier() -> BarrierWord {
    BarrierWord::Progressive
}

/// Why a job file is unusable: the TOML parser's message with line and column,
/// or the key and the fix.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum JobError {
    /// Syntax, unknown key, missing key or wrong type (line and column included).
    #[error("{0}")]
    Toml(String),
    /// Keys that name no setting (misspelt or misplaced), all of them.
    #[error("unknown keys {}: check their spelling and table against docs/job.md", keys.join(", "))]
    UnknownKeys {
        /// Each key's dotted path, with its line when found.
        keys: Vec<String>,
    },
    /// A value of one `[[operation]]` that makes no sense.
    #[error("operation {index} (`{name}`): {source}")]
    Operation {
        /// 1-based position in the file.
        index: usize,
        /// Its name.
        name: String,
        /// What is wrong (keys relative to the operation).
        source: Box<JobError>,
    },
    /// An operation names a tool number that the tool library lacks.
    #[error(
        "{}tool {number} is not in the tool library: add a [[tool]] with number = {number} to it, or use one of {known:?}",
        line.map(|l| format!("line {l}: ")).unwrap_or_default()
    )]
    UnknownTool {
        /// The number asked for.
        number: u32,
        /// The line of the `tool = ` key, when found.
        line: Option<usize>,
        /// The numbers the library has.
        known: Vec<u32>,
    },
    /// A value that makes no sense.
    #[error("`{key}` = {value}: {fix}")]
    Value {
        /// The key, e.g. `cutter.diameter`.
        key: &'static str,
        /// The value given.
        value: String,
        /// What to do.
        fix: &'static str,
    },
}

/// The file as written; every key that names no setting is collected, and
/// all of them are reported together with their lines.
fn parse_raw(text: &str) -> Result<RawJob, JobError> {
    let toml_error = |e: toml::de::Error| {
        let message = e.to_string().trim_end().to_string();
        match e.span().and_then(|span| key_at(text, span.start)) {
            Some(key) => JobError::Toml(format!("`{key}`: {message}")),
            None => JobError::Toml(message),
        }
    };
    let de = toml::Deserializer::parse(text).map_err(toml_error)?;
    let mut unknown = Vec::new();
    let raw: RawJob =
        serde_ignored::deserialize(de, |path| unknown.push(path.to_string().replace(".?", ""))).map_err(toml_error)?;
    if unknown.is_empty() {
        return Ok(raw);
    }
    let keys = unknown
        .iter()
        .map(|path| match line_of(text, path) {
            Some(line) => format!("`{path}` (line {line})"),
            None => format!("`{path}`"),
        })
        .collect::<Vec<_>>();
    Err(JobError::UnknownKeys { keys })
}

/// The dotted key set on the line holding byte `offset` (`table.key`), when
/// that line is a `key = value` line.
pub(crate) fn key_at(text: &str, offset: usize) -> Option<String> {
    let start = text.get(..offset)?.rfind('\n').map_or(0, |i| i + 1);
    let line = text[start..].lines().next()?;
    let key = line.split_once('=')?.0.trim();
    if key.is_empty() || key.starts_with('[') || key.starts_with('#') {
        return None;
    }
    let table = text[..start]
        .lines()
        .rev()
        .map(str::trim)
        .find(|l| l.starts_with('['))
        .map(|l| l.trim_start_matches('[').split(']').next().unwrap_or("").trim().to_string());
    Some(match table {
        Some(t) if !t.is_empty() => format!("{t}.{key}"),
        _ => key.to_string(),
    })
}

/// The 1-based line where the last part of a dotted key path is set, if
/// found (`name = ...` or `[name]`, the first such line).
pub(crate) fn line_of(text: &str, path: &str) -> Option<usize> {
    let key = path.rsplit('.').next()?;
    text.lines()
        .position(|l| {
            let l = l.trim_start();
            let rest = l.strip_prefix(key).map(str::trim_start);
            rest.is_some_and(|r| r.starts_with('=')) || l.trim_end().ends_with(&format!("{key}]")) && l.starts_with('[')
        })
        .map(|i| i + 1)
}

/// The operations of a job file: its `[[operation]]`s, or one finishing
/// operation of `[cutter]` and `[finishing]`.
fn normalise(raw: RawJob, text: &str, library: Option<&ToolLibrary>) -> Result<JobFile, JobError> {
    let missing =
        |key| JobError::Value { key, value: "missing".into(), fix: "give [cutter] and [finishing], or [[operation]]s" };
    let operation_list = !raw.operation.is_empty();
    let operations = if operation_list {
        if raw.cutter.is_some() || raw.finishing.is_some() {
            return Err(JobError::Value {
                key: "cutter, finishing",
                value: "given with [[operation]]".into(),
                fix: "put the cutter and the finishing settings in each [[operation]] ([operation.cutter], [operation.finishing])",
            });
        }
        let mut ops = raw.operation;
        for (k, op) in ops.iter_mut().enumerate() {
            if op.name.is_empty() {
                op.name = format!("operation {}", k + 1);
            }
        }
        ops
    } else {
        let cutter = match raw.cutter {
            Some(cutter) => cutter,
            None if library.is_some() && raw.output.tool > 0 => CutterSpec::unset(),
            None => return Err(missing("cutter")),
        };
        let finishing = raw.finishing.ok_or_else(|| missing("finishing"))?;
        vec![OperationSpec {
            kind: OperationKind::Finish,
            name: "finish".into(),
            tool: (library.is_some() && raw.output.tool > 0).then_some(raw.output.tool),
            spindle: None,
            spindle_from_library: false,
            feed_from_library: false,
            cutter,
            feed: None,
            finishing,
            roughing: None,
            rough5: None,
        }]
    };
    let mut operations = operations;
    resolve_tools(&mut operations, text, library, operation_list)?;
    if let Some(stock) = &raw.stock {
        check_stock(stock)?;
    }
    // The job's finishing settings: the first finishing operation's.
    let finishing = operations.iter().find(|o| o.kind == OperationKind::Finish).unwrap_or(&operations[0]);
    Ok(JobFile {
        part: raw.part,
        cutter: operations[0].cutter.clone(),
        finishing: finishing.finishing.clone(),
        stock: raw.stock,
        operations,
        operation_list,
        tolerances: raw.tolerances,
        machine: raw.machine,
        verify: raw.verify,
        optimize: raw.optimize,
        output: raw.output,
        setup: raw.setup,
        tool_library: raw.tool_library,
    })
}

/// Gives every operation that names a tool of `library` (and no cutter of its
/// own) that tool's cutter, and its spindle speed and feed where the operation
/// gives none; an operation left without a cutter is an error naming its line.
fn resolve_tools(
    ops: &mut [OperationSpec],
    text: &str,
    library: Option<&ToolLibrary>,
    listed: bool,
) -> Result<(), JobError> {
    for (k, op) in ops.iter_mut().enumerate() {
        if !op.cutter.is_unset() {
            continue;
        }
        let line = if listed { operation_key_line(text, k, "tool") } else { line_of(text, "output.tool") };
        let (Some(library), Some(number)) = (library, op.tool) else {
            return Err(JobError::Operation {
                index: k + 1,
                name: op.name.clone(),
                source: Box::new(JobError::Value {
                    key: "cutter",
                    value: "missing".into(),
                    fix: "give [operation.cutter], or `tool = N` with `tool_library = \"tools.toml\"` at the top of the job",
                }),
            });
        };
        let Some(tool) = library.get(number) else {
            return Err(JobError::UnknownTool { number, line, known: library.numbers() });
        };
        op.cutter = tool.cutter();
        op.spindle_from_library = op.spindle.is_none() && tool.spindle_speed().is_some();
        op.feed_from_library = op.feed.is_none() && tool.feed().is_some();
        op.spindle = op.spindle.or(tool.spindle_speed());
        op.feed = op.feed.or(tool.feed());
    }
    Ok(())
}

/// The 1-based line of `key = ...` inside the `k`-th `[[operation]]` (0-based),
/// before the next table header.
fn operation_key_line(text: &str, k: usize, key: &str) -> Option<usize> {
    let mut seen = 0;
    let mut inside = false;
    for (i, line) in text.lines().enumerate() {
        let l = line.trim_start();
        if l.starts_with("[[operation]]") {
            inside = seen == k;
            seen += 1;
        } else if l.starts_with('[') {
            inside = inside && l.starts_with("[operation.");
        } else if inside && l.strip_prefix(key).is_some_and(|r| r.trim_start().starts_with('=')) {
            return Some(i + 1);
        }
    }
    None
}

/// The `tool_library` path a job file names (relative to the job file), read
/// before the job is parsed: the caller reads that library and passes it to
/// [`parse_job_with_tools`]. `None` for text that is not TOML or names none.
#[must_use]
pub fn tool_library_of(text: &str) -> Option<String> {
    let table: toml::Table = toml::from_str(text).ok()?;
    table.get("tool_library")?.as_str().map(str::to_string)
}

fn check_stock(stock: &StockSpec) -> Result<(), JobError> {
    let bad = |key, value: String, fix| Err(JobError::Value { key, value, fix });
    match (stock.min, stock.max) {
        (Some(min), Some(max)) => {
            if stock.margin.is_some() || stock.top.is_some() || stock.bottom.is_some() {
                return bad(
                    "stock",
                    "corners and margins".into(),
                    "give either min and max, or margin, top and bottom",
                );
            }
            let finite = min.iter().chain(&max).all(|v| v.is_finite());
            if !finite || (0..3).any(|i| max[i] <= min[i]) {
                return bad(
                    "stock.max",
                    format!("{max:?} (min {min:?})"),
                    "give finite corners with max > min on every axis",
                );
            }
        }
        (None, None) => {
            for (key, v) in [("stock.margin", stock.margin), ("stock.top", stock.top), ("stock.bottom", stock.bottom)] {
                if let Some(v) = v
                    && !(v.is_finite() && v >= 0.0)
                {
                    return bad(key, v.to_string(), "give a margin in mm, >= 0");
                }
            }
        }
        _ => return bad("stock", "one corner".into(), "give both min and max"),
    }
    Ok(())
}

/// Parses and checks a job file.
///
/// # Errors
/// [`JobError`] naming the line or the key.
pub fn parse_job(text: &str) -> Result<JobFile, JobError> {
    parse_job_with_tools(text, None)
}

/// Parses and checks a job file whose operations may name tools of `library`
/// (the file its `tool_library` names, [`tool_library_of`]).
///
/// ```
/// use scallop_io::{job::parse_job_with_tools, tools::parse_tool_library};
/// let lib = parse_tool_library("[[tool]]\nnumber = 2\nshape = \"ball\"\ndiameter = 6\nflutes = 2\nflute_length = 20\nspindle = 12000\nfz = 0.05\n").unwrap();
/// let job = "tool_library = \"tools.toml\"\n[part]\nbuiltin = \"choi\"\n\
///     [[operation]]\nkind = \"finish\"\ntool = 2\n[operation.finishing]\nscallop_height = 0.01\n";
/// let job = parse_job_with_tools(job, Some(&lib)).unwrap();
/// assert_eq!((job.cutter.diameter, job.operations[0].spindle, job.operations[0].feed), (6.0, Some(12000.0), Some(1200.0)));
/// let err = parse_job_with_tools(&job_text_with_tool(9), Some(&lib)).unwrap_err().to_string();
/// assert!(err.starts_with("line 6: tool 9 is not in the tool library"), "{err}");
/// # fn job_text_with_tool(n: u32) -> String { format!("tool_library = \"t.toml\"\n[part]\nbuiltin = \"choi\"\n[[operation]]\nkind = \"finish\"\ntool = {n}\n[operation.finishing]\nscallop_height = 0.01\n") }
/// ```
///
/// # Errors
/// [`JobError`] naming the line or the key.
pub fn parse_job_with_tools(text: &str, library: Option<&ToolLibrary>) -> Result<JobFile, JobError> {
    let raw = parse_raw(text)?;
    if raw.tool_library.is_some() && library.is_none() {
        return Err(JobError::Value {
            key: "tool_library",
            value: "not read".into(),
            fix: "read the library it names and parse with parse_job_with_tools",
        });
    }
    let job = normalise(raw, text, library)?;
    let bad = |key, value: f64, fix| Err(JobError::Value { key, value: value.to_string(), fix });
    let given = [job.part.file.is_some(), job.part.builtin.is_some(), job.part.test_part.is_some()];
    if given.iter().filter(|g| **g).count() != 1 {
        return Err(JobError::Value {
            key: "part",
            value: if given.contains(&true) { "more than one of file, builtin and test_part" } else { "missing" }
                .into(),
            fix: "give exactly one of `file`, `builtin` and `test_part`",
        });
    }
    check_rough5_job(&job)?;
    let positive = |v: f64| v.is_finite() && v > 0.0;
    let operations = job.operations.clone();
    for (k, op) in operations.iter().enumerate() {
        let checked = match op.kind {
            OperationKind::Finish => check_finish_kind(op).and_then(|()| check_cutting(&op.cutter, &op.finishing)),
            OperationKind::Rough => check_rough(op),
            OperationKind::Rest if k == 0 => Err(JobError::Value {
                key: "kind",
                value: "rest".into(),
                fix: "rest roughing machines what earlier operations left: put a kind = \"rough\" operation before it",
            }),
            OperationKind::Rest => check_rough(op),
            OperationKind::Rough5 => check_rough5(op),
        };
        checked.map_err(|e| {
            if job.operation_list {
                JobError::Operation { index: k + 1, name: op.name.clone(), source: Box::new(e) }
            } else {
                e
            }
        })?;
        if let Some(t) = op.spindle
            && !(t.is_finite() && t >= 0.0)
        {
            return Err(JobError::Operation {
                index: k + 1,
                name: op.name.clone(),
                source: Box::new(JobError::Value {
                    key: "spindle",
                    value: t.to_string(),
                    fix: "give the spindle speed in 1/min, >= 0",
                }),
            });
        }
        if let Some(f) = op.feed
            && !positive(f)
        {
            return Err(JobError::Operation {
                index: k + 1,
                name: op.name.clone(),
                source: Box::new(JobError::Value {
                    key: "feed",
                    value: f.to_string(),
                    fix: "give the feed in mm/min, > 0",
                }),
            });
        }
    }
    let sh = job.finishing.scallop_height;
    for (key, v) in [
        ("tolerances.path", job.tolerances.path),
        ("machine.feed", job.machine.feed),
        ("machine.acceleration", job.machine.acceleration),
        ("machine.jerk", job.machine.jerk),
        ("machine.rapid", job.machine.rapid),
        ("machine.clearance", job.machine.clearance),
        ("verify.resolution", job.verify.resolution),
    ] {
        if !positive(v) {
            return bad(key, v, "must be a finite number > 0");
        }
    }
    if !(job.tolerances.gouge.is_finite() && job.tolerances.gouge >= 0.0) {
        return bad("tolerances.gouge", job.tolerances.gouge, "must be >= 0");
    }
    if !(job.output.spindle.is_finite() && job.output.spindle >= 0.0) {
        return bad("output.spindle", job.output.spindle, "give the spindle speed in 1/min, >= 0");
    }
    if matches!(job.output.units, UnitsWord::M | UnitsWord::Cm) {
        return Err(JobError::Value {
            key: "output.units",
            value: job.output.units.word().into(),
            fix: "programs are written in \"mm\" (G21) or \"in\" (G20)",
        });
    }
    if let Some(setup) = &job.setup {
        if let Some(a) = setup.rotation_deg.iter().find(|a| !a.is_finite()) {
            return bad("setup.rotation_deg", *a, "give three finite angles in degrees");
        }
        if !(setup.tool_length.is_finite() && setup.tool_length >= 0.0) {
            return bad("setup.tool_length", setup.tool_length, "give the tool length in mm, >= 0");
        }
        if job.output.units != UnitsWord::Mm {
            return Err(JobError::Value {
                key: "output.units",
                value: job.output.units.word().into(),
                fix: "3+2 programs are written in mm: set it to \"mm\" or remove [setup]",
            });
        }
        if job.output.arc_fitting {
            return Err(JobError::Value {
                key: "output.arc_fitting",
                value: "true".into(),
                fix: "3+2 output has no arcs: set it to false or remove [setup]",
            });
        }
    }
    if let Some(o) = &job.optimize {
        check_optimize(o, sh)?;
    }
    Ok(job)
}

/// The checks of one cutter and its finishing settings (keys named as in a
/// single-operation job).
/// A finish operation has a finishing table and no roughing table.
fn check_finish_kind(op: &OperationSpec) -> Result<(), JobError> {
    if op.rough5.is_some() {
        return Err(JobError::Value {
            key: "rough5",
            value: "given".into(),
            fix: "[operation.rough5] belongs to kind = \"rough5\" operations",
        });
    }
    if op.roughing.is_some() {
        return Err(JobError::Value {
            key: "roughing",
            value: "given".into(),
            fix: "[operation.roughing] belongs to kind = \"rough\" and \"rest\" operations",
        });
    }
    if op.finishing.scallop_height.is_nan() {
        return Err(JobError::Value {
            key: "finishing",
            value: "missing".into(),
            fix: "give [operation.finishing] with scallop_height",
        });
    }
    Ok(())
}

/// A job with a test part has one operation, of kind rough5 (the tri-dexel
/// proof starts from the part's blank; the z-map stock of the other kinds holds
/// no undercut), and a rough5 operation needs a test part (its guide curves
/// need the bottom and flank faces, which a mesh file does not tag).
fn check_rough5_job(job: &JobFile) -> Result<(), JobError> {
    let rough5 = job.operations.iter().filter(|o| o.kind == OperationKind::Rough5).count();
    let bad = |key, value: &str, fix| Err(JobError::Value { key, value: value.into(), fix });
    if rough5 > 0 && job.part.test_part.is_none() {
        return bad(
            "part",
            "not a test part",
            "kind = \"rough5\" needs `part.test_part` (pocket, impeller or fitting): its guide curves need the \
             pocket's bottom and flank faces, which a mesh or surface file does not tag",
        );
    }
    if job.part.test_part.is_some() && (rough5 != 1 || job.operations.len() != 1) {
        return bad(
            "operation",
            "not one rough5 operation",
            "a job of a test part has exactly one [[operation]], of kind = \"rough5\" (the other kinds run on a \
             z-map stock, which holds no undercut)",
        );
    }
    if rough5 > 0 && job.setup.is_some() {
        return bad("setup", "given", "a rough5 operation sets its own tool axes: remove [setup]");
    }
    Ok(())
}

/// A rough5 operation: a torus, flat or ball cutter, `[operation.rough5]`
/// with finite, positive steps, a_e within the tool's diameter and a_p within
/// its flutes, and no finishing or roughing table.
fn check_rough5(op: &OperationSpec) -> Result<(), JobError> {
    let bad = |key, value: String, fix| Err(JobError::Value { key, value, fix });
    if op.cutter.shape == ShapeWord::Cone {
        return bad("cutter.shape", "cone".into(), "a rough5 tool is a torus (\"bull\"), \"flat\" or \"ball\"");
    }
    check_cutter(&op.cutter)?;
    let Some(r) = &op.rough5 else {
        return bad("rough5", "missing".into(), "give [operation.rough5] with ap and ae");
    };
    if !op.finishing.scallop_height.is_nan() || op.roughing.is_some() {
        return bad(
            "finishing, roughing",
            "given".into(),
            "a rough5 operation takes [operation.rough5], not [operation.finishing] or [operation.roughing]",
        );
    }
    for (key, v) in [
        ("rough5.ap", r.ap),
        ("rough5.ae", r.ae),
        ("rough5.voxel", r.voxel),
        ("rough5.step", r.step),
        ("rough5.max_angle_step_deg", r.max_angle_step_deg),
        ("rough5.max_azimuth_step_deg", r.max_azimuth_step_deg),
        ("rough5.resolution", r.resolution),
        ("rough5.sim_tolerance", r.sim_tolerance),
        ("rough5.feed_per_tooth", r.feed_per_tooth.unwrap_or(1.0)),
        ("rough5.tool_length", r.tool_length.unwrap_or(1.0)),
        ("rough5.air_feed", r.air_feed),
        ("rough5.air_clearance", r.air_clearance),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return bad(key, v.to_string(), "must be a finite number > 0");
        }
    }
    for (key, v) in [
        ("rough5.stock_to_leave", r.stock_to_leave),
        ("rough5.stock_to_leave_axial", r.stock_to_leave_axial.unwrap_or(0.0)),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            return bad(key, v.to_string(), "give the allowance in mm, >= 0");
        }
    }
    if r.ae > op.cutter.diameter {
        return bad("rough5.ae", r.ae.to_string(), "give a radial engagement of at most the cutter diameter");
    }
    let flutes = op.cutter.flute_length.unwrap_or(4.0 * op.cutter.diameter);
    if r.ap > flutes {
        return bad(
            "rough5.ap",
            r.ap.to_string(),
            "give an axial depth of cut of at most the flute length (cutter.flute_length, default 4 D)",
        );
    }
    if r.max_angle_step_deg > 90.0 || r.max_azimuth_step_deg > 180.0 {
        return bad(
            "rough5.max_angle_step_deg",
            format!("{} (azimuth {})", r.max_angle_step_deg, r.max_azimuth_step_deg),
            "give an angular step of at most 90 deg and an azimuth step of at most 180 deg",
        );
    }
    if let Some(z) = r.teeth
        && !(1..=64).contains(&z)
    {
        return bad("rough5.teeth", z.to_string(), "give a whole number of teeth, 1 to 64");
    }
    if r.teeth.is_some() != r.feed_per_tooth.is_some() {
        return bad("rough5.teeth", format!("{:?}", r.teeth), "give both teeth and feed_per_tooth, or neither");
    }
    if let Some(w) = &r.limit_weights {
        let key = "rough5.limit_weights";
        if w.len() != 3 {
            return bad(key, format!("{w:?}"), "give three weights [beta, phi, tau] (bounds, fluidity, pitch)");
        }
        if let Some(x) = w.iter().find(|x| !(x.is_finite() && **x >= 0.0)) {
            return bad(
                key,
                format!("{w:?}"),
                if x.is_nan() { "a weight is NaN: give finite weights >= 0" } else { "give finite weights >= 0" },
            );
        }
        if r.tilt == TiltWord::Zero {
            return bad(
                key,
                format!("{w:?}"),
                "per-pass weights orient tilted passes: remove them or use tilt = \"guides\"",
            );
        }
    }
    Ok(())
}

/// A rough operation: its cutter and `[operation.roughing]`, and no finishing table.
fn check_rough(op: &OperationSpec) -> Result<(), JobError> {
    check_cutter(&op.cutter)?;
    if op.rough5.is_some() {
        return Err(JobError::Value {
            key: "rough5",
            value: "given".into(),
            fix: "[operation.rough5] belongs to kind = \"rough5\" operations",
        });
    }
    let Some(r) = &op.roughing else {
        return Err(JobError::Value {
            key: "roughing",
            value: "missing".into(),
            fix: "give [operation.roughing] with stepdown and stepover",
        });
    };
    if !op.finishing.scallop_height.is_nan() {
        return Err(JobError::Value {
            key: "finishing",
            value: "given".into(),
            fix: "a rough operation takes [operation.roughing], not [operation.finishing]",
        });
    }
    let bad = |key, value: f64, fix| Err(JobError::Value { key, value: value.to_string(), fix });
    if !(r.stepdown.is_finite() && r.stepdown > 0.0) {
        return bad("roughing.stepdown", r.stepdown, "give the depth per level in mm, > 0");
    }
    if !(r.stepover.is_finite() && r.stepover > 0.0 && r.stepover <= 0.5) {
        return bad("roughing.stepover", r.stepover, "give a fraction of the cutter diameter in (0, 0.5]");
    }
    for (key, v) in [
        ("roughing.stock_to_leave", r.stock_to_leave),
        ("roughing.stock_to_leave_axial", r.stock_to_leave_axial.unwrap_or(0.0)),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            return bad(key, v, "give the allowance in mm, >= 0");
        }
    }
    Ok(())
}

/// The checks of one cutter and its finishing settings (keys named as in a
/// single-operation job).
fn check_cutting(cutter: &CutterSpec, finishing: &FinishingSpec) -> Result<(), JobError> {
    let bad = |key, value: f64, fix| Err(JobError::Value { key, value: value.to_string(), fix });
    let positive = |v: f64| v.is_finite() && v > 0.0;
    check_cutter(cutter)?;
    let sh = finishing.scallop_height;
    if !positive(sh) || sh >= cutter.diameter / 2.0 {
        return bad("finishing.scallop_height", sh, "need 0 < sh < the cutter radius (diameter / 2)");
    }
    if cutter.shape == ShapeWord::Bull && cutter.corner_radius.is_some_and(|r| sh >= r) {
        return bad("finishing.scallop_height", sh, "need 0 < sh < the bull-nose corner radius");
    }
    check_direction_and_leads(finishing)
}

/// The checks of a cutter alone (a job's `[cutter]` or a library tool).
pub(crate) fn check_cutter(cutter: &CutterSpec) -> Result<(), JobError> {
    let bad = |key, value: f64, fix| Err(JobError::Value { key, value: value.to_string(), fix });
    let positive = |v: f64| v.is_finite() && v > 0.0;
    if !positive(cutter.diameter) {
        return bad("cutter.diameter", cutter.diameter, "give the diameter in mm, > 0");
    }
    if cutter.shape == ShapeWord::Bull {
        match cutter.corner_radius {
            Some(r) if positive(r) && r <= cutter.diameter / 2.0 => {}
            Some(r) => return bad("cutter.corner_radius", r, "need 0 < r <= diameter / 2"),
            None => {
                return Err(JobError::Value {
                    key: "cutter.corner_radius",
                    value: "missing".into(),
                    fix: "a bull-nose cutter needs its corner radius",
                });
            }
        }
    }
    match (cutter.shape, cutter.angle_deg) {
        (ShapeWord::Cone, Some(a)) if a.is_finite() && a > 0.0 && a < 180.0 => {}
        (ShapeWord::Cone, Some(a)) => {
            return bad("cutter.angle_deg", a, "give the included tip angle, 0 < angle < 180");
        }
        (ShapeWord::Cone, None) => {
            return Err(JobError::Value {
                key: "cutter.angle_deg",
                value: "missing".into(),
                fix: "a cone cutter needs its included tip angle in degrees (90 for a 90° V cutter)",
            });
        }
        (_, Some(a)) => return bad("cutter.angle_deg", a, "only a cone cutter has a tip angle: remove it"),
        (_, None) => {}
    }
    for (key, v) in [
        ("cutter.flute_length", cutter.flute_length),
        ("cutter.shank_diameter", cutter.shank_diameter),
        ("cutter.shank_length", cutter.shank_length),
    ] {
        if let Some(v) = v
            && !positive(v)
        {
            return bad(key, v, "give the length in mm, > 0");
        }
    }
    for h in &cutter.holder {
        for v in [Some(h.length), Some(h.diameter), h.top_diameter].into_iter().flatten() {
            if !positive(v) {
                return bad("cutter.holder", v, "give each holder segment's length and diameters in mm, > 0");
            }
        }
    }
    Ok(())
}

/// The checks of a `[finishing]` table's direction, leads and step.
fn check_direction_and_leads(finishing: &FinishingSpec) -> Result<(), JobError> {
    let bad = |key, value: f64, fix| Err(JobError::Value { key, value: value.to_string(), fix });
    let positive = |v: f64| v.is_finite() && v > 0.0;
    match &finishing.direction {
        DirectionSpec::Named(n) if n != "auto" => {
            return Err(JobError::Value {
                key: "finishing.direction",
                value: n.clone(),
                fix: "use \"auto\" or an angle in degrees",
            });
        }
        DirectionSpec::Degrees(d) if !d.is_finite() => return bad("finishing.direction", *d, "give a finite angle"),
        _ => {}
    }
    let angle = finishing.lead_angle_deg;
    if !(angle.is_finite() && angle > 0.0 && angle < 90.0) {
        return bad("finishing.lead_angle_deg", angle, "need 0 < angle < 90 degrees");
    }
    for (key, v) in [
        ("finishing.lead_radius", finishing.lead_radius),
        ("finishing.lead_length", finishing.lead_length),
        ("finishing.max_step", finishing.max_step),
    ] {
        if !positive(v) {
            return bad(key, v, "must be a finite number > 0");
        }
    }
    Ok(())
}

fn check_optimize(o: &OptimizeSpec, sh: f64) -> Result<(), JobError> {
    let bad = |key, value: String, fix| Err(JobError::Value { key, value, fix });
    if o.k_max < 2 {
        return bad("optimize.k_max", o.k_max.to_string(), "give K_max >= 2 (the spec studies K = 2..10)");
    }
    if o.k_max > 64 {
        return bad("optimize.k_max", o.k_max.to_string(), "give K_max <= 64");
    }
    if o.k_min < 1 || o.k_min > o.k_max {
        return bad("optimize.k_min", o.k_min.to_string(), "give 1 <= k_min <= k_max");
    }
    if !(o.budget.is_finite() && o.budget >= 1.0) {
        return bad(
            "optimize.budget",
            o.budget.to_string(),
            "give at least 1 black-box evaluation per K (the spec uses 1000)",
        );
    }
    match &o.surrogate_cost {
        SurrogateCostSpec::Ratio(r) if !(r.is_finite() && *r >= 0.0) => {
            return bad("optimize.surrogate_cost", r.to_string(), "give a ratio >= 0 or \"measured\"");
        }
        SurrogateCostSpec::Named(n) if n != "measured" => {
            return bad("optimize.surrogate_cost", n.clone(), "give a ratio >= 0 or \"measured\"");
        }
        _ => {}
    }
    if let Some(w) = o.omega.iter().find(|w| !(0.0..=1.0).contains(*w)) {
        return bad("optimize.omega", w.to_string(), "clustering weights must lie in [0, 1]");
    }
    for (key, g) in [("optimize.grid", o.grid), ("optimize.surrogate_grid", o.surrogate_grid)] {
        if g.iter().any(|&n| !(2..=2000).contains(&n)) {
            return bad(key, format!("{g:?}"), "give [N_u, N_v] with 2 to 2000 cells each");
        }
    }
    for (key, v) in [
        ("optimize.step", o.step),
        ("optimize.surrogate_step", o.surrogate_step),
        ("optimize.transition_clearance", o.transition_clearance),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return bad(key, v.to_string(), "must be a finite number > 0 (mm)");
        }
    }
    let ssh = o.surrogate_scallop_height;
    if !(ssh.is_finite() && ssh >= sh) {
        return bad(
            "optimize.surrogate_scallop_height",
            ssh.to_string(),
            "give a scallop height >= finishing.scallop_height (S4 uses 0.1 mm)",
        );
    }
    Ok(())
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::float_cmp, reason = "tests: a panic is the failure report; defaults are exact")]
mod tests {
    use super::*;

    const BASE: &str = "[part]\nbuiltin = \"choi\"\n[cutter]\nshape = \"bull\"\ndiameter = 10\ncorner_radius = 2\n[finishing]\nscallop_height = 0.01\n";

    #[test]
    fn defaults_and_example_files_parse() {
        let job = parse_job(BASE).unwrap();
        assert_eq!(job.finishing.direction, DirectionSpec::Auto);
        assert_eq!(job.machine.feed, 5.0);
        for example in [
            include_str!("../../../examples/jobs/choi.toml"),
            include_str!("../../../examples/jobs/rubio.toml"),
            include_str!("../../../examples/jobs/choi-arcs.toml"),
            include_str!("../../../examples/jobs/choi-3plus2.toml"),
            include_str!("../../../examples/jobs/rubio-iso.toml"),
        ] {
            parse_job(example).unwrap();
        }
        let job = parse_job(&format!("{BASE}[optimize]\nformulation = \"3axis\"\n")).unwrap();
        let o = job.optimize.unwrap();
        assert_eq!((o.k_min, o.k_max, o.budget, o.grid, o.step), (2, 10, 1000.0, [80, 80], 0.5));
        assert_eq!(o.surrogate_cost, SurrogateCostSpec::Ratio(0.05));
        for example in [
            include_str!("../../../examples/jobs/optimize-choi-3axis.toml"),
            include_str!("../../../examples/jobs/optimize-choi-3plus2.toml"),
            include_str!("../../../examples/jobs/optimize-choi-heuristic.toml"),
            include_str!("../../../examples/jobs/optimize-rubio-3axis.toml"),
            include_str!("../../../examples/jobs/optimize-rubio-3plus2.toml"),
            include_str!("../../../examples/jobs/optimize-rubio-heuristic.toml"),
        ] {
            assert!(parse_job(example).unwrap().optimize.is_some());
        }
    }

    /// The finishing jobs of the real meshes (issue 15's table): one per part,
    /// cutter shape and scallop height, each naming a mesh of the shared models
    /// beside the repository, both scallop heights of the table and its cutter.
    #[test]
    fn the_real_mesh_finishing_examples_parse() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/jobs/finish");
        let mut count = 0;
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_stem().unwrap().to_string_lossy().into_owned();
            let job = parse_job(&std::fs::read_to_string(&path).unwrap()).unwrap();
            let file = job.part.file.as_deref().unwrap();
            let (part, rest) = name.rsplit_once('-').and_then(|(a, sh)| Some((a.rsplit_once('-')?, sh))).unwrap();
            assert!(file.starts_with("../../../../shared/models/"), "{name}: {file}");
            assert!(std::path::Path::new(file).file_stem().unwrap().to_string_lossy() == part.0, "{name}: {file}");
            assert_eq!(job.finishing.scallop_height, rest.parse::<f64>().unwrap(), "{name}");
            assert_eq!(job.cutter.shape, if part.1 == "ball" { ShapeWord::Ball } else { ShapeWord::Bull }, "{name}");
            count += 1;
        }
        assert_eq!(count, 56, "14 meshes x ball, bull-nose x sh 0.01, 0.05");
    }

    #[test]
    fn bad_jobs_name_the_key() {
        let cases = [
            (BASE.replace("diameter = 10", "diameter = -10"), "cutter.diameter"),
            (BASE.replace("scallop_height = 0.01", "scallop_height = 7"), "finishing.scallop_height"),
            (BASE.replace("corner_radius = 2", "corner_radius = 9"), "cutter.corner_radius"),
            (BASE.replace("corner_radius = 2\n", ""), "cutter.corner_radius"),
            (BASE.replace("\"bull\"", "\"lollipop\""), "cutter.shape"),
            (format!("{BASE}[machine]\njerk = 0\n"), "machine.jerk"),
            (format!("{BASE}[machine]\njerks = 40\n"), "jerks"),
            (format!("{BASE}direction = \"north\"\n"), "finishing.direction"),
            (BASE.replace("builtin = \"choi\"", "builtin = \"choi\"\nfile = \"a.stl\""), "part"),
            (BASE.replace("scallop_height = 0.01", "scallop_height = \"fine\""), "scallop_height"),
            (format!("{BASE}[optimize]\nformulation = \"5axis\"\n"), "optimize.formulation"),
            (format!("{BASE}[optimize]\nformulation = \"3axis\"\nk_max = 1\n"), "optimize.k_max"),
            (format!("{BASE}[optimize]\nformulation = \"3axis\"\nk_min = 0\n"), "optimize.k_min"),
            (format!("{BASE}[optimize]\nformulation = \"3axis\"\nbudget = 0\n"), "optimize.budget"),
            (format!("{BASE}[optimize]\nformulation = \"3+2\"\nomega = [1, 1, 1.5, 1]\n"), "optimize.omega"),
            (format!("{BASE}[optimize]\nformulation = \"3+2\"\nsurrogate = \"s9\"\n"), "optimize.surrogate"),
            (
                format!("{BASE}[optimize]\nformulation = \"3+2\"\nsurrogate_cost = \"free\"\n"),
                "optimize.surrogate_cost",
            ),
            (format!("{BASE}[optimize]\nformulation = \"3+2\"\ngrid = [80, 1]\n"), "optimize.grid"),
            (format!("{BASE}[optimize]\nformulation = \"3+2\"\nstep = 0\n"), "optimize.step"),
            (format!("{BASE}[optimize]\nformulation = \"3+2\"\ntransition = \"teleport\"\n"), "optimize.transition"),
            (format!("{BASE}[optimize]\nformulation = \"3+2\"\nbarier = \"extreme\"\n"), "barier"),
            (format!("{BASE}[optimize]\nk_max = 4\n"), "formulation"),
            (BASE.replace("scallop_height = 0.01", "scallop_height = 3"), "corner radius"),
            (BASE.replace("diameter = 10", "diameter = 10\nflute_length = -3"), "cutter.flute_length"),
            (format!("{BASE}[output]\nspindle = -1\n"), "output.spindle"),
            (format!("{BASE}[output]\nunits = \"m\"\n"), "output.units"),
            (format!("{BASE}[output]\nunits = \"ft\"\n"), "output.units"),
            (
                format!("{BASE}[setup]\nrotation_deg = [0, 30, 0]\nmachine = \"m\"\n[output]\nunits = \"in\"\n"),
                "output.units",
            ),
            (format!("{BASE}lead = \"loop\"\n"), "finishing.lead"),
            (format!("{BASE}strategy = \"spiral\"\n"), "finishing.strategy"),
            (format!("{BASE}iso_direction = \"w\"\n"), "finishing.iso_direction"),
            (format!("{BASE}lead = \"arc\"\nlead_radius = -2\n"), "finishing.lead_radius"),
            (format!("{BASE}lead = \"ramp\"\nlead_angle_deg = 90\n"), "finishing.lead_angle_deg"),
            (format!("{BASE}[output]\narcs = true\n"), "arcs"),
            (format!("{BASE}[setup]\nrotation_deg = [0, 30]\nmachine = \"m\"\n"), "rotation_deg"),
            (
                format!("{BASE}[setup]\nrotation_deg = [0, 30, 0]\nmachine = \"m\"\n[output]\narc_fitting = true\n"),
                "output.arc_fitting",
            ),
        ];
        for (text, key) in cases {
            let err = parse_job(&text).unwrap_err().to_string();
            assert!(err.contains(key), "{key}: {err}");
        }
    }

    #[test]
    fn a_machine_is_named_by_string_or_table_and_the_file_wins_over_its_dynamics() {
        let job = parse_job(&format!("machine = \"grbl-3axis\"\n{BASE}")).unwrap();
        assert_eq!(job.machine.description.as_deref(), Some("grbl-3axis"));
        assert_eq!(job.machine.clearance, MachineSpec::default().clearance);
        let job = parse_job(&format!("{BASE}[machine]\ndescription = \"m.toml\"\nclearance = 9\nfeed = 2\n")).unwrap();
        assert_eq!(
            (job.machine.description.as_deref(), job.machine.clearance, job.machine.feed),
            (Some("m.toml"), 9.0, 2.0)
        );
        assert_eq!(parse_job(BASE).unwrap().machine.description, None);
        for key in ["acceleration", "jerk", "rapid"] {
            let text = format!("{BASE}[machine]\ndescription = \"grbl-3axis\"\n{key} = 6\n");
            let err = parse_job(&text).unwrap_err().to_string();
            assert!(err.contains(key) && err.contains("remove"), "{err}");
        }
        let err = parse_job(&format!("{BASE}[machine]\ndescription = \"m\"\nfeeed = 2\n")).unwrap_err().to_string();
        assert!(err.contains("machine.feeed"), "{err}");
        let err = parse_job(&format!("machine = 3\n{BASE}")).unwrap_err().to_string();
        assert!(err.contains("machine"), "{err}");
    }

    #[test]
    fn every_unknown_key_is_reported_with_its_line() {
        let text = format!("{BASE}colour = 3\n[machine]\njerks = 40\nfeeed = 5\n");
        let err = parse_job(&text).unwrap_err();
        let JobError::UnknownKeys { keys } = &err else { panic!("{err}") };
        assert_eq!(keys.len(), 3, "{keys:?}");
        for (word, path) in [("colour", "finishing.colour"), ("jerks", "machine.jerks"), ("feeed", "machine.feeed")] {
            let line = text.lines().position(|l| l.starts_with(word)).unwrap() + 1;
            assert!(keys.contains(&format!("`{path}` (line {line})")), "{path} {line}: {keys:?}");
        }
    }

    #[test]
    fn operations_and_stock_are_read_and_checked() {
        let ops = "[part]\nbuiltin = \"choi\"\n[stock]\ntop = 4\n\
            [[operation]]\nkind = \"finish\"\n[operation.cutter]\nshape = \"ball\"\ndiameter = 8\n[operation.finishing]\nscallop_height = 0.2\n\
            [[operation]]\nkind = \"finish\"\nname = \"fine\"\ntool = 7\n[operation.cutter]\nshape = \"bull\"\ndiameter = 10\ncorner_radius = 2\n[operation.finishing]\nscallop_height = 0.01\n";
        let job = parse_job(ops).unwrap();
        assert!(job.operation_list);
        assert_eq!(job.operations.len(), 2);
        assert_eq!((job.operations[0].name.as_str(), job.operations[1].name.as_str()), ("operation 1", "fine"));
        assert_eq!((job.operations[1].tool, job.cutter.shape), (Some(7), ShapeWord::Ball));
        assert_eq!(job.stock.as_ref().and_then(|s| s.top), Some(4.0));
        // The single-operation form is one finishing operation.
        let one = parse_job(BASE).unwrap();
        assert!(!one.operation_list);
        assert_eq!(one.operations.len(), 1);
        assert_eq!(one.operations[0].cutter, one.cutter);
        // A bad value inside an operation names the operation and the key.
        let err = parse_job(&ops.replace("scallop_height = 0.01", "scallop_height = 4")).unwrap_err().to_string();
        assert!(err.starts_with("operation 2 (`fine`)") && err.contains("finishing.scallop_height"), "{err}");
        // Cutter tables beside operations, half a box, a stock upside down.
        let err = parse_job(&format!("{ops}[cutter]\nshape = \"ball\"\ndiameter = 3\n")).unwrap_err().to_string();
        assert!(err.contains("[[operation]]"), "{err}");
        let err = parse_job(&ops.replace("top = 4", "min = [0, 0, 0]")).unwrap_err().to_string();
        assert!(err.contains("both min and max"), "{err}");
        let err = parse_job(&ops.replace("top = 4", "min = [0, 0, 0]\nmax = [1, 1, -1]")).unwrap_err().to_string();
        assert!(err.contains("max > min"), "{err}");
        let err = parse_job(&ops.replace("kind = \"finish\"\nname", "kind = \"mill\"\nname")).unwrap_err().to_string();
        assert!(err.contains("unknown variant `mill`") && err.contains("operation.kind"), "{err}");
    }

    #[test]
    fn rough_operations_are_read_and_checked() {
        let rough = "[part]\nbuiltin = \"choi\"\n\
            [[operation]]\nkind = \"rough\"\n[operation.cutter]\nshape = \"flat\"\ndiameter = 6\n\
            [operation.roughing]\nstepdown = 2\nstepover = 0.2\nstock_to_leave = 0.3\n\
            [[operation]]\nkind = \"finish\"\n[operation.cutter]\nshape = \"ball\"\ndiameter = 4\n[operation.finishing]\nscallop_height = 0.01\n";
        let job = parse_job(rough).unwrap();
        let r = job.operations[0].roughing.as_ref().unwrap();
        assert_eq!((r.stepdown, r.stepover, r.stock_to_leave, r.stock_to_leave_axial), (2.0, 0.2, 0.3, None));
        assert_eq!((r.pattern, r.direction), (RoughPatternWord::Offset, MillingWord::Climb));
        let both = parse_job(&rough.replace("stock_to_leave = 0.3\n", "stock_to_leave = 0.3\ndirection = \"both\"\n"))
            .unwrap();
        assert_eq!(both.operations[0].roughing.as_ref().unwrap().direction, MillingWord::Both);
        // The job's finishing settings are the finishing operation's.
        assert!((job.finishing.scallop_height - 0.01).abs() < 1e-15);
        for (from, to, key) in [
            ("stepover = 0.2", "stepover = 0.7", "roughing.stepover"),
            ("stepdown = 2", "stepdown = 0", "roughing.stepdown"),
            ("stock_to_leave = 0.3", "stock_to_leave = -1", "roughing.stock_to_leave"),
            ("[operation.roughing]\nstepdown = 2\nstepover = 0.2\nstock_to_leave = 0.3\n", "", "roughing"),
            ("stepover = 0.2", "stepover = 0.2\npattern = \"spiral\"", "pattern"),
            ("stepover = 0.2", "stepover = 0.2\nstepovr = 1", "stepovr"),
        ] {
            let err = parse_job(&rough.replace(from, to)).unwrap_err().to_string();
            assert!(err.contains(key), "{to}: {err}");
        }
        // A finishing table on a rough operation, a finish operation without one.
        let err =
            parse_job(&rough.replace(
                "stock_to_leave = 0.3\n",
                "stock_to_leave = 0.3\n[operation.finishing]\nscallop_height = 0.1\n",
            ))
            .unwrap_err()
            .to_string();
        assert!(err.contains("operation 1") && err.contains("finishing"), "{err}");
        let err =
            parse_job(&rough.replace("[operation.finishing]\nscallop_height = 0.01\n", "")).unwrap_err().to_string();
        assert!(err.contains("operation 2") && err.contains("finishing"), "{err}");
        // Rest roughing reads as roughing, after an earlier operation only.
        let rest = rough.replace(
            "[[operation]]\nkind = \"finish\"",
            "[[operation]]\nkind = \"rest\"\n[operation.cutter]\nshape = \"flat\"\ndiameter = 2\n\
             [operation.roughing]\nstepdown = 1\nstepover = 0.2\nstock_to_leave = 0.3\n[[operation]]\nkind = \"finish\"",
        );
        let job = parse_job(&rest).unwrap();
        assert_eq!(job.operations[1].kind, OperationKind::Rest);
        assert!(job.operations[1].roughing.is_some());
        let first = rest.replacen("kind = \"rough\"", "kind = \"rest\"", 1);
        let err = parse_job(&first).unwrap_err().to_string();
        assert!(err.contains("operation 1") && err.contains("kind = \"rough\" operation before it"), "{err}");
    }

    #[test]
    fn rough5_operations_read_with_defaults_and_their_limits() {
        let job = "[part]\ntest_part = \"pocket\"\n[[operation]]\nkind = \"rough5\"\n\
            [operation.cutter]\nshape = \"bull\"\ndiameter = 10\ncorner_radius = 1.5\nflute_length = 30\n\
            [operation.rough5]\nap = 4\nae = 4.5\n";
        let parsed = parse_job(job).unwrap();
        assert_eq!(parsed.part.test_part, Some(TestPartWord::Pocket));
        let r = parsed.operations[0].rough5.as_ref().unwrap();
        assert_eq!((r.tilt, r.stock_to_leave, r.stock_to_leave_axial, r.voxel), (TiltWord::Guides, 0.5, None, 1.0));
        for (from, to, key) in [
            ("ap = 4", "ap = 31", "rough5.ap"),
            ("ap = 4", "ap = nan", "rough5.ap"),
            ("ae = 4.5", "ae = 0", "rough5.ae"),
            ("ae = 4.5", "ae = 11", "rough5.ae"),
            ("ae = 4.5", "ae = 4.5\nstock_to_leave = -1", "rough5.stock_to_leave"),
            ("ae = 4.5", "ae = 4.5\nteeth = 2", "rough5.teeth"),
            ("ae = 4.5", "ae = 4.5\nmax_angle_step_deg = 120", "rough5.max_angle_step_deg"),
            ("test_part = \"pocket\"", "test_part = \"gear\"", "unknown variant `gear`"),
            ("test_part = \"pocket\"", "file = \"a.stl\"", "part.test_part"),
            ("test_part = \"pocket\"", "test_part = \"pocket\"\nbuiltin = \"choi\"", "exactly one of"),
            ("kind = \"rough5\"", "kind = \"rough\"", "z-map stock"),
        ] {
            let err = parse_job(&job.replace(from, to)).unwrap_err().to_string();
            assert!(err.contains(key), "{to}: {err}");
        }
        // The collision corrections: none by default, the step-1 switch, or a list of steps.
        assert_eq!((r.correction.planar(), r.correction.spatial(), r.entry), (false, false, EntryWord::Auto));
        for (keys, planar, spatial, entry) in [
            ("correction = true", true, false, EntryWord::Auto),
            ("correction = false\nentry = \"side\"", false, false, EntryWord::Side),
            ("correction = [\"spatial\"]\nentry = \"helix\"", false, true, EntryWord::Helix),
            ("correction = [\"planar\", \"spatial\"]\nentry = \"ramp\"", true, true, EntryWord::Ramp),
        ] {
            let parsed = parse_job(&job.replace("ae = 4.5", &format!("ae = 4.5\n{keys}"))).unwrap();
            let r = parsed.operations[0].rough5.as_ref().unwrap();
            assert_eq!((r.correction.planar(), r.correction.spatial(), r.entry), (planar, spatial, entry), "{keys}");
        }
        for bad in ["correction = [\"sideways\"]", "correction = 1", "entry = \"plunge\""] {
            assert!(parse_job(&job.replace("ae = 4.5", &format!("ae = 4.5\n{bad}"))).is_err(), "{bad}");
        }
        // Per-pass weights: none by default, three finite weights >= 0 on a tilted program.
        assert_eq!(r.limit_weights, None);
        let weighted = parse_job(&job.replace("ae = 4.5", "ae = 4.5\nlimit_weights = [15, 1.2, 1]")).unwrap();
        assert_eq!(weighted.operations[0].rough5.as_ref().unwrap().limit_weights, Some(vec![15.0, 1.2, 1.0]));
        for (keys, why) in [
            ("limit_weights = [15, 1.2]", "three weights"),
            ("limit_weights = [15, 1.2, 1, 0]", "three weights"),
            ("limit_weights = [15, nan, 1]", "NaN"),
            ("limit_weights = [15, 1.2, -1]", ">= 0"),
            ("limit_weights = [15, 1.2, inf]", ">= 0"),
            ("limit_weights = [1, 1, 1]\ntilt = \"zero\"", "tilt"),
            ("limit_weights = \"mixed\"", "limit_weights"),
        ] {
            let err = parse_job(&job.replace("ae = 4.5", &format!("ae = 4.5\n{keys}"))).unwrap_err().to_string();
            assert!(err.contains("rough5.limit_weights") || err.contains("limit_weights"), "{keys}: {err}");
            assert!(err.contains(why), "{keys}: {err}");
        }
        // Air moves: on by default at 30 m/min with a 1 mm clearance; a feed must be positive.
        assert_eq!((r.air_moves, r.air_feed, r.air_clearance), (true, 30_000.0, 1.0));
        let off = parse_job(&job.replace("ae = 4.5", "ae = 4.5\nair_moves = false\nair_feed = 20000")).unwrap();
        let o = off.operations[0].rough5.as_ref().unwrap();
        assert_eq!((o.air_moves, o.air_feed), (false, 20_000.0));
        let err = parse_job(&job.replace("ae = 4.5", "ae = 4.5\nair_feed = -1")).unwrap_err().to_string();
        assert!(err.contains("rough5.air_feed"), "{err}");
    }
}
