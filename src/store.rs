//! Writing tables ([`crate::table`]: trajectories, sampled bifurcation and resonance curves)
//! as CSV or HDF5, chosen by the file's extension; the atlas file and the resume journal
//! (with the `hdf5` feature). Files are written to a temporary name and renamed into place, so
//! a failed write never leaves a partial output behind.

#[cfg(feature = "hdf5")]
pub mod atlas_file;
#[cfg(feature = "hdf5")]
mod h5;
#[cfg(feature = "hdf5")]
pub mod journal;

use crate::cf::{self, AttrValue};
use crate::error::{AtlasError, Result};
use crate::table::{Table, Values};
use std::io::Write;
use std::path::{Path, PathBuf};

/// A file format for a table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TableFormat {
    Csv,
    Hdf5,
}

impl TableFormat {
    /// The format named by a path's extension: `.csv`, or `.h5` / `.hdf5` / `.nc`.
    pub fn from_path(path: &Path) -> Result<Self> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("csv") => Ok(Self::Csv),
            Some("h5") | Some("hdf5") | Some("nc") => Ok(Self::Hdf5),
            _ => Err(AtlasError::Output {
                path: path.display().to_string(),
                reason: "unknown extension: use .csv, .h5 or .hdf5".into(),
            }),
        }
    }
}

fn output_error(path: &Path, e: impl std::fmt::Display) -> AtlasError {
    AtlasError::Output {
        path: path.display().to_string(),
        reason: e.to_string(),
    }
}

/// Checks an output path before any work is done (issue 13): it must name a file (not end in
/// a separator) with one of `extensions`, in an existing folder; if something is there it
/// must be a regular file — never a directory, a device, a FIFO or a symlink, even with
/// `force` — and is replaced only with `force`; and it must not be one of the command's
/// `inputs`.
pub fn check_output(path: &Path, force: bool, inputs: &[&Path], extensions: &[&str]) -> Result<()> {
    let refuse = |reason: String| Err(output_error(path, reason));
    let text = path.as_os_str().to_string_lossy();
    if text.is_empty() || text.ends_with(std::path::MAIN_SEPARATOR) {
        return refuse("is a folder, not a file name".into());
    }
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_lowercase())
        .unwrap_or_default();
    if !extensions.contains(&ext.as_str()) {
        return refuse(format!(
            "unknown extension {:?} (expected {})",
            ext,
            extensions
                .iter()
                .map(|e| format!(".{e}"))
                .collect::<Vec<_>>()
                .join(", ")
        ));
    }
    // (HDF5 takes a file's name as UTF-8 only: a run into another name was refused by it
    // after its journal was made, which then blocked every later run: adversary pass 43.)
    if matches!(ext.as_str(), "h5" | "hdf5") && path.to_str().is_none() {
        return refuse(
            "is not UTF-8, and the HDF5 library takes only UTF-8 file names: choose another \
             name (a .csv table may have any name)"
                .into(),
        );
    }
    // (A finished atlas by that name was refused by open_atlas as an unfinished run's file:
    // adversary pass of 2026-11-27.)
    if text.to_lowercase().ends_with(".partial.h5") {
        return refuse(
            "ends in .partial.h5, the name of a run's unfinished file (open_atlas refuses such \
             a file): choose another name"
                .into(),
        );
    }
    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        if !parent.is_dir() {
            return refuse(format!("the folder {} does not exist", parent.display()));
        }
        // (Not inside a run's resume journal, which that run removes whole when it ends: a
        // table written there was deleted with it, without a word to either: adversary pass
        // 42. Also where a link leads there.)
        fn journal(folder: &Path) -> Option<&Path> {
            folder.ancestors().find(|a| {
                a.file_name()
                    .is_some_and(|n| n.to_string_lossy().to_lowercase().ends_with(".partial.d"))
            })
        }
        let real = std::fs::canonicalize(parent).ok();
        if let Some(folder) = journal(parent).or_else(|| real.as_deref().and_then(journal)) {
            return refuse(format!(
                "lies inside {}, a folder named as a run's resume journal, which that run \
                 removes when it ends: choose another folder",
                folder.display()
            ));
        }
    }
    match std::fs::symlink_metadata(path) {
        Ok(meta) if !meta.file_type().is_file() => {
            let kind = if meta.file_type().is_dir() {
                "a directory"
            } else if meta.file_type().is_symlink() {
                "a symbolic link"
            } else {
                "not a regular file (a device, FIFO or socket)"
            };
            return refuse(format!(
                "is {kind}; refusing to replace it, even with --force"
            ));
        }
        Ok(_) => {
            let same = |input: &&&Path| match (
                std::fs::canonicalize(path),
                std::fs::canonicalize(input),
            ) {
                (Ok(a), Ok(b)) => a == b,
                _ => false,
            };
            if let Some(input) = inputs.iter().find(same) {
                return refuse(format!(
                    "is an input of this command ({}); never written over",
                    input.display()
                ));
            }
            if !force {
                return refuse("exists; use --force to overwrite it".into());
            }
        }
        Err(_) => {}
    }
    Ok(())
}

