//! The `rubber-atlas` command: parses the command line (see [`cli`]), runs it, and maps the
//! outcome to an exit code: 0 success, 2 bad input (one line naming the bad value), 1 a
//! computation that failed.

mod cli;
mod progress;

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    // Output into a closed pipe (`… | head`) ends the process quietly, as for any Unix
    // filter (exit status 141 in a shell), instead of a panic in `println!`.
    #[cfg(unix)]
    // SAFETY: restoring the default disposition of SIGPIPE before any thread starts.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    let args = match cli::Cli::try_parse() {
        Ok(args) => args,
        Err(e) if !e.use_stderr() => {
            // --help and --version.
            let _ = e.print();
            return ExitCode::SUCCESS;
        }
        Err(e) if e.kind() == clap::error::ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
            // No command given: the whole help, with the usage and the commands.
            let _ = e.print();
            return ExitCode::from(2);
        }
        Err(e) => {
            // One line: clap's message up to its usage block, folded.
            let text = e.render().to_string();
            let line: Vec<&str> = text
                .lines()
                .take_while(|l| !l.starts_with("Usage:"))
                .map(str::trim)
                .filter(|l| !l.is_empty() && !l.starts_with("tip:"))
                .collect();
            eprintln!("{}", line.join(" "));
            return ExitCode::from(2);
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
                            | rubber_atlas::AtlasError::Scene { .. }
                            | rubber_atlas::AtlasError::Atlas { .. }
                    )
                )
            });
            ExitCode::from(if bad_input { 2 } else { 1 })
        }
    }
}
