//! The resume journal: a directory next to the output where every finished work unit is kept
//! as one small file — its chunks as the atlas file stores them (shuffled, deflated) and its
//! counts for the run's summary — written under a temporary name and renamed into place, with
//! a checksum.
//! A run killed at any moment leaves only whole, verifiable units behind; `--resume` keeps
//! them and computes the rest. The atlas file itself appears only when every unit is done.

use crate::error::{AtlasError, Result};
use crate::store::atlas_file::EncodedUnit;
use std::collections::BTreeSet;
use std::io::Write;
use std::path::{Path, PathBuf};

const MAGIC: &[u8; 8] = b"RATLUNIT";
const FINGERPRINT_FILE: &str = "fingerprint";
/// What was at the output path when the run started ([`output_identity`]).
const OUTPUT_FILE: &str = "output";

/// The bytes of the regular file at `path`; anything else at the path (a FIFO, a device, a
/// folder) is an error, found without waiting: a FIFO put in place of a journal's file was
/// opened for reading and waited on for a writer, and `--resume` hung beyond SIGTERM
/// (adversary pass 41).
fn read_regular(path: &Path) -> std::io::Result<Vec<u8>> {
    use std::io::Read;
    use std::os::unix::fs::OpenOptionsExt;
    let mut file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK)
        .open(path)?;
    if !file.metadata()?.is_file() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "not a regular file",
        ));
    }
    let mut bytes = Vec::new();
    file.read_to_end(&mut bytes)?;
    Ok(bytes)
}

/// [`read_regular`] as UTF-8 text.
fn read_text(path: &Path) -> std::io::Result<String> {
    String::from_utf8(read_regular(path)?)
        .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidData, e))
}

/// The journal of one output file.
#[derive(Debug)]
pub struct Journal {
    dir: PathBuf,
    fingerprint: u64,
}

impl Journal {
    /// The journal directory of the output `out`: `<out>.partial.d`.
    pub fn dir_for(out: &Path) -> PathBuf {
        crate::store::with_suffix(out, ".partial.d")
    }

    /// Starts an empty journal (the directory must not exist) of a run into `out`, noting
    /// what is at `out` now: the file the run was allowed to replace, or nothing.
    pub fn create(dir: &Path, fingerprint: u64, scene_text: &str, out: &Path) -> Result<Journal> {
        std::fs::create_dir(dir).map_err(|e| AtlasError::atlas(dir, e))?;
        std::fs::write(dir.join("scene.toml"), scene_text)
            .map_err(|e| AtlasError::atlas(dir, e))?;
        write_atomically(&dir.join(OUTPUT_FILE), output_identity(out).as_bytes())?;
        write_atomically(
            &dir.join(FINGERPRINT_FILE),
            format!("{fingerprint:016x}\n").as_bytes(),
        )?;
        Ok(Journal {
            dir: dir.to_path_buf(),
            fingerprint,
        })
    }

    /// Whether what is at `out` now is what was there when the run of the journal in `dir`
    /// started: the same file, unchanged, or nothing. `--resume` replaces only the file the
    /// interrupted run was allowed to replace (a file put at the path after the run started
    /// was replaced without a word: adversary pass 38).
    pub fn output_unchanged(dir: &Path, out: &Path) -> bool {
        read_text(&dir.join(OUTPUT_FILE)).is_ok_and(|noted| noted == output_identity(out))
    }

    /// The `name` of the scene whose run made the journal in `dir`, if its scene can be read.
    pub fn scene_name_in(dir: &Path) -> Option<String> {
        let text = read_text(&dir.join("scene.toml")).ok()?;
        let table = text.parse::<toml::Table>().ok()?;
        table.get("name")?.as_str().map(str::to_string)
    }

    /// Whether `dir` holds what [`Journal::create`] writes (its fingerprint file, or its
    /// scene before the fingerprint landed, or nothing yet when a run was killed just after
    /// making it): a directory the program may resume or remove.
    pub fn looks_like_one(dir: &Path) -> bool {
        dir.join(FINGERPRINT_FILE).is_file()
            || dir.join("scene.toml").is_file()
            || std::fs::read_dir(dir).is_ok_and(|mut entries| entries.next().is_none())
    }

