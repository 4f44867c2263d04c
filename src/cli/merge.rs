//! `rubber-atlas merge`: shard files of one scene joined into the atlas.

use super::*;
use anyhow::Result;
use clap::Args;
use rubber_atlas::store::check_output;
use rubber_atlas::sweep::{self};
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct MergeArgs {
    /// The shard files, all N of them, in any order.
    #[arg(value_name = "SHARDS", required = true)]
    pub shards: Vec<PathBuf>,
    /// The merged atlas.
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    /// Overwrite an existing output.
    #[arg(long)]
    pub force: bool,
    /// No summary.
    #[arg(long)]
    pub quiet: bool,
    /// (Internal) Open and check the shards as the merge would, naming each on standard
    /// output before it is read, and write nothing: asked in a child process, since reading
    /// a damaged file can crash HDF5.
    #[arg(long, hide = true)]
    pub probe_shards: bool,
}

/// The shard whose reading crashed HDF5 in a child process that opened `shards` as the merge
/// will (a flipped bit in a file's global heap made `merge` die of a segmentation fault,
/// leaving its lock behind: an adversary pass); None when the child ended of itself (the
/// merge then reports whatever it found).
fn shard_that_crashes(args: &MergeArgs) -> Option<PathBuf> {
    use std::process::{Command, Stdio};
    let exe = std::env::current_exe().ok()?;
    let output = Command::new(exe)
        .arg("merge")
        .args(&args.shards)
        .arg("--out")
        .arg(&args.out)
        .arg("--probe-shards")
        .stdin(Stdio::null())
        .stderr(Stdio::null())
        .output()
        .ok()?;
    // A crash, not a signal from outside (Ctrl-C reaches the child too: the merge then
    // stops at its first check).
    use std::os::unix::process::ExitStatusExt;
    let crashed = [
        libc::SIGSEGV,
        libc::SIGBUS,
        libc::SIGABRT,
        libc::SIGFPE,
        libc::SIGILL,
    ];
    if !output.status.signal().is_some_and(|s| crashed.contains(&s)) {
        return None;
    }
    let named = String::from_utf8_lossy(&output.stdout);
    named.lines().last().map(PathBuf::from)
}

pub(super) fn merge(args: MergeArgs) -> Result<()> {
    let inputs: Vec<&std::path::Path> = args.shards.iter().map(|p| p.as_path()).collect();
    // (Before the output's checks, which the merge itself makes: the probe answers for the
    // shards alone.)
    if args.probe_shards {
        sweep::open_shards(&args.shards, &args.out, &|path| {
            tell!("{}", path.display());
        })?;
        return Ok(());
    }
    check_output(&args.out, args.force, &inputs, &ATLAS_EXTENSIONS)?;
    if let Some(path) = shard_that_crashes(&args) {
        return Err(rubber_atlas::AtlasError::Atlas {
            path: path.display().to_string(),
            reason: "is damaged: reading it crashed HDF5 (in a child process, so nothing was \
                     written); run that shard again"
                .into(),
        }
        .into());
    }
    let summary = sweep::merge_until(
        &args.shards,
        &args.out,
        args.force,
        &invocation_attributes(),
        &crate::stop::requested,
    )?;
    if !args.quiet {
        tell!(
            "merged {} shard{} into {} ({} cells, {} components) in {:.2} s",
            args.shards.len(),
            if args.shards.len() == 1 { "" } else { "s" },
            args.out.display(),
            summary.cells,
            summary.components,
            summary.seconds
        );
    }
    Ok(())
}
