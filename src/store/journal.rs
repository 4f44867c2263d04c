//! The resume journal: a directory next to the output where every finished work unit is kept
//! as one small file, written under a temporary name and renamed into place, with a checksum.
//! A run killed at any moment leaves only whole, verifiable units behind; `--resume` keeps
//! them and computes the rest. The atlas file itself appears only when every unit is done.

use crate::atlas::{Block, Column, Kind, Variable, COMPONENT_SLOTS};
use crate::error::{AtlasError, Result};
use std::collections::BTreeSet;
use std::io::Write;
use std::path::{Path, PathBuf};

const MAGIC: &[u8; 8] = b"RATLUNIT";
const FINGERPRINT_FILE: &str = "fingerprint";

/// The journal of one output file.
#[derive(Debug)]
pub struct Journal {
    dir: PathBuf,
    fingerprint: u64,
}

fn io_error(path: &Path, e: impl std::fmt::Display) -> AtlasError {
    AtlasError::Atlas {
        path: path.display().to_string(),
        reason: e.to_string(),
    }
}

impl Journal {
    /// The journal directory of the output `out`: `<out>.partial.d`.
    pub fn dir_for(out: &Path) -> PathBuf {
        let mut name = out
            .file_name()
            .map(|n| n.to_os_string())
            .unwrap_or_default();
        name.push(".partial.d");
        out.with_file_name(name)
    }

    /// Starts an empty journal (the directory must not exist).
    pub fn create(dir: &Path, fingerprint: u64, scene_text: &str) -> Result<Journal> {
        std::fs::create_dir(dir).map_err(|e| io_error(dir, e))?;
        std::fs::write(dir.join("scene.toml"), scene_text).map_err(|e| io_error(dir, e))?;
        write_atomically(
            &dir.join(FINGERPRINT_FILE),
            format!("{fingerprint:016x}\n").as_bytes(),
        )?;
        Ok(Journal {
            dir: dir.to_path_buf(),
            fingerprint,
        })
    }

    /// Opens an existing journal; refuses one of another scene or program version.
    pub fn open(dir: &Path, fingerprint: u64) -> Result<Journal> {
        let path = dir.join(FINGERPRINT_FILE);
        let text = std::fs::read_to_string(&path).map_err(|e| io_error(&path, e))?;
        let found = u64::from_str_radix(text.trim(), 16).map_err(|e| io_error(&path, e))?;
        if found != fingerprint {
            return Err(AtlasError::Atlas {
                path: dir.display().to_string(),
                reason: "the interrupted run was of another scene (or program version); \
                         use --force to start over"
                    .into(),
            });
        }
        Ok(Journal {
            dir: dir.to_path_buf(),
            fingerprint,
        })
    }