/// An exclusive claim on an output: held from before the first check of the output and its
/// journal until the finished file is in place, so that a second run (or merge) on the same
/// output is refused at once instead of writing the same temporary file. It is an advisory
/// `flock` on `<out>.lock`, which the kernel releases when the process ends however it ends
/// (a SIGKILL leaves the file but never a held lock); the file holds the holder's PID for
/// the message, and is removed when the claim is dropped.
#[derive(Debug)]
pub struct OutputLock {
    file: std::fs::File,
    path: PathBuf,
}

impl OutputLock {
    /// Claims `out`, or says which process holds it.
    pub fn acquire(out: &Path) -> Result<OutputLock> {
        use std::os::unix::fs::MetadataExt;
        let path = with_suffix(out, ".lock");
        let fail = |reason: String| AtlasError::Busy {
            path: out.display().to_string(),
            reason,
        };
        // A claim on a lock file that the previous holder unlinked meanwhile would be no
        // claim at all: lock, then check that the path still names the locked file.
        // Never through a symbolic link (the PID would be written into its target, and the
        // link removed at the end) and only into a regular file.
        let not_ours = |reason: &str| {
            output_error(
                &path,
                format!("{reason}, and a run keeps its lock file at this path; move it away (the program never removes it)"),
            )
        };
        for _ in 0..100 {
            use std::os::unix::fs::OpenOptionsExt;
            let file = std::fs::OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK)
                .open(&path)
                .map_err(|e| {
                    if e.raw_os_error() == Some(libc::ELOOP) {
                        not_ours("is a symbolic link")
                    } else {
                        // (Named by the output asked for: in /proc the lock file cannot be
                        // made, and its name alone left the user to guess why.)
                        output_error(
                            out,
                            format!("its lock file {} cannot be created: {e}", path.display()),
                        )
                    }
                })?;
            if !file.metadata().is_ok_and(|m| m.is_file()) {
                return Err(not_ours("is not a regular file"));
            }
            match file.try_lock() {
                Ok(()) => {}
                Err(std::fs::TryLockError::WouldBlock) => {
                    let holder = std::fs::read_to_string(&path).unwrap_or_default();
                    let holder = holder.trim();
                    return Err(fail(if holder.is_empty() {
                        "another rubber-atlas process is writing it; wait for it to end or choose another --out".into()
                    } else {
                        format!("another rubber-atlas process ({holder}) is writing it; wait for it to end or choose another --out")
                    }));
                }
                Err(std::fs::TryLockError::Error(e)) => return Err(output_error(&path, e)),
            }
            let same = match (file.metadata(), std::fs::metadata(&path)) {
                (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
                _ => false,
            };
            if !same {
                continue;
            }
            let mut file = file;
            let holder = format!(
                "pid {} on {}",
                std::process::id(),
                std::fs::read_to_string("/proc/sys/kernel/hostname")
                    .map(|h| h.trim().to_string())
                    .unwrap_or_default()
            );
            let _ = file.set_len(0);
            let _ = file.write_all(holder.as_bytes());
            return Ok(OutputLock { file, path });
        }
        Err(fail(
            "its lock file keeps changing under this process".into(),
        ))
    }

