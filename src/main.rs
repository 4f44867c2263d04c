//! The `rubber-atlas` command: parses the command line (see [`cli`]), runs it, and maps the
//! outcome to an exit code: 0 success, 2 bad input (one line naming the bad value), 1 a
//! computation that failed, 75 an output another process is writing, 130 / 143 / 129 a
//! command stopped by SIGINT / SIGTERM / SIGHUP (a run's journal kept for --resume).

/// `eprintln!` that cannot fail: a line that cannot reach standard error (`2> /dev/full`) is
/// lost, and the exit status stays the outcome's (bad input exited 1, not 2, and a written
/// file's "wrote" line failed the command: adversary pass of 2026-11-27).
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

/// `println!` for what a command says after its output file is in place (`run`'s and
/// `merge`'s summary): a line that cannot reach standard output (a closed pipe, `> /dev/full`)
/// is lost, and the exit status stays the work's (a complete atlas exited 1: adversary pass of
/// 2026-11-28).
macro_rules! tell {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}

mod cli;
mod progress;
mod stop;

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
    // A file-size limit (`ulimit -f`) makes the write that crosses it fail with EFBIG, which
    // is reported in one line, exit 1, with the partial files removed; by default SIGXFSZ
    // killed the process there instead (exit 153, temporary files left; an adversary pass).
    #[cfg(unix)]
    // SAFETY: ignoring a signal before any thread starts.
    unsafe {
        libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
    }
    // Output that cannot be written (standard output on a full disk, `> /dev/full`) is one
    // line and exit status 1, not a panic in `println!` with a backtrace.
    let default_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let payload = info.payload();
        let message = payload
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| payload.downcast_ref::<&str>().copied())
            .unwrap_or("");
        if message.starts_with("failed printing to std") {
            say!("rubber-atlas: {message}");
            std::process::exit(1);
        }
        default_hook(info);
    }));
    let args = match cli::Cli::try_parse() {
        Ok(args) => args,
        Err(e) if !e.use_stderr() => {
            // --help and --version, which a full disk must not lose in silence either.
            use std::io::Write;
            if let Err(error) = e.print().and_then(|()| std::io::stdout().flush()) {
                say!("rubber-atlas: failed printing to stdout: {error}");
                return ExitCode::from(1);
            }
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
            say!("{}", line.join(" "));
            return ExitCode::from(2);
        }
    };
    // A command that writes an atlas must not be killed by a closed pipe on its progress or
    // its summary: that left its lock and an empty journal, which blocked the next run
    // (`run … 2>&1 | head -c 10`, exit 141: adversary pass of 2026-11-28). Lines into a
    // closed pipe are lost instead, and the run ends as it would have.
    #[cfg(unix)]
    if matches!(args.command, cli::Command::Run(_) | cli::Command::Merge(_)) {
        // SAFETY: ignoring a signal before any thread starts.
        unsafe {
            libc::signal(libc::SIGPIPE, libc::SIG_IGN);
        }
    }
    match cli::run(args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e)
            if e.chain().any(|c| {
                matches!(
                    c.downcast_ref::<rubber_atlas::AtlasError>(),
                    Some(rubber_atlas::AtlasError::Stopped)
                )
            }) =>
        {
            let (signal, status) = stop::received();
            say!("rubber-atlas: stopped by {signal} before the work was done; nothing was written");
            ExitCode::from(status)
        }
        Err(e) if e.to_string() == cli::PRINTING_FAILED => {
            // (As a failed `println!` is reported: `completions` and `man` into /dev/full said
            // "error: …" where every other command says this; adversary pass 41.)
            say!("rubber-atlas: {}", one_line(&format!("{e:#}")));
            ExitCode::from(1)
        }
        Err(e) => {
            say!("error: {}", one_line(&format!("{e:#}")));
            if e.chain().any(|c| {
                matches!(
                    c.downcast_ref::<rubber_atlas::AtlasError>(),
                    Some(rubber_atlas::AtlasError::Busy { .. })
                )
            }) {
                // EX_TEMPFAIL: try again once the other process is done.
                return ExitCode::from(75);
            }
            // A full disk (a quota, a file-size limit) is no bad input, whatever the error's
            // kind (a run into a full disk exited 2: adversary pass of 2026-11-27).
            let text = format!("{e:#}");
            // (By the system's error codes as io::Error and HDF5 show them: ENOSPC, EFBIG,
            // EDQUOT. An HDF5 table into a full disk or past `ulimit -f` exited 2: adversary
            // pass of 2026-11-28.)
            let out_of_space = [
                "(os error 28)",
                "(os error 27)",
                "(os error 122)",
                "errno = 28,",
                "errno = 27,",
                "errno = 122,",
            ]
            .iter()
            .any(|m| text.contains(m));
            let bad_input = !out_of_space
                && e.chain().any(|c| {
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
                                | rubber_atlas::AtlasError::Unsupported { .. }
                                // A request refused before any work for its size, as `run`'s
                                // (a trajectory's step count exited 1: an adversary pass).
                                | rubber_atlas::AtlasError::TooLarge { .. }
                        )
                    )
                });
            ExitCode::from(if bad_input { 2 } else { 1 })
        }
    }
}

/// An error message on one line. HDF5's failed-write message carries a ctime() stamp (with
/// its newline) and a dump of the write call around the system's own message, which is what
/// a user needs: "… file write failed: No space left on device".
fn one_line(text: &str) -> String {
    let mut text = text.replace('\n', " ");
    let start = text.find("file write failed: time = ");
    let message = text.find("error message = '").and_then(|at| {
        let rest = &text[at + "error message = '".len()..];
        rest.find('\'').map(|end| rest[..end].to_string())
    });
    if let (Some(start), Some(message)) = (start, message) {
        text = format!("{}file write failed: {message}", &text[..start]);
    }
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

#[cfg(test)]
mod tests {
    use super::one_line;

    #[test]
    fn an_hdf5_write_error_becomes_one_line_with_the_system_message() {
        let hdf5 = "cannot write t.h5: H5Dwrite(): can't write data: file write failed: time = \
                    Sun Nov 22 21:51:04 2026\n, filename = 't.h5.partial-1', file descriptor = 3, \
                    errno = 28, error message = 'No space left on device', buf = 0x7f, total \
                    write size = 783624, bytes this sub-write = 783624, bytes actually written = \
                    18446744073709551615, offset = 0";
        assert_eq!(
            one_line(hdf5),
            "cannot write t.h5: H5Dwrite(): can't write data: file write failed: No space left on device"
        );
        assert_eq!(one_line("a\n  b"), "a b");
    }
}
