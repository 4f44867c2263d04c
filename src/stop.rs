//! SIGINT, SIGTERM and SIGHUP during `run` and the other long commands (`trajectory`,
//! `diagram`, `resonance`, `verdict`): the first asks the work to stop (a run between two cells,
//! keeping the units its journal holds, see [`rubber_atlas::sweep::Progress::interrupted`]; the
//! others at their next check, writing nothing); a second ends the process at once, with one
//! line saying what is kept. Once asked, the work stays asked (the flag is never reset).

use signal_hook::consts::signal::{SIGHUP, SIGINT, SIGTERM};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::OnceLock;

static STOPPING: AtomicBool = AtomicBool::new(false);
static SIGNAL: AtomicUsize = AtomicUsize::new(0);
/// The line a second signal prints, made before any signal can arrive (a handler may not
/// allocate).
static AT_ONCE: OnceLock<Vec<u8>> = OnceLock::new();

/// Installs the handlers (once, before the work starts); `kept` says what a second signal
/// leaves behind (for a run: the units finished so far, and the command that continues it).
pub fn install(kept: &str) -> std::io::Result<()> {
    let _ = AT_ONCE
        .set(format!("rubber-atlas: stopped at once by a second signal; {kept}\n").into_bytes());
    for signal in [SIGINT, SIGTERM, SIGHUP] {
        // The immediate stop must be registered first: it acts only on a signal that finds
        // the run already stopping.
        // SAFETY: the action only reads atomics and a finished OnceLock, and calls write(2)
        // and _exit(2), which are async-signal-safe.
        unsafe {
            signal_hook::low_level::register(signal, move || {
                if STOPPING.load(Ordering::SeqCst) {
                    if let Some(line) = AT_ONCE.get() {
                        libc::write(2, line.as_ptr().cast(), line.len());
                    }
                    signal_hook::low_level::exit(128 + signal);
                }
            })?;
        }
        signal_hook::flag::register_usize(signal, &SIGNAL, signal as usize)?;
        signal_hook::flag::register(signal, &STOPPING)?;
    }
    Ok(())
}

/// Whether a stop was asked for.
pub fn requested() -> bool {
    STOPPING.load(Ordering::SeqCst)
}

/// The signal's name and the shell's exit status for it (128 + its number).
pub fn received() -> (&'static str, u8) {
    match SIGNAL.load(Ordering::SeqCst) as i32 {
        SIGTERM => ("SIGTERM", 143),
        SIGHUP => ("SIGHUP", 129),
        _ => ("SIGINT", 130),
    }
}