    /// Whether the lock file's path still names the file this claim locked. A lock file
    /// removed while its run was writing (by hand, or by a clean-up script after a
    /// preemption) lets a second process claim the output afresh, remove the partial file and
    /// journal, and write its own: the first run, renaming `<out>.partial.h5` by name, would
    /// publish the other's half-written file as its own, with a success summary (adversary
    /// pass of 2026-11-28). Checked before a finished file is put in place.
    pub fn is_held(&self) -> bool {
        use std::os::unix::fs::MetadataExt;
        match (self.file.metadata(), std::fs::symlink_metadata(&self.path)) {
            (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
            _ => false,
        }
    }

    /// [`Self::is_held`], or the error that says the output was not put in place.
    pub fn check_held(&self, out: &Path) -> Result<()> {
        if self.is_held() {
            return Ok(());
        }
        Err(AtlasError::Busy {
            path: out.display().to_string(),
            reason: format!(
                "its lock file {} was removed while this process wrote it, so another process \
                 may have claimed the output and written its partial file since; the output is \
                 not replaced: run again when no other process writes it",
                self.path.display()
            ),
        })
    }
}

impl Drop for OutputLock {
    fn drop(&mut self) {
        // Unlinked while still held: a process that opened the old file finds it unlinked
        // (above) and tries again with a fresh one. (Not another's: where this claim's file
        // was removed, the path may name a second process's lock by now.)
        if self.is_held() {
            let _ = std::fs::remove_file(&self.path);
        }
        let _ = self.file.unlock();
    }
}

/// `path` with `suffix` appended to its file name (`x.h5` → `x.h5<suffix>`), in the same
/// directory: where an output is written before it is renamed into place.
pub(crate) fn with_suffix(path: &Path, suffix: &str) -> PathBuf {
    let mut name = path
        .file_name()
        .map(|n| n.to_os_string())
        .unwrap_or_default();
    name.push(suffix);
    path.with_file_name(name)
}

fn temp_path(path: &Path) -> PathBuf {
    with_suffix(path, &format!(".partial-{}", std::process::id()))
}

/// Writes `bytes` to `path` by way of a temporary name beside it, renamed into place (a
/// manual page; the path checked by [`check_output`] first).
pub fn write_bytes(path: &Path, bytes: &[u8]) -> Result<()> {
    let tmp = temp_path(path);
    std::fs::write(&tmp, bytes)
        .and_then(|()| std::fs::rename(&tmp, path))
        .map_err(|e| {
            let _ = std::fs::remove_file(&tmp);
            output_error(path, e)
        })
}

/// Writes `table` to `path`, as CSV (`# key: value` comment lines for the attributes, a
/// header, then rows: shortest round-trip decimals) or HDF5 (one 1-D variable per column
/// along the table's dimension, whose coordinate is a dimension scale; CF attributes).
pub fn write_table(path: &Path, table: &Table) -> Result<()> {
    write_table_until(path, table, &|| false)
}

/// [`write_table`], given up with [`AtlasError::Stopped`] and nothing at `path` when `stop`
/// says so (asked before the file is renamed into place, every 65,536 CSV rows and every
/// 2^20 rows of an HDF5 column).
pub fn write_table_until(path: &Path, table: &Table, stop: &dyn Fn() -> bool) -> Result<()> {
    let format = TableFormat::from_path(path)?;
    if stop() {
        return Err(AtlasError::Stopped);
    }
    let tmp = temp_path(path);
    let written = match format {
        TableFormat::Csv => write_csv(&tmp, table, stop),
        #[cfg(feature = "hdf5")]
        TableFormat::Hdf5 => write_hdf5(&tmp, table, stop),
        #[cfg(not(feature = "hdf5"))]
        TableFormat::Hdf5 => Err("built without the hdf5 feature: write .csv".to_string()),
    };
    let failed = match (written, stop()) {
        (_, true) => Some(AtlasError::Stopped),
        (Err(e), false) => Some(output_error(path, e)),
        (Ok(()), false) => None,
    };
    if let Some(e) = failed {
        let _ = std::fs::remove_file(&tmp);
        return Err(e);
    }
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        output_error(path, e)
    })
}

