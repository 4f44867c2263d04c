//! A whole atlas run (`rubber-atlas run`) and the merge of shards (`rubber-atlas merge`):
//! the work units of the scene (or of one shard) are computed slice by slice into the resume
//! journal, then written to the HDF5 file, which is renamed into place only when complete.
//! Memory stays at one slice's worth whatever the grid.

use crate::atlas::{
    self, compute_rows, Block, Region, Shard, Unit, Variable, COMPONENT_SLOTS, FLAG_FILL,
};
use crate::error::{AtlasError, Result};
use crate::family::ComponentAxis;
use crate::scene::Scene;
use crate::store::atlas_file::{encode_unit, AtlasFile, AttrValue, EncodedUnit};
use crate::store::journal::Journal;
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What the caller is told while a run goes on.
pub trait Progress: Sync {
    /// The run starts: `total` cells in this run (or shard), `done` of them already in the
    /// journal of an interrupted run.
    fn begin(&self, _total: u64, _done: u64) {}
    /// `cells` more cells are done.
    fn advance(&self, _cells: u64) {}
    /// A unit counted as done at [`Progress::begin`] (`cells` cells, listed in the journal)
    /// turned out damaged and is computed again.
    fn retract(&self, _cells: u64) {}
    /// A unit stopped part way (the run was asked to stop) is dropped: the `cells` of it
    /// already counted by [`Progress::advance`] are not done after all.
    fn dropped(&self, _cells: u64) {}
    /// The component axis is being laid out from the grid's critical points (the census,
    /// before [`Progress::begin`]; long only for grids of very many bodies and κ-rows).
    fn laying_out(&self) {}
    /// Every unit is computed; the HDF5 file is being written.
    fn writing(&self) {}
    /// Whether the run should stop (the caller got SIGINT or SIGTERM): no new unit is started,
    /// and those in flight are dropped between two cells (a resumed run computes them again).
    fn interrupted(&self) -> bool {
        false
    }
}

/// A progress sink that says nothing.
pub struct Silent;
impl Progress for Silent {}

/// Counts over the cells and components of a run.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Summary {
    /// Cells in the file (or in the shard).
    pub cells: u64,
    /// Components over those cells.
    pub components: u64,
    /// Cells by `cell_status`: ok, no_motion, failed.
    pub cells_by_status: [u64; 3],
    /// Components by `status`: ok, tolerance_not_reached, fixed_point, separatrix,
    /// high_energy_limit, reaches_face.
    pub components_by_status: [u64; 6],
    /// Work units of this run, and how many of them an interrupted run had finished.
    pub units: usize,
    pub units_resumed: usize,
    /// Cells computed by this invocation (0 for a merge).
    pub cells_computed: u64,
    /// Wall time, seconds.
    pub seconds: f64,
    /// The output was already complete and current (`RunRequest::update`): nothing done.
    pub up_to_date: bool,
}

impl Summary {
    /// Words of a unit's counts in the journal.
    const WORDS: usize = 11;

    /// The counts of a unit, for the journal.
    fn words(&self) -> [u64; Self::WORDS] {
        let [a, b, c] = self.cells_by_status;
        let [d, e, f, g, h, i] = self.components_by_status;
        [self.cells, self.components, a, b, c, d, e, f, g, h, i]
    }

    fn from_words(w: &[u64]) -> Summary {
        Summary {
            cells: w[0],
            components: w[1],
            cells_by_status: [w[2], w[3], w[4]],
            components_by_status: [w[5], w[6], w[7], w[8], w[9], w[10]],
            ..Summary::default()
        }
    }

    fn add(&mut self, other: &Summary) {
        self.cells += other.cells;
        self.components += other.components;
        self.cells_computed += other.cells_computed;
        self.units_resumed += other.units_resumed;
        for (a, b) in self.cells_by_status.iter_mut().zip(other.cells_by_status) {
            *a += b;
        }
        for (a, b) in self
            .components_by_status
            .iter_mut()
            .zip(other.components_by_status)
        {
            *a += b;
        }
    }

    fn count(&mut self, variables: &[Variable], block: &Block) {
        self.cells += block.cells as u64;
        if let Some(status) = block.flags(variables, "cell_status") {
            for &s in status {
                self.cells_by_status[usize::from(s.min(2))] += 1;
            }
        }
        // The components stored (at κ = 0 mirror images of one family share a slot).
        if let Some(family) = block.flags(variables, "family") {
            self.components += family.iter().filter(|&&f| f != FLAG_FILL).count() as u64;
        }
        if let Some(status) = block.flags(variables, "status") {
            for &s in status {
                if let Some(count) = self.components_by_status.get_mut(usize::from(s)) {
                    *count += 1;
                }
            }
        }
    }
}

