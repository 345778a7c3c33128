//! The crate's error type: every variant names the place and the fix.

use scallop_machine::MachineError;

/// What can go wrong when writing or reading back a program.
///
/// ```
/// let e = scallop_post::Dialect::builtin("nope").unwrap_err();
/// assert!(e.to_string().contains("nope"));
/// ```
#[non_exhaustive]
#[derive(Debug, thiserror::Error)]
pub enum PostError {
    /// The output failed.
    #[error("writing the program: {0}")]
    Io(#[from] std::io::Error),
    /// A dialect file does not parse or names an unknown dialect.
    /// Fix: correct the TOML as documented in `docs/post.md`.
    #[error("dialect: {problem}; fix: see docs/post.md")]
    Dialect {
        /// What is wrong.
        problem: String,
    },
    /// The dialect or the machine cannot express what the program needs.
    #[error("dialect `{dialect}`: {what} is not supported; fix: {fix}")]
    Unsupported {
        /// Dialect name.
        dialect: String,
        /// What cannot be written.
        what: String,
        /// How to proceed.
        fix: String,
    },
    /// Reading back: a line could not be understood.
    #[error("reading back, line {line}: {problem}")]
    Parse {
        /// 1-based line.
        line: usize,
        /// What is wrong.
        problem: String,
    },
    /// Reading back: the replayed tool tip or axis leaves the input path by more than
    /// the tolerance (spec K16). Fix: a post-processor bug, report it with the program.
    #[error("reading back, line {line}: {what} deviates {deviation:.6} from the input path (allowed {allowed:.6})")]
    Deviation {
        /// 1-based line.
        line: usize,
        /// `tip (mm)`, `tool axis (rad)`, `axis rate (ratio)` or `missing pose`.
        what: String,
        /// The deviation.
        deviation: f64,
        /// The allowance.
        allowed: f64,
    },
    /// The kinematics refused a pose or a word is outside its stroke.
    #[error("line {line}: {source}")]
    Machine {
        /// 1-based line of the output (0 while writing).
        line: usize,
        /// The machine layer's error (names the axis and the value).
        source: MachineError,
    },
}