fn write_csv(
    path: &Path,
    table: &Table,
    stop: &dyn Fn() -> bool,
) -> std::result::Result<(), String> {
    let file = std::fs::File::create(path).map_err(|e| e.to_string())?;
    let mut w = std::io::BufWriter::new(file);
    let io = |e: std::io::Error| e.to_string();
    writeln!(w, "# Conventions: {}", cf::CONVENTIONS).map_err(io)?;
    for (k, v) in &table.attributes {
        writeln!(w, "# {k}: {}", v.display().replace('\n', " ")).map_err(io)?;
    }
    // The columns with their types (a reader can tell an edited header, and give the index
    // and flag columns back their integer types), then the number of rows, last: a reader
    // can tell a file cut short at a line's end.
    let columns: Vec<String> = table
        .columns
        .iter()
        .map(|c| {
            let kind = match c.values {
                Values::F64(_) => "float64",
                Values::I32(_) => "int32",
                Values::U8(_) => "uint8",
            };
            format!("{}:{kind}", c.name)
        })
        .collect();
    writeln!(w, "# columns: {}", columns.join(" ")).map_err(io)?;
    writeln!(w, "# rows: {}", table.rows()).map_err(io)?;
    let mut csv = csv::Writer::from_writer(w);
    let text = |e: csv::Error| e.to_string();
    csv.write_record(table.columns.iter().map(|c| c.name))
        .map_err(text)?;
    let mut record = Vec::with_capacity(table.columns.len());
    for i in 0..table.rows() {
        if i % 65_536 == 0 && stop() {
            return Err("stopped".into());
        }
        record.clear();
        record.extend(table.columns.iter().map(|c| match &c.values {
            Values::F64(v) => format!("{:e}", v[i]),
            Values::I32(v) => v[i].to_string(),
            Values::U8(v) => v[i].to_string(),
        }));
        csv.write_record(&record).map_err(text)?;
    }
    let mut w = csv.into_inner().map_err(|e| e.to_string())?;
    w.flush().map_err(io)?;
    w.get_ref().sync_all().map_err(io)
}

#[cfg(feature = "hdf5")]
fn write_hdf5(
    path: &Path,
    table: &Table,
    stop: &dyn Fn() -> bool,
) -> std::result::Result<(), String> {
    use h5::{attach_scale, describe, set_scale, text_attr, write_attr};
    let file = hdf5::File::create(path).map_err(|e| e.to_string())?;
    let inner = || -> hdf5::Result<()> {
        text_attr(&file, "Conventions", cf::CONVENTIONS)?;
        for (k, v) in &table.attributes {
            write_attr(&file, k, v)?;
        }
        let mut scale: Option<hdf5::Dataset> = None;
        // Written a million rows at a time, asking `stop` between (a diagram of 5e7 samples
        // writes several GB: in one call per column Ctrl-C waited up to 6 s).
        const ROWS: usize = 1 << 20;
        fn column<T: hdf5::H5Type>(
            file: &hdf5::File,
            name: &str,
            values: &[T],
            stop: &dyn Fn() -> bool,
        ) -> hdf5::Result<hdf5::Dataset> {
            let d = file.new_dataset::<T>().shape(values.len()).create(name)?;
            for (i, part) in values.chunks(ROWS).enumerate() {
                if stop() {
                    return Err("stopped".into());
                }
                d.write_slice(part, i * ROWS..i * ROWS + part.len())?;
            }
            Ok(d)
        }
        for c in &table.columns {
            let d = match &c.values {
                Values::F64(v) => column(&file, c.name, v, stop)?,
                Values::I32(v) => column(&file, c.name, v, stop)?,
                Values::U8(v) => column(&file, c.name, v, stop)?,
            };
            describe(&d, c.long_name, c.units)?;
            if let Some(flags) = c.flags {
                h5::flags(&d, flags)?;
            }
            match &scale {
                None if c.name == table.dimension => {
                    set_scale(&d, c.name)?;
                    scale = Some(d);
                }
                None => return Err("a table's first column is its dimension".into()),
                Some(s) => attach_scale(&d, s, 0)?,
            }
        }
        Ok(())
    };
    inner().map_err(|e| e.to_string())?;
    file.close().map_err(|e| e.to_string())?;
    if stop() {
        return Err("stopped".into());
    }
    std::fs::File::open(path)
        .and_then(|f| f.sync_all())
        .map_err(|e| e.to_string())
}

/// The root attributes naming what made a file: the program, its version and its git
/// commit (every atlas, table and Python result carries them).
pub fn program_attributes() -> Vec<(String, AttrValue)> {
    vec![
        ("program".into(), AttrValue::Text("rubber-atlas".into())),
        (
            "program_version".into(),
            AttrValue::Text(env!("CARGO_PKG_VERSION").into()),
        ),
        (
            "git_commit".into(),
            AttrValue::Text(env!("RUBBER_ATLAS_GIT_COMMIT").into()),
        ),
    ]
}