/// How to run a scene.
#[derive(Debug, Clone)]
pub struct RunRequest {
    pub out: PathBuf,
    /// Continue an interrupted run from its journal.
    pub resume: bool,
    /// Replace an existing output, and discard an interrupted run's journal.
    pub force: bool,
    /// Bring the output up to date (a Slurm task's mode): keep it if it was made from this
    /// scene by this build for this shard, continue an interrupted run of the same, and
    /// compute everything else afresh, replacing what is stale.
    pub update: bool,
    /// With `update`: whether the existing output is current ([`output_is_current`], which
    /// the caller may ask in a child process). An output that is not is replaced.
    pub output_current: bool,
    pub shard: Shard,
    /// Attributes the caller adds to the file's root (command line, creation time).
    pub attributes: Vec<(String, AttrValue)>,
}

/// Removes what a stopped run may have left at its temporary file's path: a file, or a link
/// (never its target), also a dangling one, which `exists` does not see (the file was then
/// created beside it and HDF5 refused in a line of its internals: adversary pass 42).
fn remove_stale(tmp: &Path) -> Result<()> {
    if std::fs::symlink_metadata(tmp).is_ok() {
        std::fs::remove_file(tmp).map_err(|e| AtlasError::atlas(tmp, e))?;
    }
    Ok(())
}

/// `<out>.partial.h5`: where the file is written before it is renamed into place.
fn temporary_path(out: &Path) -> PathBuf {
    crate::store::with_suffix(out, ".partial.h5")
}

/// The root attributes every atlas file carries: provenance and the scene.
fn scene_attributes(scene: &Scene, shard: Shard, units: usize) -> Vec<(String, AttrValue)> {
    let text = |s: &str| AttrValue::Text(s.to_string());
    let mut attributes = vec![(
        "title".into(),
        text(&format!("rubber-atlas atlas of scene {}", scene.name)),
    )];
    attributes.extend(crate::store::program_attributes());
    attributes.extend([
        ("scene_name".into(), text(&scene.name)),
        ("scene".into(), text(&scene.text)),
        (
            "scene_fingerprint".into(),
            text(&format!("{:016x}", scene.fingerprint())),
        ),
    ]);
    // The ellipsoid's files are as they always were; another shape names itself.
    if scene.shape.is_some() {
        attributes.push(("shape".into(), text(scene.shape_name())));
    }
    // A profile's table, one `rho z edge` row a line (it is in the scene's text too).
    if let Some(crate::EdgedKind::Profile(profile)) = scene.shape {
        attributes.push(("profile".into(), text(&profile.text())));
    }
    attributes.extend([
        ("nu".into(), AttrValue::Number(scene.nu)),
        ("eta".into(), AttrValue::Number(scene.eta)),
        ("tolerance".into(), AttrValue::Number(scene.options.tol)),
        (
            "method".into(),
            text(match scene.options.method {
                crate::cell::Method::Quadrature => "quadrature",
                crate::cell::Method::Ode => "ode",
            }),
        ),
        (
            "resonance_tol".into(),
            AttrValue::Number(scene.options.resonance_tol),
        ),
        ("shard_index".into(), AttrValue::Integer(shard.index as i64)),
        ("shard_count".into(), AttrValue::Integer(shard.count as i64)),
        ("unit_count".into(), AttrValue::Integer(units as i64)),
    ]);
    attributes
}

fn borrowed(attributes: &[(String, AttrValue)]) -> Vec<(&str, AttrValue)> {
    attributes
        .iter()
        .map(|(k, v)| (k.as_str(), v.clone()))
        .collect()
}

/// What a run of a scene (or of one shard of it) needs, estimated from the grid alone
/// before anything is allocated: the caller compares it with the machine.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Footprint {
    /// Cells this run computes.
    pub cells: f64,
    /// Disk at the peak: the journal and the file side by side, uncompressed (an upper
    /// bound: the file's chunks are deflated).
    pub disk_bytes: f64,
    /// Memory at the peak: the largest batch of units (a slice, or several small ones),
    /// computed and encoded before it is written, plus one unit per thread, and the list of
    /// the journal's units.
    pub memory_bytes: f64,
}

