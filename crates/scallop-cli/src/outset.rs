//! Outputs as a set (issue 21): every file of one command goes into a staging folder
//! next to the target folder, and the set replaces the target in one step at the end,
//! so a run killed at any moment leaves either the previous complete set or the new one.
//!
//! - Staging: `PARENT/.NAME.tmp-PID/` (the target is `PARENT/NAME/`).
//! - Commit: on Linux the staging folder and the target are exchanged atomically
//!   (`renameat2(RENAME_EXCHANGE)`), then the old set (now in the staging path) is
//!   removed. Where the exchange is not available, the target is first renamed to
//!   `PARENT/.NAME.old-PID/`; a run killed between the two renames leaves the previous set
//!   there, and the next run puts it back before doing anything else.
//! - Files in the target folder that are not part of this kind of set (another command's
//!   outputs, the user's own files) are carried over into the new set by hard links; the
//!   previous set's own files are listed in its manifest `.scallop-set-KIND.json` and are
//!   not carried over, so sets never mix. A target folder holding sub-folders or the
//!   working folder (`-o .`), or on a file system without hard links, falls back to
//!   replacing the files one by one (each file whole, the set not atomic).
//! - Leftovers of killed runs (staging and old folders, `.FILE.tmp-PID` files) whose
//!   process is gone are removed (or, for an old set, restored) by the next run.

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::{CliResult, Failure};

/// One set of outputs being written.
pub struct OutputSet {
    parent: PathBuf,
    name: String,
    target: PathBuf,
    staging: PathBuf,
    kind: &'static str,
    files: Vec<String>,
    committed: bool,
    /// The target holds the working folder: files are replaced one by one, never the folder.
    in_place: bool,
}

fn io_err(path: &Path, what: &str, e: &std::io::Error) -> Failure {
    Failure::Io(anyhow::anyhow!("{}: cannot {what}: {e}", path.display()))
}

/// The process id in a leftover's name `.NAME.tmp-PID` / `.NAME.old-PID`, if it is one.
fn leftover_pid(entry: &str, name: &str, tag: &str) -> Option<u32> {
    entry.strip_prefix(&format!(".{name}.{tag}-"))?.parse().ok()
}

/// Whether process `pid` may still be running (always true for this process). Without
/// `/proc` every other process counts as gone.
fn alive(pid: u32) -> bool {
    pid == std::process::id() || Path::new("/proc").join(pid.to_string()).exists()
}

/// Removes leftovers of killed runs in `parent` for the target `name`: an old set is put
/// back when the target is missing (the previous complete set), the rest is removed.
/// Also removes `.FILE.tmp-PID` files of dead processes inside `target`.
pub fn clean_leftovers(parent: &Path, name: &str) -> CliResult<()> {
    let target = parent.join(name);
    let Ok(entries) = std::fs::read_dir(parent) else { return Ok(()) };
    let mut names: Vec<String> = entries.filter_map(|e| e.ok()?.file_name().into_string().ok()).collect();
    names.sort();
    for entry in &names {
        let old = leftover_pid(entry, name, "old");
        let tmp = leftover_pid(entry, name, "tmp");
        let Some(pid) = old.or(tmp) else { continue };
        if pid == std::process::id() || alive(pid) {
            continue;
        }
        let path = parent.join(entry);
        if old.is_some() && !target.exists() {
            std::fs::rename(&path, &target).map_err(|e| io_err(&path, "restore the previous outputs", &e))?;
            continue;
        }
        let removed = if path.is_dir() { std::fs::remove_dir_all(&path) } else { std::fs::remove_file(&path) };
        removed.map_err(|e| io_err(&path, "remove a leftover of an earlier run", &e))?;
    }
    if target.is_dir() {
        remove_stale_temporaries(&target);
    }
    Ok(())
}

