//! Reading the user's input: the files a user names (a missing file is a
//! rejected input, exit code 1; any other I/O error a failure of the machine,
//! exit code 2) and the numbers that must be positive.

use std::path::Path;

use crate::{CliResult, Failure};

/// The bytes of `path`; `name` is how messages call the file (its path as the
/// user gave it), `what` what it holds (`"the program"`, `"the job file"`).
pub(crate) fn read_bytes(path: &Path, name: &str, what: &str) -> CliResult<Vec<u8>> {
    std::fs::read(path).map_err(|e| {
        let err = anyhow::anyhow!("{name}: cannot read {what}: {e}");
        if e.kind() == std::io::ErrorKind::NotFound { Failure::Rejected(err) } else { Failure::Io(err) }
    })
}

/// The UTF-8 text of `path`; `what` as in [`read_bytes`].
pub(crate) fn read_text(path: &Path, what: &str) -> CliResult<String> {
    let name = path.display().to_string();
    let bytes = read_bytes(path, &name, what)?;
    let text = scallop_io::utf8_text(&bytes).map_err(|e| Failure::rejected(format!("{name}: {e}")))?;
    Ok(text.to_owned())
}

/// Rejects the first flag of `flags` (flag, value) that is not a finite number > 0.
pub(crate) fn positive_flags(flags: &[(&str, f64)]) -> CliResult<()> {
    match scallop_geom::num::first_not_positive(flags) {
        Some((flag, v)) => Err(Failure::rejected(format!("{flag} {v}: must be a finite number > 0"))),
        None => Ok(()),
    }
}