/// The [`Footprint`] of running `shard` of `scene` on `threads` threads.
pub fn footprint(scene: &Scene, shard: Shard, threads: usize) -> Footprint {
    let shape = scene.shape();
    // In floating point: the grid may be too large for its unit count to fit a usize.
    let [na, nb, nk, ne] = shape.map(|n| n as f64);
    let rows = atlas::rows_per_unit(shape) as f64;
    let betas = atlas::betas_per_unit(shape) as f64;
    let per_slice = (nk / rows).ceil();
    let total = na * (nb / betas).ceil() * per_slice;
    // This shard's share of the units: its box of the layout (the largest one), or all.
    let share = match shard.layout(shape) {
        Some(counts) => Region::positions(shape)
            .iter()
            .zip(counts)
            .map(|(&p, c)| p.div_ceil(c) as f64)
            .product(),
        None => total,
    };
    let unit_cells = betas * rows * ne;
    // The component axis before its census: at most every slot of the layout.
    let slots = ComponentAxis::full(
        scene.layout,
        crate::family::Family::possible_for(scene.shape.as_ref()),
        COMPONENT_SLOTS,
    )
    .len();
    let bytes_per_cell = atlas::scene_variables(scene)
        .iter()
        .map(|v| v.kind.bytes_per_cell(slots))
        .sum::<usize>() as f64;
    // The cells themselves, not the units' (a unit at the end of a slice, or a group of β
    // at its end, is short): a grid of 1e4 α × 1e4 β and one cell each was 1.229e8 cells.
    // The disk and the memory stay those of whole units (HDF5 stores a short chunk whole):
    // bounds for the largest shard.
    let cells = na * nb * nk * ne * share / total;
    let unit_bound = share * unit_cells;
    let batch = (share.min(per_slice) * unit_cells).max((BATCH_CELLS as f64).min(unit_bound));
    // A BTreeSet<usize> of the journal's units: about 3 words an entry.
    let journal_list = share * 24.0;
    Footprint {
        cells,
        disk_bytes: 2.0 * unit_bound * bytes_per_cell,
        memory_bytes: journal_list + (2.0 * batch + threads as f64 * unit_cells) * bytes_per_cell,
    }
}

/// Whether `out` is an atlas made from `scene` (its text and this build: the fingerprint)
/// for this shard, and intact ([`AtlasFile::is_intact`]). A damaged file can crash HDF5
/// itself (a length in its global heap read as written): a caller that must survive that
/// asks this in a child process, as `run --update` does, and passes the answer in
/// [`RunRequest::output_current`].
pub fn output_is_current(out: &Path, scene: &Scene, shard: Shard) -> bool {
    let Ok(axis) = AtlasFile::read_axis(out) else {
        return false;
    };
    let region = shard.region(scene.shape());
    let Ok(file) = AtlasFile::open(out, scene, &region, &atlas::scene_variables(scene), &axis)
    else {
        return false;
    };
    file.text_attribute("scene_fingerprint").as_deref()
        == Some(format!("{:016x}", scene.fingerprint()).as_str())
        && file.integer_attribute("shard_index") == Some(shard.index as i64)
        && file.integer_attribute("shard_count") == Some(shard.count as i64)
        && file.is_intact(scene)
}

