//! Ctrl-C (SIGINT) and SIGTERM end a run as its source's end would: after the scan in hand,
//! with the summary printed and every file written. A live radar or NMEA source never ends
//! by itself, and `kill` or Ctrl-C is how a watch's run ends; dying on the signal lost the
//! summary. A second signal ends the process at once (a source that hangs).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, LazyLock};

static INTERRUPTED: LazyLock<Arc<AtomicBool>> = LazyLock::new(|| Arc::new(AtomicBool::new(false)));

/// Installs the handlers (once a process; again is harmless).
///
/// # Errors
/// The operating system refuses a handler.
pub fn install() -> std::io::Result<()> {
    use signal_hook::consts::{SIGINT, SIGTERM};
    for signal in [SIGINT, SIGTERM] {
        // The order matters: the exit is armed by a flag already set, so the first signal
        // only sets it.
        signal_hook::flag::register_conditional_shutdown(signal, 130, Arc::clone(&INTERRUPTED))?;
        signal_hook::flag::register(signal, Arc::clone(&INTERRUPTED))?;
    }
    Ok(())
}

/// Whether the run has been asked to end.
pub fn interrupted() -> bool {
    INTERRUPTED.load(Ordering::Relaxed)
}

// Tested end to end (tests/cli_pipes.rs): a signal raised here would stop the other tests'
// runs in this process.
