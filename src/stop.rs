//! SIGINT and SIGTERM during `run`: the first asks the run to stop once the units in flight
//! are in the journal (see [`rubber_atlas::sweep::Progress::interrupted`]); a second ends
//! the process at once. Either way a resumed run continues from the journal.

use signal_hook::consts::signal::{SIGINT, SIGTERM};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

static STOPPING: AtomicBool = AtomicBool::new(false);
static SIGNAL: AtomicUsize = AtomicUsize::new(0);

/// Installs the handlers (once, before the work starts).
pub fn install() -> std::io::Result<()> {
    for signal in [SIGINT, SIGTERM] {
        // The shutdown must be registered first: it acts only on a signal that finds the
        // run already stopping.
        signal_hook::flag::register_conditional_shutdown(signal, 128 + signal, &STOPPING)?;
        signal_hook::flag::register_usize(signal, &SIGNAL, signal as usize)?;
        signal_hook::flag::register(signal, &STOPPING)?;
    }
    Ok(())
}

/// Whether a stop was asked for.
pub fn requested() -> bool {
    STOPPING.load(Ordering::SeqCst)
}

/// The signal's name and the shell's exit status for it (128 + its number: 130, 143).
pub fn received() -> (&'static str, u8) {
    match SIGNAL.load(Ordering::SeqCst) as i32 {
        SIGTERM => ("SIGTERM", 143),
        _ => ("SIGINT", 130),
    }
}