/// Runs `scene` as `request` says; returns the summary.
pub fn run(scene: &Scene, request: &RunRequest, progress: &dyn Progress) -> Result<Summary> {
    let started = Instant::now();
    let out = &request.out;
    // Before anything is written: the shard must have work units of its own.
    request
        .shard
        .check_against(scene.shape(), scene.second_name())?;
    // Held until the file is in place and the journal gone.
    let claim = crate::store::OutputLock::acquire(out)?;
    // A current output (made from this scene by this build for this shard): --update
    // keeps it without a census.
    if out.exists() && request.update && request.output_current {
        // A run over it that was stopped (a `--force`) left its journal and partial file:
        // with the output current they hold nothing to resume. Only a journal this program
        // made is removed (a real directory that looks like one, never through a link).
        let journal_dir = Journal::dir_for(out);
        let ours = std::fs::symlink_metadata(&journal_dir).is_ok_and(|m| m.is_dir())
            && Journal::looks_like_one(&journal_dir);
        if ours {
            std::fs::remove_dir_all(&journal_dir)
                .map_err(|e| AtlasError::atlas(&journal_dir, e))?;
            let partial = temporary_path(out);
            if std::fs::symlink_metadata(&partial).is_ok_and(|m| m.is_file()) {
                std::fs::remove_file(&partial).map_err(|e| AtlasError::atlas(&partial, e))?;
            }
        }
        return Ok(Summary {
            up_to_date: true,
            seconds: started.elapsed().as_secs_f64(),
            ..Summary::default()
        });
    }
    // (An interrupted run over an existing output, `--force` or a stale `--update`, left
    // its journal beside it: `--resume` continues that run, which replaces the output as
    // the run itself would have.)
    // Only the file that run was allowed to replace, unchanged since: a file put at the path
    // after it started is not (it was replaced without a word: adversary pass 38).
    let interrupted = request.resume && Journal::looks_like_one(&Journal::dir_for(out));
    if out.exists() && !request.force && !request.update {
        if interrupted && !Journal::output_unchanged(&Journal::dir_for(out), out) {
            return Err(AtlasError::atlas(
                out,
                "exists, and is not what was at this path when the interrupted run started: \
                 --resume replaces only the file that run was allowed to replace; move it away, \
                 or use --force to replace it",
            ));
        }
        if !interrupted {
            return Err(AtlasError::atlas(
                out,
                "exists; use --force to overwrite it (a finished run has nothing to resume)",
            ));
        }
    }
    // The component axis, from the whole grid's critical points: the same for every shard.
    // (A census cut short by a signal lays out nothing: the run stops before any work.)
    progress.laying_out();
    let axis = atlas::component_axis(scene, &|| progress.interrupted());
    let shape = scene.shape();
    let region = request.shard.region(shape);
    let cells_of = |u: &Unit| u.cells(scene.energy.len());
    let units_total = atlas::unit_count(shape);
    let kept_cells = |listed: &std::collections::BTreeSet<usize>| -> u64 {
        listed
            .iter()
            .filter(|&&i| i < units_total)
            .map(|&i| atlas::unit(shape, i))
            .filter(|u| region.holds(u))
            .map(|u| cells_of(&u) as u64)
            .sum()
    };
    let total = region.shape().iter().product::<usize>() as u64;
    if progress.interrupted() {
        // A resumed run stopped here keeps what its journal holds (it said 0 cells kept).
        let journal_dir = Journal::dir_for(out);
        let done = if Journal::looks_like_one(&journal_dir) {
            kept_cells(&Journal::units_listed_in(&journal_dir).unwrap_or_default())
        } else {
            0
        };
        return Err(AtlasError::Interrupted {
            path: out.display().to_string(),
            done,
            total,
        });
    }
    // The journal belongs to this scene, build, shard and component axis: a unit kept for
    // one shard is chunked for that shard's file and axis, and never taken by a run of
    // another shard, the whole grid or another layout into the same output.
    let fingerprint = crate::scene::fnv1a(
        scene.fingerprint(),
        format!(
            "shard {} component {} {:?}",
            request.shard,
            axis.layout.name(),
            axis.labels
        )
        .as_bytes(),
    );
    let journal_dir = Journal::dir_for(out);
    if let Ok(meta) = std::fs::symlink_metadata(&journal_dir) {
        // Only a journal this program made is ever removed or resumed there.
        let reason = if meta.file_type().is_symlink() {
            Some("is a symbolic link")
        } else if !meta.is_dir() {
            Some("is not a directory")
        } else if !Journal::looks_like_one(&journal_dir) {
            Some("is a directory that is not a rubber-atlas resume journal")
        } else {
            None
        };
        if let Some(reason) = reason {
            return Err(AtlasError::atlas(
                &journal_dir,
                format!(
                    "{reason}, and a run keeps its resume journal at this path; move it away \
                     (the program never removes it)"
                ),
            ));
        }
    }
    let journal = if journal_dir.exists() {
        let matching = || Journal::open(&journal_dir, fingerprint);
        // `--update` starts over from the journal of an earlier version of this scene, never
        // from another scene's (adversary pass 5: its stopped run's 20,020 cells were lost).
        if request.update && !request.force && matching().is_err() {
            if let Some(name) = Journal::scene_name_in(&journal_dir).filter(|n| *n != scene.name) {
                return Err(AtlasError::atlas(
                    &journal_dir,
                    format!(
                        "holds the journal of a stopped run of another scene ({name:?}): \
                         --update does not discard it (resume that run, or use --force)"
                    ),
                ));
            }
        }
        if request.force || (request.update && matching().is_err()) {
            std::fs::remove_dir_all(&journal_dir)
                .map_err(|e| AtlasError::atlas(&journal_dir, e))?;
            Journal::create(&journal_dir, fingerprint, &scene.text, out)?
        } else if request.resume || request.update {
            matching()?
        } else if matching().is_ok() {
            return Err(AtlasError::atlas(
                &journal_dir,
                "an interrupted run of this output left its journal here; \
                 use --resume to continue it or --force to start over",
            ));
        } else {
            // (Suggesting --resume here only led to its refusal: adversary pass of 2026-11-27;
            // --update too refuses another scene's journal, above.)
            let reason = match Journal::scene_name_in(&journal_dir) {
                Some(name) if name != scene.name => format!(
                    "an interrupted run of another scene ({name:?}) left its journal here; \
                     resume that run with its own scene, or use --force to start over"
                ),
                _ => "an interrupted run of this output, of another version of this scene or \
                      of the program, left its journal here; use --update to compute this \
                      scene afresh or --force to start over"
                    .to_string(),
            };
            return Err(AtlasError::atlas(&journal_dir, reason));
        }
    } else {
        Journal::create(&journal_dir, fingerprint, &scene.text, out)?
    };

    let variables = atlas::scene_variables(scene);
    let chunk_cells = region.chunk_cells(shape);
    // Units with a file in the journal; each is checked when it is read, below, and computed
    // again if its file turns out damaged.
    let listed = journal.listed_units()?;
    let done_cells = kept_cells(&listed);
    let mut summary = Summary {
        units: region.unit_count(shape),
        ..Summary::default()
    };
    progress.begin(total, done_cells);

    // Batch by batch, the units of a batch in parallel (and within each unit its κ-rows, one
    // at a time, so that no thread idles at a batch's end): compute, keep in the journal,
    // encode as the file stores it; then the batch's chunks are written in order. A batch
    // is a slice, or several small slices (a grid of one-cell slices keeps every thread
    // busy). The file is written afresh by every invocation: the journal, not the file,
    // survives a kill.
    let tmp = temporary_path(out);
    remove_stale(&tmp)?;
    let mut attributes = scene_attributes(scene, request.shard, units_total);
    attributes.extend(request.attributes.iter().cloned());
    let advance = |cells: usize| progress.advance(cells as u64);
    let written = (|| -> Result<()> {
        let file = AtlasFile::create(
            &tmp,
            scene,
            &region,
            &variables,
            &axis,
            &borrowed(&attributes),
        )?;
        for batch in batches(request.shard.units(shape), shape) {
            let encoded = batch
                .par_iter()
                .map(|u| -> Result<Option<(EncodedUnit, Summary)>> {
                    // A unit of the journal is taken as it was stored; a damaged one (torn by
                    // a power loss) is computed again.
                    if listed.contains(&u.index) {
                        if let Some((chunks, words)) =
                            journal.read(u.index, variables.len(), Summary::WORDS)
                        {
                            let mut part = Summary::from_words(&words);
                            part.units_resumed = 1;
                            return Ok(Some((chunks, part)));
                        }
                        // Counted as done when the run began: not any more.
                        progress.retract(cells_of(u) as u64);
                    }
                    // Asked to stop: no new unit (those in flight are dropped between two cells).
                    if progress.interrupted() {
                        return Ok(None);
                    }
                    let rows: Vec<usize> = u.rows.clone().collect();
                    // A unit stopped part way is dropped: a resumed run computes it again, and
                    // its cells counted so far are taken back (the progress line had counted
                    // them as done after Ctrl-C; an adversary pass).
                    let counted = std::sync::atomic::AtomicUsize::new(0);
                    let advance_unit = |cells: usize| {
                        counted.fetch_add(cells, std::sync::atomic::Ordering::Relaxed);
                        advance(cells);
                    };
                    let Some(block) = compute_rows(
                        scene,
                        &variables,
                        &axis,
                        u.alpha_index,
                        u.betas.clone(),
                        &rows,
                        &advance_unit,
                        &|| progress.interrupted(),
                    ) else {
                        progress.dropped(counted.into_inner() as u64);
                        return Ok(None);
                    };
                    let mut part = Summary::default();
                    part.count(&variables, &block);
                    let chunks = encode_unit(&variables, &block, chunk_cells);
                    journal.write(u.index, &chunks, &part.words())?;
                    part.cells_computed = block.cells as u64;
                    Ok(Some((chunks, part)))
                })
                .collect::<Result<Vec<_>>>()?;
            if encoded.iter().any(Option::is_none) || progress.interrupted() {
                return Err(AtlasError::Interrupted {
                    path: out.display().to_string(),
                    done: 0,
                    total,
                });
            }
            for (u, (chunks, part)) in batch.iter().zip(encoded.into_iter().flatten()) {
                file.write_encoded(u, &chunks)?;
                summary.add(&part);
            }
        }
        progress.writing();
        file.close()?;
        // Asked to stop while the file was written: stopped as at any other moment, the
        // file not put in place (every unit is in the journal: a resumed run only writes
        // it). It used to finish and exit 0 after Ctrl-C: an adversary pass.
        if progress.interrupted() {
            return Err(AtlasError::Interrupted {
                path: out.display().to_string(),
                done: 0,
                total,
            });
        }
        Ok(())
    })();
    if let Err(e) = written {
        if claim.is_held() {
            let _ = std::fs::remove_file(&tmp);
        }
        if let AtlasError::Interrupted { path, total, .. } = e {
            // What a resumed run will find: the units the journal holds now.
            let done = kept_cells(&journal.listed_units().unwrap_or_default());
            return Err(AtlasError::Interrupted { path, done, total });
        }
        return Err(e);
    }
    // (Not where the claim was lost: the partial file and the journal may be another's now.)
    claim.check_held(out)?;
    std::fs::rename(&tmp, out).map_err(|e| AtlasError::write_failed(out, e))?;
    journal.remove()?;
    summary.seconds = started.elapsed().as_secs_f64();
    Ok(summary)
}

