//! `rubber-atlas run`: an atlas of a scene (or one shard of it), with the size check, the
//! signals and the summary.

use super::*;
use crate::progress::Reporter;
use anyhow::{Context, Result};
use clap::Args;
use rubber_atlas::atlas::Shard;
use rubber_atlas::error::AtlasError;
use rubber_atlas::scene::Scene;
use rubber_atlas::store::check_output;
use rubber_atlas::sweep::{self, RunRequest};
use std::path::PathBuf;

/// The scene format, shown by `run --help` (and in docs/scenes.md at more length).
pub const SCENE_FORMAT: &str = "\
Scene files (TOML):
  name = \"paper-c\"                 # the default output: paper-c.h5 beside the scene
  [body]
  shape = \"ellipsoid\"              # the default; or \"disk\", \"truncated_ball\", \"wheel\"
  nu = 0.5                         # i3 / i1, 0 < nu <= 2
  eta = 0.5                        # m b3^2 / i1 > 0
  [axes]                           # each axis: a list, or { start, stop, num [, spacing = \"log\"] }
  alpha = [0.5]                    # -1 < alpha < 1 (the disk: -100 <= alpha <= 100)
  beta = [3.0]                     # beta > 0; the cut balls take cut instead, the disk neither
  kappa = { start = 0.0, stop = 2.0, num = 201 }
  energy = { start = 0.5, stop = 4.5, num = 201 }
  [solver]
  tolerance = 1e-10                # 1e-15 ... 0.1
  method = \"quadrature\"            # or \"ode\"
  resonance_tol = 1e-9             # |N - round(N)| counted as an integer resonance
  [outputs]
  fields = [\"rotation_number\", \"drift_radius\", \"bounded\"]   # default: all
  layout = \"family\"                # component axis: one torus family per slot, or \"theta_min\"

The plane is one of: kappa with energy; kappa with excess_energy (energy measured from the
bottom of V at each kappa); lambda with s (kappa = lambda / s, energy = 1 / s^2; s = 0 is
the high-energy limit). Shapes and their parameters: docs/bodies.md.
Fields: theta_min, theta_max, period, omega_theta, omega_psi, rotation_number, drift,
drift_radius, bounded, motion, status, error_estimate. Examples: atlas/*.toml in the
repository; every key: docs/scenes.md.";

#[derive(Debug, Args)]
pub struct RunArgs {
    /// The scene file (TOML; the format is below).
    #[arg(value_name = "SCENE")]
    pub scene: PathBuf,
    /// Output file [default: <name>.h5 in the scene's folder; with --shard I/N
    /// <name>.shard-I-of-N.h5 there].
    #[arg(long, value_name = "PATH")]
    pub out: Option<PathBuf>,
    /// Worker threads [default: RAYON_NUM_THREADS if set, else every core].
    #[arg(long, value_name = "N", allow_hyphen_values = true)]
    pub threads: Option<usize>,
    /// Continue an interrupted run of the same scene and output (finished units are kept).
    #[arg(long, conflicts_with = "force")]
    pub resume: bool,
    /// Overwrite an existing output and discard an interrupted run.
    #[arg(long)]
    pub force: bool,
    /// Bring the output up to date (as a Slurm task does): keep it if it was made from this
    /// scene by this build for this shard, continue an interrupted run of the same, and
    /// compute afresh (replacing) whatever is stale; a file that is not an atlas of
    /// rubber-atlas is refused (--force replaces it).
    #[arg(long, conflicts_with_all = ["force", "resume"])]
    pub update: bool,
    /// Print the output path the run would write (the default from the scene's name and
    /// --shard, or --out) and exit.
    #[arg(long)]
    pub print_out: bool,
    #[command(flatten)]
    pub limits: Limits,
    /// Compute part I of N of the grid (1 <= I <= N) into its own file.
    #[arg(long, value_name = "I/N", allow_hyphen_values = true)]
    pub shard: Option<String>,
    /// No progress and no summary.
    #[arg(long)]
    pub quiet: bool,
    /// (Internal, for --update) Exit 0 if the output is current, 3 if not, 4 if it is not an
    /// atlas of rubber-atlas, 5 if another scene's, 6 if another program holds it open for
    /// writing: asked in a child process, since reading a damaged file can crash HDF5.
    #[arg(long, hide = true)]
    pub probe_current: bool,
}

/// Whether the existing output `out` is current for `args`' scene and shard, asked of this
/// program in a child process: a damaged file that crashes HDF5 (a length in its global
/// heap) then crashes the child, and the output is computed afresh.
fn output_current(args: &RunArgs, out: &std::path::Path) -> Result<bool> {
    use std::process::{Command, Stdio};
    let Ok(exe) = std::env::current_exe() else {
        return Ok(false);
    };
    let mut probe = Command::new(exe);
    probe
        .arg("run")
        .arg(&args.scene)
        .arg("--out")
        .arg(out)
        .arg("--probe-current");
    if let Some(shard) = &args.shard {
        probe.arg("--shard").arg(shard);
    }
    let status = probe
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status();
    Ok(match status {
        Ok(status) if status.code() == Some(0) => true,
        // Someone else's file (a text file, another program's HDF5) is not an atlas to
        // update: replacing it needs --force (which --update excludes).
        Ok(status) if status.code() == Some(4) => {
            return Err(AtlasError::Atlas {
                path: out.display().to_string(),
                reason: "exists and is not an atlas of rubber-atlas: --update replaces only \
                         its own files (run with --force in its place to replace it)"
                    .into(),
            }
            .into());
        }
        // An atlas of another scene (by its name) is not an earlier version of this one.
        Ok(status) if status.code() == Some(5) => {
            return Err(AtlasError::Atlas {
                path: out.display().to_string(),
                reason: "is the atlas of another scene (its scene_name differs): --update \
                         replaces only an earlier atlas of this scene (run with --force in its \
                         place to replace it)"
                    .into(),
            }
            .into());
        }
        // Open for writing in another program: not readable here, and not ours to replace.
        Ok(status) if status.code() == Some(6) => {
            return Err(AtlasError::Atlas {
                path: out.display().to_string(),
                reason: "is open for writing in another program (it holds the file's HDF5 \
                         lock): --update neither reads nor replaces it; close it there and run \
                         again (or run with --force in its place to replace it)"
                    .into(),
            }
            .into());
        }
        Ok(status) if status.code().is_none() && !args.quiet => {
            say!(
                "rubber-atlas: reading {} crashed HDF5 (a damaged file); it is computed afresh",
                out.display()
            );
            false
        }
        _ => false,
    })
}

/// The bytes of the regular files directly in the journal `dir` (0 where there is none).
fn journal_bytes(dir: &std::path::Path) -> f64 {
    std::fs::read_dir(dir).map_or(0.0, |entries| {
        entries
            .flatten()
            .filter_map(|e| e.metadata().ok())
            .filter(|m| m.is_file())
            .map(|m| m.len() as f64)
            .sum()
    })
}

pub(super) fn run_scene(args: RunArgs) -> Result<()> {
    let scene = Scene::from_file(&args.scene)?;
    let shard = match &args.shard {
        Some(text) => Shard::parse(text)?,
        None => Shard::WHOLE,
    };
    // A shard count that does not tile the grid is refused at once (also by --print-out,
    // which submit.sh calls before anything is queued).
    shard.check_against(scene.shape(), scene.second_name())?;
    // By default beside the scene, so that a run works from any folder.
    let out = args.out.clone().unwrap_or_else(|| {
        let folder = args.scene.parent().unwrap_or(std::path::Path::new(""));
        folder.join(if shard == Shard::WHOLE {
            format!("{}.h5", scene.name)
        } else {
            format!("{}.shard-{}-of-{}.h5", scene.name, shard.index, shard.count)
        })
    });
    if args.print_out {
        // Only a path a run would write (an existing file aside, which --update, --resume or
        // --force write over): it printed x.nc, the scene itself, a folder (adversary pass
        // of 2026-11-27).
        check_output(&out, true, &[&args.scene], &ATLAS_EXTENSIONS)?;
        println!("{}", out.display());
        return Ok(());
    }
    if args.probe_current {
        use rubber_atlas::store::atlas_file::AtlasFile;
        std::process::exit(if AtlasFile::is_locked_by_another(&out) {
            6
        } else if sweep::output_is_current(&out, &scene, shard) {
            0
        } else if AtlasFile::is_foreign(&out) {
            4
        } else if AtlasFile::scene_name(&out).is_some_and(|name| name != scene.name) {
            5
        } else {
            3
        });
    }
    // Before any work: never a directory, device, symlink or the scene itself.
    check_output(
        &out,
        args.force || args.resume || args.update,
        &[&args.scene],
        &ATLAS_EXTENSIONS,
    )?;
    if let Some(parent) = out.parent().filter(|p| !p.as_os_str().is_empty()) {
        if !parent.is_dir() {
            return Err(AtlasError::Atlas {
                path: out.display().to_string(),
                reason: format!("the directory {} does not exist", parent.display()),
            }
            .into());
        }
    }
    // --threads, else RAYON_NUM_THREADS (as rayon itself reads it), else every core.
    // (0, as for rayon, is every core; anything but a whole number is refused, not ignored.)
    let from_env = rubber_atlas::machine::threads_from_env()?;
    let threads = match args.threads.or(from_env) {
        Some(0) => {
            return Err(AtlasError::Atlas {
                path: "--threads 0".into(),
                reason: "needs at least one thread".into(),
            }
            .into())
        }
        // More threads than cores only add overhead: capped at the cores.
        Some(n) => n.min(std::thread::available_parallelism().map_or(1, |c| c.get())),
        None => std::thread::available_parallelism().map_or(1, |n| n.get()),
    };
    // A current output (--update) is kept without a census: nothing to allocate or write, so
    // no size check (a finished shard resubmitted on a nearly full disk was refused:
    // adversary pass of 2026-11-28).
    let current = args.update && out.exists() && output_current(&args, &out)?;
    // Before anything is allocated: a grid the machine cannot hold is refused in one line.
    let need = sweep::footprint(&scene, shard, threads);
    // What a resumed run's journal holds is on the disk already: after a full disk, the room
    // freed need only hold the rest (`--resume` was refused with enough freed for it).
    let journaled = if args.resume {
        journal_bytes(&rubber_atlas::store::journal::Journal::dir_for(&out))
    } else {
        0.0
    };
    // Beyond 2^64 cells no 64-bit index counts them, and no machine would finish such a run:
    // refused even with --allow-large (a grid of 1e24 cells sat in its census with no word:
    // adversary pass 26).
    if need.cells > MOST_CELLS {
        return Err(AtlasError::Atlas {
            path: out.display().to_string(),
            reason: format!(
                "the run has {:.3e} cells, beyond the {MOST_CELLS:.3e} (2^64) a 64-bit index \
                 counts, even with --allow-large: use fewer points on the axes",
                need.cells
            ),
        }
        .into());
    }
    if !current {
        args.limits.check(
            need.memory_bytes,
            Some((need.disk_bytes - journaled).max(0.0)),
            Some(&out),
            // (The shard count is searched only for a refusal.)
            &|| {
                format!(
                    "the run has {:.3e} cells: {}use fewer kappa or energy points",
                    need.cells,
                    shards_to_fit(&scene, &out, threads)
                )
            },
        )?;
    }
    // The global pool, so that the run's serial parts (file creation, writing) stay on the
    // main thread: on a pool thread glibc grows that thread's heap a page at a time, and
    // creating the HDF5 file took 7 ms of mprotect calls instead of 1.
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build_global()
        .context("cannot start the worker threads")?;
    let request = RunRequest {
        out: out.clone(),
        resume: args.resume,
        force: args.force,
        update: args.update,
        output_current: current,
        shard,
        attributes: invocation_attributes(),
    };
    // The command that continues this run, quoted for a POSIX shell.
    let shard_arg = match &args.shard {
        Some(text) => format!(" --shard {}", shell_quote(text)),
        None => String::new(),
    };
    let resume = format!(
        "rubber-atlas run {}{shard_arg} --out {} --resume",
        shell_quote(&args.scene.display().to_string()),
        shell_quote(&out.display().to_string()),
    );
    crate::stop::install(&format!(
        "the units finished so far are kept; continue with: {resume}"
    ))
    .context("cannot install the SIGINT and SIGTERM handlers")?;
    let reporter = Reporter::new(args.quiet, &scene.name);
    let summary = match sweep::run(&scene, &request, &reporter) {
        Err(AtlasError::Interrupted { done, total, .. }) => {
            reporter.finish();
            let (signal, status) = crate::stop::received();
            let journal = rubber_atlas::store::journal::Journal::dir_for(&out);
            if journal.is_dir() {
                say!(
                    "rubber-atlas: stopped by {signal} with {done} of {total} cells computed and kept in {}; continue with: {resume}",
                    journal.display(),
                );
            } else {
                say!(
                    "rubber-atlas: stopped by {signal} before any cell was computed (nothing kept, nothing to resume)",
                );
            }
            std::process::exit(i32::from(status));
        }
        result => result?,
    };
    reporter.finish();
    if summary.up_to_date {
        if !args.quiet {
            tell!(
                "{} is complete and current (this scene, this build); nothing to do",
                out.display()
            );
        }
        return Ok(());
    }
    if !args.quiet {
        print_summary(&summary, &out, threads);
    }
    Ok(())
}

/// The most cells one run may have: 2^64, what a 64-bit index counts.
const MOST_CELLS: f64 = 18_446_744_073_709_551_616.0;

/// A shard count that tiles the grid and whose shards each fit in half the available memory
/// and in the free disk beside `out` (a machine like this one), as a phrase for the refusal.
/// The search starts where the whole run's need divided by what is there says and tries 256
/// counts, then 256 from a count a quarter larger, and so on (a shard's memory has a floor,
/// its threads' work units, so the first guess can be short). Where even the most shards
/// do not fit, it says that a work unit is too large for the machine. The search tries at
/// most [`SHARD_SEARCH`] counts, none above [`SHARD_SEARCH_COUNTS`]: a count's layout takes
/// the divisors of the count, a millisecond at 1e12 (a grid of 1e16 cells took 40 s of
/// tries before its refusal, deaf to Ctrl-C); past that the phrase gives the least count
/// the need implies. (A count of tries, not a time: the answer is the same on any machine.)
pub(super) fn shards_to_fit(scene: &Scene, out: &std::path::Path, threads: usize) -> String {
    let mut tries = 0;
    let memory = rubber_atlas::machine::available_memory().map_or(f64::INFINITY, |m| 0.5 * m);
    let disk = rubber_atlas::machine::free_disk(out).unwrap_or(f64::INFINITY);
    let shape = scene.shape();
    let most: usize = rubber_atlas::atlas::Region::positions(shape)
        .iter()
        .product();
    let fits = |count: usize| {
        let shard = Shard { index: 1, count };
        let need = sweep::footprint(scene, shard, threads);
        shard.check_against(shape, scene.second_name()).is_ok()
            && need.memory_bytes <= memory
            && need.disk_bytes <= disk
    };
    let whole = sweep::footprint(scene, Shard::WHOLE, threads);
    let needed = (whole.memory_bytes / memory).max(whole.disk_bytes / disk);
    // (as usize saturates; a count is at least 2.)
    let least = (needed.ceil() as usize).clamp(2, most.max(2));
    let at_least = format!(
        "split it with --shard I/N across machines, N at least {least} (each shard must fit \
         this machine), or "
    );
    // (One count's layout near 1e16 alone took 10 s.)
    if least > SHARD_SEARCH_COUNTS {
        return at_least;
    }
    let mut from = least;
    while from <= most.min(SHARD_SEARCH_COUNTS) {
        if let Some(count) = (from..=most.min(from + 255))
            .take_while(|_| {
                tries += 1;
                tries <= SHARD_SEARCH
            })
            .find(|&c| fits(c))
        {
            return format!(
                "split it with --shard I/{count} across machines (enough shards to fit), or "
            );
        }
        if tries > SHARD_SEARCH {
            return at_least;
        }
        from = from.saturating_add(256).max(from.saturating_add(from / 4));
    }
    if most > SHARD_SEARCH_COUNTS {
        return at_least;
    }
    "even a shard of one work unit (a block of kappa-rows, every energy) does not fit this \
     machine: "
        .to_string()
}

/// The shard counts [`shards_to_fit`] may try (at most half a second at the largest).
const SHARD_SEARCH: usize = 512;

/// The largest shard count [`shards_to_fit`] tries (a count's layout takes its divisors:
/// a millisecond here).
const SHARD_SEARCH_COUNTS: usize = 1 << 40;

pub(super) fn print_summary(summary: &sweep::Summary, out: &std::path::Path, threads: usize) {
    let [ok, no_motion, failed] = summary.cells_by_status;
    let [c_ok, c_tol, c_fixed, c_sep, c_limit, c_face] = summary.components_by_status;
    let rate = summary.cells_computed as f64 / summary.seconds.max(1e-9);
    tell!("wrote {}", out.display());
    tell!(
        "cells: {} (with motion {ok}, no motion {no_motion}, failed {failed}); components: {}",
        summary.cells,
        summary.components
    );
    tell!(
        "components by status: ok {c_ok}, tolerance_not_reached {c_tol}, fixed_point {c_fixed}, \
         separatrix {c_sep}, high_energy_limit {c_limit}, reaches_face {c_face}"
    );
    tell!(
        "units: {} ({} resumed from an interrupted run, {} computed now)",
        summary.units,
        summary.units_resumed,
        summary.units - summary.units_resumed
    );
    tell!(
        "time: {:.2} s on {threads} thread(s), {} cells computed, {rate:.0} cells per second",
        summary.seconds,
        summary.cells_computed
    );
}
