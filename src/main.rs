//! The `rubber-atlas` command: parses the command line (see [`cli`]), runs it, and maps the
//! outcome to an exit code: 0 success, 2 bad input (one line naming the bad value), 1 a
//! computation that failed.

mod cli;

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    let args = match cli::Cli::try_parse() {
        Ok(args) => args,
        Err(e) => {
            // clap prints usage errors with exit code 2 and help/version with 0.
            let _ = e.print();
            return ExitCode::from(e.exit_code() as u8);
        }
    };
    match cli::run(args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            let bad_input = e.chain().any(|c| {
                matches!(
                    c.downcast_ref::<rubber_atlas::AtlasError>(),
                    Some(
                        rubber_atlas::AtlasError::InvalidParameter { .. }
                            | rubber_atlas::AtlasError::InvalidInitialAngle { .. }
                            | rubber_atlas::AtlasError::NoMotion { .. }
                            | rubber_atlas::AtlasError::NotPeriodic { .. }
                            | rubber_atlas::AtlasError::Output { .. }
                    )
                )
            });
            ExitCode::from(if bad_input { 2 } else { 1 })
        }
    }
}