/// The shard files of one scene, opened and checked for a merge: the scene (from the first
/// shard), its variables and component axis, and each file in its shard's position.
pub struct OpenShards {
    scene: Scene,
    variables: Vec<Variable>,
    axis: ComponentAxis,
    by_index: Vec<Option<(PathBuf, AtlasFile)>>,
}

/// Opens the shard files `shards` of a merge into `out` and checks that they are the whole
/// of one scene, made by this build and undamaged (what [`merge_until`] checks before it
/// writes anything); `opening` is told each file before it is read (a damaged file can
/// crash HDF5: a caller that asks in a child process learns which).
pub fn open_shards(shards: &[PathBuf], out: &Path, opening: &dyn Fn(&Path)) -> Result<OpenShards> {
    if shards.is_empty() {
        return Err(AtlasError::atlas(out, "no shard files given"));
    }
    if let Some(path) = shards.iter().find(|p| !p.is_file()) {
        let why = if path.exists() {
            "is not a regular file"
        } else {
            "does not exist"
        };
        return Err(AtlasError::atlas(path, why));
    }
    // The same file named twice (under one name or two): one line that says so.
    let canonical: Vec<Option<PathBuf>> = shards.iter().map(|p| p.canonicalize().ok()).collect();
    for (i, path) in shards.iter().enumerate() {
        if canonical[..i]
            .iter()
            .any(|c| c.is_some() && *c == canonical[i])
        {
            return Err(AtlasError::atlas(path, "is named twice among the shards"));
        }
    }
    // The scene, from the first shard; every shard must carry the same one.
    let first = shards[0].as_path();
    opening(first);
    let scene_text = read_root_text(first, "scene")?;
    let scene = Scene::parse(&scene_text, &first.display().to_string())?;
    let variables = atlas::scene_variables(&scene);
    let shape = scene.shape();
    let fingerprint = format!("{:016x}", scene.fingerprint());
    let axis = AtlasFile::read_axis(first)?;
    let mut by_index: Vec<Option<(PathBuf, AtlasFile)>> = Vec::new();
    let mut count = None;
    for path in shards {
        opening(path);
        let (index, n) = shard_attributes(path)?;
        let shard = Shard { index, count: n };
        shard
            .check_against(shape, scene.second_name())
            .map_err(|e| AtlasError::atlas(path, e))?;
        let own = AtlasFile::read_axis(path)?;
        if own != axis {
            // (Another scene's shard said "made by different builds?": an adversary pass.)
            if read_root_text(path, "scene_fingerprint")? != fingerprint {
                return Err(AtlasError::atlas(
                    path,
                    format!(
                        "is not a shard of the same scene as {} (or was made by another build)",
                        first.display()
                    ),
                ));
            }
            return Err(AtlasError::atlas(
                path,
                format!(
                    "its component axis ({} {:?}) differs from that of {} ({} {:?}): shards \
                     of one scene made by different builds?",
                    own.layout.name(),
                    own.labels,
                    first.display(),
                    axis.layout.name(),
                    axis.labels
                ),
            ));
        }
        let file = AtlasFile::open(path, &scene, &shard.region(shape), &variables, &axis)?;
        // The checks `--update` and `open_atlas(check=True)` make of the text and the
        // constants: a shard whose scene text or program version was edited merged into a
        // file with a fresh checksum, its damage laundered (adversary pass of 2026-11-28).
        if !file.texts_intact() {
            return Err(AtlasError::atlas(
                path,
                "is damaged: its text attributes (scene, program version, …) do not have the \
                 CRC-32 it was written with; run that shard again",
            ));
        }
        if file.text_attribute("scene_fingerprint").as_deref() != Some(fingerprint.as_str()) {
            return Err(AtlasError::atlas(
                path,
                if path == first {
                    "was made by another build of rubber-atlas (its scene fingerprint is not \
                     this build's): merge with the build that made the shards, or run them again"
                        .to_string()
                } else {
                    format!(
                        "is not a shard of the same scene as {} (or was made by another build)",
                        first.display()
                    )
                },
            ));
        }
        if !file.constants_match(&scene) {
            return Err(AtlasError::atlas(
                path,
                "its nu or eta is not its scene's (the file was edited?); run that shard again",
            ));
        }
        if !file.coordinates_match(&scene) {
            return Err(AtlasError::atlas(
                path,
                format!(
                    "its coordinates are not those of shard {index}/{n} of the scene (its shard \
                     attributes were changed?)"
                ),
            ));
        }
        if *count.get_or_insert(n) != n {
            return Err(AtlasError::atlas(
                path,
                format!(
                    "is shard {index}/{n}, but the first shard is of {}",
                    count.unwrap()
                ),
            ));
        }
        by_index.resize_with(n, || None);
        let slot = &mut by_index[index - 1];
        if let Some((other, _)) = slot {
            return Err(AtlasError::atlas(
                path,
                format!(
                    "shard {index}/{n} is given twice (also {})",
                    other.display()
                ),
            ));
        }
        *slot = Some((path.clone(), file));
    }
    let missing: Vec<String> = by_index
        .iter()
        .enumerate()
        .filter(|(_, s)| s.is_none())
        .map(|(i, _)| format!("{}/{}", i + 1, by_index.len()))
        .collect();
    if !missing.is_empty() {
        return Err(AtlasError::atlas(
            out,
            format!("shards missing: {}", missing.join(", ")),
        ));
    }

    Ok(OpenShards {
        scene,
        variables,
        axis,
        by_index,
    })
}