    /// The directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    fn unit_path(&self, index: usize) -> PathBuf {
        self.dir.join(format!("unit-{index:08}.bin"))
    }

    /// The units with a file in the journal (not yet verified; [`Journal::read`] checks).
    pub fn listed_units(&self) -> Result<BTreeSet<usize>> {
        let mut out = BTreeSet::new();
        for entry in std::fs::read_dir(&self.dir).map_err(|e| io_error(&self.dir, e))? {
            let entry = entry.map_err(|e| io_error(&self.dir, e))?;
            let name = entry.file_name();
            let name = name.to_string_lossy();
            if let Some(i) = name
                .strip_prefix("unit-")
                .and_then(|s| s.strip_suffix(".bin"))
                .and_then(|s| s.parse().ok())
            {
                out.insert(i);
            }
        }
        Ok(out)
    }

    /// Stores the finished unit `index`: the cells `cells` of `block`.
    pub fn write(
        &self,
        index: usize,
        block: &Block,
        variables: &[Variable],
        cells: std::ops::Range<usize>,
    ) -> Result<()> {
        let path = self.unit_path(index);
        let tmp = path.with_extension("bin.tmp");
        let write = || -> std::io::Result<()> {
            let file = std::fs::File::create(&tmp)?;
            let mut w = Checked {
                inner: std::io::BufWriter::with_capacity(1 << 16, file),
                crc: crc32fast::Hasher::new(),
            };
            w.put(MAGIC)?;
            for word in [
                self.fingerprint,
                index as u64,
                cells.len() as u64,
                variables.len() as u64,
            ] {
                w.put(&word.to_le_bytes())?;
            }
            let mut buffer = Vec::new();
            for (v, c) in variables.iter().zip(&block.columns) {
                let width = if v.kind == Kind::CellFlag {
                    1
                } else {
                    COMPONENT_SLOTS
                };
                let range = cells.start * width..cells.end * width;
                match c {
                    Column::U8(x) => w.put(&x[range])?,
                    Column::F64(x) => {
                        buffer.clear();
                        buffer.extend(x[range].iter().flat_map(|v| v.to_le_bytes()));
                        w.put(&buffer)?;
                    }
                }
            }
            let sum = u64::from(w.crc.clone().finalize());
            w.inner.write_all(&sum.to_le_bytes())?;
            w.inner.flush()
        };
        write().map_err(|e| io_error(&tmp, e))?;
        std::fs::rename(&tmp, &path).map_err(|e| io_error(&path, e))
    }

    /// A unit read back, if its file is there, whole and of this scene; None otherwise (a
    /// damaged file is removed, and the unit is computed again).
    pub fn read(&self, index: usize, variables: &[Variable], cells: usize) -> Option<Block> {
        let path = self.unit_path(index);
        let bytes = std::fs::read(&path).ok()?;
        let block = self.decode(&bytes, index, variables, cells);
        if block.is_none() {
            let _ = std::fs::remove_file(&path);
        }
        block
    }

    fn decode(
        &self,
        bytes: &[u8],
        index: usize,
        variables: &[Variable],
        cells: usize,
    ) -> Option<Block> {
        let (body, sum) = bytes.split_at_checked(bytes.len().checked_sub(8)?)?;
        if u64::from(crc32fast::hash(body)) != u64::from_le_bytes(sum.try_into().ok()?) {
            return None;
        }
        let word = |at: usize| -> Option<u64> {
            Some(u64::from_le_bytes(body.get(at..at + 8)?.try_into().ok()?))
        };
        if body.get(..8)? != MAGIC
            || word(8)? != self.fingerprint
            || word(16)? != index as u64
            || word(24)? != cells as u64
            || word(32)? != variables.len() as u64
        {
            return None;
        }
        let mut at = 40;
        let mut columns = Vec::with_capacity(variables.len());
        for v in variables {
            let n = match v.kind {
                Kind::CellFlag => cells,
                Kind::Value | Kind::Flag => cells * COMPONENT_SLOTS,
            };
            columns.push(match v.kind {
                Kind::Value => {
                    let raw = body.get(at..at + 8 * n)?;
                    at += 8 * n;
                    Column::F64(
                        raw.chunks_exact(8)
                            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
                            .collect(),
                    )
                }
                Kind::Flag | Kind::CellFlag => {
                    let raw = body.get(at..at + n)?;
                    at += n;
                    Column::U8(raw.to_vec())
                }
            });
        }
        (at == body.len()).then_some(Block { cells, columns })
    }

    /// Removes the journal (after the atlas file is in place).
    pub fn remove(self) -> Result<()> {
        std::fs::remove_dir_all(&self.dir).map_err(|e| io_error(&self.dir, e))
    }
}

/// Writes `bytes` to `path` through a temporary file in the same directory and a rename, so
/// that after a killed process `path` is either absent or whole. Not flushed to disk: after a
/// power loss a unit file may be torn, which its checksum shows, and the unit is computed
/// again (a flush per unit would cost as much as computing it).
fn write_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    let mut tmp = path.as_os_str().to_os_string();
    tmp.push(".tmp");
    let tmp = PathBuf::from(tmp);
    let mut file = std::fs::File::create(&tmp).map_err(|e| io_error(&tmp, e))?;
    file.write_all(bytes).map_err(|e| io_error(&tmp, e))?;
    drop(file);
    std::fs::rename(&tmp, path).map_err(|e| io_error(path, e))
}

/// A writer that keeps a CRC-32 of what passes through.
struct Checked<W: Write> {
    inner: W,
    crc: crc32fast::Hasher,
}

impl<W: Write> Checked<W> {
    fn put(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        self.crc.update(bytes);
        self.inner.write_all(bytes)
    }
}