    /// Opens an existing journal; refuses one of another scene or program version.
    pub fn open(dir: &Path, fingerprint: u64) -> Result<Journal> {
        let path = dir.join(FINGERPRINT_FILE);
        // (A damaged fingerprint said only "cannot parse integer from empty string":
        // adversary pass 42.)
        let damaged = |e: &dyn std::fmt::Display| {
            AtlasError::atlas(
                &path,
                format!(
                    "the journal's fingerprint is damaged ({e}): its units cannot be trusted; \
                     start over with --force"
                ),
            )
        };
        let text = read_text(&path).map_err(|e| damaged(&e))?;
        let found = u64::from_str_radix(text.trim(), 16).map_err(|e| damaged(&e))?;
        if found != fingerprint {
            return Err(AtlasError::Atlas {
                path: dir.display().to_string(),
                reason: "the interrupted run was of another scene, program version, shard \
                         (--shard) or component layout; resume it with the same scene, build \
                         and --shard, or use --force to start over"
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
        Self::units_listed_in(&self.dir)
    }

    /// The units with a file in the journal folder `dir`, whichever run made it.
    pub fn units_listed_in(dir: &Path) -> Result<BTreeSet<usize>> {
        let mut out = BTreeSet::new();
        for entry in std::fs::read_dir(dir).map_err(|e| AtlasError::atlas(dir, e))? {
            let entry = entry.map_err(|e| AtlasError::atlas(dir, e))?;
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

    /// Stores the finished unit `index`: its encoded chunks and its counts (`counts`, a
    /// fixed number of words that the caller defines).
    pub fn write(&self, index: usize, encoded: &EncodedUnit, counts: &[u64]) -> Result<()> {
        let path = self.unit_path(index);
        let tmp = path.with_extension("bin.tmp");
        let write = || -> std::io::Result<()> {
            let file = std::fs::File::create(&tmp)?;
            let mut w = Checked {
                inner: std::io::BufWriter::with_capacity(1 << 16, file),
                crc: crc32fast::Hasher::new(),
            };
            w.put(MAGIC)?;
            let chunks = encoded.chunks();
            for word in [
                self.fingerprint,
                index as u64,
                counts.len() as u64,
                chunks.len() as u64,
            ] {
                w.put(&word.to_le_bytes())?;
            }
            for c in counts {
                w.put(&c.to_le_bytes())?;
            }
            for chunk in chunks {
                w.put(&(chunk.len() as u64).to_le_bytes())?;
                w.put(chunk)?;
            }
            let sum = u64::from(w.crc.clone().finalize());
            w.inner.write_all(&sum.to_le_bytes())?;
            w.inner.flush()
        };
        write().map_err(|e| AtlasError::write_failed(&tmp, e))?;
        std::fs::rename(&tmp, &path).map_err(|e| {
            if path.is_dir() {
                AtlasError::atlas(
                    &path,
                    "a folder with files in it, where the journal keeps a unit's file: \
                     remove it and resume, or start over with --force",
                )
            } else {
                AtlasError::write_failed(&path, e)
            }
        })
    }

    /// A unit read back — its chunks and counts — if its file is there, whole, of this scene,
    /// with `chunks` chunks and `counts` counts; None otherwise (a damaged file is removed, and
    /// the unit is computed again).
    pub fn read(
        &self,
        index: usize,
        chunks: usize,
        counts: usize,
    ) -> Option<(EncodedUnit, Vec<u64>)> {
        let path = self.unit_path(index);
        let unit = read_regular(&path)
            .ok()
            .and_then(|bytes| self.decode(&bytes, index, chunks, counts));
        if unit.is_none() {
            // (Whatever is there, but a folder with something in it: an empty folder in a
            // unit's place made every resume fail where the unit was written again,
            // adversary pass 42.)
            let is_dir = std::fs::symlink_metadata(&path).is_ok_and(|m| m.is_dir());
            let _ = if is_dir {
                std::fs::remove_dir(&path)
            } else {
                std::fs::remove_file(&path)
            };
        }
        unit
    }

    fn decode(
        &self,
        bytes: &[u8],
        index: usize,
        chunks: usize,
        counts: usize,
    ) -> Option<(EncodedUnit, Vec<u64>)> {
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
            || word(24)? != counts as u64
            || word(32)? != chunks as u64
        {
            return None;
        }
        let mut at = 40;
        let mut values = Vec::with_capacity(counts);
        for _ in 0..counts {
            values.push(word(at)?);
            at += 8;
        }
        let mut data = Vec::with_capacity(chunks);
        for _ in 0..chunks {
            let len = usize::try_from(word(at)?).ok()?;
            at += 8;
            data.push(body.get(at..at.checked_add(len)?)?.to_vec());
            at += len;
        }
        (at == body.len()).then(|| (EncodedUnit::from_chunks(data), values))
    }

    /// Removes the journal (after the atlas file is in place).
    pub fn remove(self) -> Result<()> {
        match std::fs::remove_dir_all(&self.dir) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                Err(AtlasError::write_failed(&self.dir, e))
            }
            _ => Ok(()),
        }
    }
}

/// What is at `path`, as one line: `absent`, or the file's device, inode, size and time of
/// last change (what tells another file, or the same one rewritten, from it).
fn output_identity(path: &Path) -> String {
    let Ok(meta) = std::fs::symlink_metadata(path) else {
        return "absent\n".to_string();
    };
    let modified = meta
        .modified()
        .ok()
        .and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok())
        .map_or(0, |d| d.as_nanos());
    use std::os::unix::fs::MetadataExt;
    format!("{} {} {} {modified}\n", meta.dev(), meta.ino(), meta.len())
}

/// Writes `bytes` to `path` through a temporary file in the same directory and a rename, so
/// that after a killed process `path` is either absent or whole. Not flushed to disk: after a
/// power loss a unit file may be torn, which its checksum shows, and the unit is computed
/// again (a flush per unit would cost as much as computing it).
fn write_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    let mut tmp = path.as_os_str().to_os_string();
    tmp.push(".tmp");
    let tmp = PathBuf::from(tmp);
    let mut file = std::fs::File::create(&tmp).map_err(|e| AtlasError::atlas(&tmp, e))?;
    file.write_all(bytes)
        .map_err(|e| AtlasError::atlas(&tmp, e))?;
    drop(file);
    std::fs::rename(&tmp, path).map_err(|e| AtlasError::atlas(path, e))
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
