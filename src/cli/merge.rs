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
}

pub(super) fn merge(args: MergeArgs) -> Result<()> {
    let inputs: Vec<&std::path::Path> = args.shards.iter().map(|p| p.as_path()).collect();
    check_output(&args.out, args.force, &inputs, &ATLAS_EXTENSIONS)?;
    let summary = sweep::merge_until(
        &args.shards,
        &args.out,
        args.force,
        &invocation_attributes(),
        &crate::stop::requested,
    )?;
    if !args.quiet {
        println!(
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