/// Removes the `.FILE.tmp-PID` files of dead processes in `folder` (best effort).
pub fn remove_stale_temporaries(folder: &Path) {
    let Ok(entries) = std::fs::read_dir(folder) else { return };
    for entry in entries.flatten() {
        let Ok(file) = entry.file_name().into_string() else { continue };
        let Some((_, pid)) = file.strip_prefix('.').and_then(|f| f.rsplit_once(".tmp-")) else { continue };
        if let Ok(pid) = pid.parse::<u32>()
            && !alive(pid)
            && entry.path().is_file()
        {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

impl OutputSet {
    /// Starts a set of kind `kind` (one manifest per kind) for the folder `target`:
    /// cleans leftovers of earlier killed runs, creates the staging folder.
    ///
    /// # Errors
    /// I/O failures (exit code 2).
    pub fn begin(target: &Path, kind: &'static str) -> CliResult<OutputSet> {
        // `-o .` or `-o ..`: the folder by its real name. The working folder (or one
        // above it) is never exchanged: its files are replaced one by one instead.
        let real = std::fs::canonicalize(target).ok();
        let holds_cwd = real.as_ref().is_some_and(|r| std::env::current_dir().is_ok_and(|cwd| cwd.starts_with(r)));
        let target = match &real {
            Some(r) if target.file_name().is_none() => r.as_path(),
            _ => target,
        };
        let parent = target.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new(".")).to_path_buf();
        let name = target
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .ok_or_else(|| Failure::rejected(format!("{}: an output folder needs a name", target.display())))?;
        std::fs::create_dir_all(&parent).map_err(|e| io_err(&parent, "create the folder", &e))?;
        if target.exists() && !target.is_dir() {
            return Err(Failure::rejected(format!(
                "{}: is a file, not a folder; give an output folder with -o",
                target.display()
            )));
        }
        clean_leftovers(&parent, &name)?;
        let staging = parent.join(format!(".{name}.tmp-{}", std::process::id()));
        if staging.exists() {
            std::fs::remove_dir_all(&staging).map_err(|e| io_err(&staging, "remove", &e))?;
        }
        std::fs::create_dir(&staging).map_err(|e| io_err(&staging, "create the staging folder", &e))?;
        Ok(OutputSet {
            parent,
            name,
            target: target.to_path_buf(),
            staging,
            kind,
            files: Vec::new(),
            committed: false,
            in_place: holds_cwd,
        })
    }

    /// The final path of `file` in the target folder (for messages).
    pub fn final_path(&self, file: &str) -> PathBuf {
        self.target.join(file)
    }

    /// Writes `file` of the set into the staging folder (flushed and synced).
    ///
    /// # Errors
    /// I/O failures.
    pub fn write(&mut self, file: &str, bytes: &[u8]) -> CliResult<()> {
        let path = self.staging.join(file);
        let result = (|| -> std::io::Result<()> {
            let mut w = std::io::BufWriter::new(std::fs::File::create(&path)?);
            w.write_all(bytes)?;
            w.flush()?;
            w.get_ref().sync_all()
        })();
        result.map_err(|e| io_err(&self.final_path(file), "write", &e))?;
        self.files.push(file.to_string());
        Ok(())
    }

    fn manifest_name(&self) -> String {
        format!(".scallop-set-{}.json", self.kind)
    }

    /// Files of the target that the new set must keep: everything but this kind's
    /// previous set (its manifest and what it lists) and the new set's own names.
    /// `None` when the target holds a folder (no atomic swap then).
    fn carried_over(&self) -> Option<Vec<String>> {
        let Ok(entries) = std::fs::read_dir(&self.target) else { return Some(Vec::new()) };
        let manifest = self.target.join(self.manifest_name());
        let previous: Vec<String> = std::fs::read_to_string(&manifest)
            .ok()
            .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
            .and_then(|v| {
                v.get("files")?.as_array().map(|a| a.iter().filter_map(|f| f.as_str().map(str::to_string)).collect())
            })
            .unwrap_or_default();
        let mut keep = Vec::new();
        for entry in entries.flatten() {
            let file = entry.file_name().to_string_lossy().into_owned();
            if file == self.manifest_name() || previous.contains(&file) || self.files.contains(&file) {
                continue;
            }
            if file.starts_with('.') && file.contains(".tmp-") {
                continue; // a stale temporary of an older version
            }
            if !entry.path().is_file() {
                return None;
            }
            keep.push(file);
        }
        keep.sort();
        Some(keep)
    }

    /// Puts the set in place in one step and returns the paths written.
    ///
    /// # Errors
    /// I/O failures.
    pub fn commit(mut self) -> CliResult<Vec<PathBuf>> {
        let manifest = serde_json::json!({ "kind": self.kind, "files": self.files });
        let text = serde_json::to_string_pretty(&manifest).map_err(|e| Failure::Io(e.into()))?;
        let manifest_name = self.manifest_name();
        self.write(&manifest_name, format!("{text}\n").as_bytes())?;
        self.files.pop();
        let written: Vec<PathBuf> = self.files.iter().map(|f| self.target.join(f)).collect();
        if !self.target.exists() {
            std::fs::rename(&self.staging, &self.target)
                .map_err(|e| io_err(&self.target, "move the outputs into place", &e))?;
            self.committed = true;
            return Ok(written);
        }
        let Some(keep) = self.carried_over().filter(|_| !self.in_place) else {
            self.commit_file_by_file()?;
            return Ok(written);
        };
        for file in &keep {
            if std::fs::hard_link(self.target.join(file), self.staging.join(file)).is_err() {
                self.commit_file_by_file()?;
                return Ok(written);
            }
        }
        if exchange(&self.staging, &self.target).is_err() {
            let old = self.parent.join(format!(".{}.old-{}", self.name, std::process::id()));
            std::fs::rename(&self.target, &old).map_err(|e| io_err(&self.target, "move the previous outputs", &e))?;
            std::fs::rename(&self.staging, &self.target)
                .map_err(|e| io_err(&self.target, "move the outputs into place", &e))?;
            let _ = std::fs::remove_dir_all(&old);
            self.committed = true;
            return Ok(written);
        }
        // The staging path now holds the previous set.
        self.committed = true;
        let _ = std::fs::remove_dir_all(&self.staging);
        Ok(written)
    }

    /// The fallback for a target folder that holds sub-folders: each file renamed into
    /// place (each file whole, the set not atomic).
    fn commit_file_by_file(&mut self) -> CliResult<()> {
        let mut names = self.files.clone();
        names.push(self.manifest_name());
        for file in &names {
            let to = self.target.join(file);
            std::fs::rename(self.staging.join(file), &to).map_err(|e| io_err(&to, "move into place", &e))?;
        }
        self.committed = true;
        let _ = std::fs::remove_dir_all(&self.staging);
        Ok(())
    }
}

impl Drop for OutputSet {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_dir_all(&self.staging);
        }
    }
}

/// Exchanges two paths atomically (Linux `renameat2(RENAME_EXCHANGE)`).
#[cfg(target_os = "linux")]
fn exchange(a: &Path, b: &Path) -> std::io::Result<()> {
    rustix::fs::renameat_with(rustix::fs::CWD, a, rustix::fs::CWD, b, rustix::fs::RenameFlags::EXCHANGE)
        .map_err(std::io::Error::from)
}

/// No atomic exchange here: the caller falls back to two renames.
#[cfg(not(target_os = "linux"))]
fn exchange(_a: &Path, _b: &Path) -> std::io::Result<()> {
    Err(std::io::Error::new(std::io::ErrorKind::Unsupported, "no atomic exchange"))
}