/// Merges the shard files `shards` of one scene into `out`; the arrays equal those of a
/// single run bit for bit. Refuses shards of different scenes or program versions,
/// duplicates, and missing parts.
pub fn merge(
    shards: &[PathBuf],
    out: &Path,
    force: bool,
    extra_attributes: &[(String, AttrValue)],
) -> Result<Summary> {
    merge_until(shards, out, force, extra_attributes, &|| false)
}

/// [`merge`], given up when `stop` says so (asked before each unit is copied): then
/// [`AtlasError::Stopped`], with the partial file removed and the output as it was.
pub fn merge_until(
    shards: &[PathBuf],
    out: &Path,
    force: bool,
    extra_attributes: &[(String, AttrValue)],
    stop: &dyn Fn() -> bool,
) -> Result<Summary> {
    let started = Instant::now();
    let claim = crate::store::OutputLock::acquire(out)?;
    if out.exists() && !force {
        return Err(AtlasError::atlas(
            out,
            "exists; use --force to overwrite it",
        ));
    }
    let OpenShards {
        scene,
        variables,
        axis,
        by_index,
    } = open_shards(shards, out, &|_| {})?;
    let shape = scene.shape();
    let tmp = temporary_path(out);
    remove_stale(&tmp)?;
    let mut attributes = scene_attributes(&scene, Shard::WHOLE, atlas::unit_count(shape));
    let whole = Region::whole(shape);
    let chunk_cells = whole.chunk_cells(shape);
    // Provenance of the computation: the first shard's program and commit.
    let (_, first_file) = by_index[0].as_ref().unwrap();
    for key in ["program_version", "git_commit"] {
        if let Some(v) = first_file.text_attribute(key) {
            attributes.retain(|(k, _)| k != key);
            attributes.push((key.into(), AttrValue::Text(v)));
        }
    }
    attributes.push((
        "merged_from".into(),
        AttrValue::Text(
            by_index
                .iter()
                .map(|s| s.as_ref().unwrap().0.display().to_string())
                .collect::<Vec<_>>()
                .join("\n"),
        ),
    ));
    attributes.extend(extra_attributes.iter().cloned());
    let mut summary = Summary {
        units: atlas::unit_count(shape),
        ..Summary::default()
    };
    let n = by_index.len();
    let written = (|| -> Result<()> {
        let file = AtlasFile::create(
            &tmp,
            &scene,
            &whole,
            &variables,
            &axis,
            &borrowed(&attributes),
        )?;
        for (i, shard) in by_index.iter().enumerate() {
            let (_, source) = shard.as_ref().unwrap();
            let shard = Shard {
                index: i + 1,
                count: n,
            };
            for u in shard.units(shape) {
                if stop() {
                    return Err(AtlasError::Stopped);
                }
                let block = source.read_unit(&u)?;
                summary.count(&variables, &block);
                let encoded = encode_unit(&variables, &block, chunk_cells);
                file.write_encoded(&u, &encoded)?;
            }
        }
        file.close()?;
        // (A signal while the file was closed: nothing put in place, as at any unit.)
        if stop() {
            return Err(AtlasError::Stopped);
        }
        Ok(())
    })();
    if let Err(e) = written {
        let _ = std::fs::remove_file(&tmp);
        return Err(e);
    }
    claim.check_held(out)?;
    std::fs::rename(&tmp, out).map_err(|e| AtlasError::write_failed(out, e))?;
    summary.seconds = started.elapsed().as_secs_f64();
    Ok(summary)
}

/// Cells of a batch of small slices: enough work for every thread, little memory.
const BATCH_CELLS: usize = 1 << 16;

/// `units` in batches computed in parallel and then written: each slice (or group of small
/// slices, [`atlas::betas_per_unit`]) whole, its units ending together, and consecutive ones
/// together until a batch holds [`BATCH_CELLS`] cells.
fn batches(
    units: impl Iterator<Item = Unit>,
    shape: [usize; 4],
) -> impl Iterator<Item = Vec<Unit>> {
    let slice_cells = shape[2] * shape[3] * atlas::betas_per_unit(shape);
    let mut units = units.peekable();
    std::iter::from_fn(move || {
        let mut batch: Vec<Unit> = Vec::new();
        let mut cells = 0;
        while let Some(u) = units.peek() {
            let new_slice = batch
                .last()
                .is_none_or(|b| (b.alpha_index, &b.betas) != (u.alpha_index, &u.betas));
            if new_slice && !batch.is_empty() && cells + slice_cells > BATCH_CELLS {
                break;
            }
            cells += u.cells(shape[3]);
            batch.push(units.next().expect("peeked"));
        }
        (!batch.is_empty()).then_some(batch)
    })
}

/// A shard file's `shard_index` and `shard_count`, checked (they are the file's word).
fn shard_attributes(path: &Path) -> Result<(usize, usize)> {
    let file = hdf5::File::open(path).map_err(|e| AtlasError::atlas(path, e))?;
    let read = |name: &str| file.attr(name).and_then(|a| a.read_scalar::<i64>()).ok();
    let (Some(index), Some(n)) = (read("shard_index"), read("shard_count")) else {
        return Err(AtlasError::atlas(path, "has no shard_index / shard_count"));
    };
    match (usize::try_from(index), usize::try_from(n)) {
        (Ok(i), Ok(n)) => Ok((i, n)),
        _ => Err(AtlasError::atlas(
            path,
            format!("has shard_index {index} / shard_count {n}, not a shard"),
        )),
    }
}

fn read_root_text(path: &Path, name: &str) -> Result<String> {
    let file = hdf5::File::open(path).map_err(|e| AtlasError::atlas(path, e))?;
    file.attr(name)
        .and_then(|a| a.read_scalar::<hdf5::types::VarLenUnicode>())
        .map(|s| s.as_str().to_string())
        .map_err(|_| AtlasError::atlas(path, format!("has no {name} attribute: not an atlas file")))
}
