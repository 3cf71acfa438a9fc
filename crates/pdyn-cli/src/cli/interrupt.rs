//! SIGINT and SIGTERM during `pdyn run` (issue 29): the first sets the engines' stop flag
//! (`pdyn::Request::interrupt`, the flag Python's Ctrl-C sets), so the run finishes its step,
//! writes `summary.json` with status `interrupted`, flushes its files and exits with code 4;
//! a second one ends the process at once with code 5 (the files hold whole rows: rows are
//! handed to the system whole, so a row is in a file entirely or not at all).

use pdyn_ode::Interrupt;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// Exit code of a process ended at once by a second signal.
pub const EXIT_AT_ONCE: i32 = 5;

/// The stop flag, set by the first SIGINT or SIGTERM.
#[cfg(unix)]
pub fn install() -> Option<Interrupt> {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let flag: Interrupt = Arc::new(AtomicBool::new(false));
    for sig in [SIGINT, SIGTERM] {
        // The conditional shutdown first: it sees the flag the first signal set.
        signal_hook::flag::register_conditional_shutdown(sig, EXIT_AT_ONCE, flag.clone()).ok()?;
        signal_hook::flag::register(sig, flag.clone()).ok()?;
    }
    // A file-size limit (`ulimit -f`) would kill the process with SIGXFSZ in the middle of a
    // row; handled (by a flag nobody reads), the write fails with EFBIG instead, and the run
    // stops as on a full disk: the file cut back to its last whole row, the last checkpoint
    // kept, a located error (`pdyn::stream::RowFile::flush`).
    signal_hook::flag::register(
        signal_hook::consts::SIGXFSZ,
        Arc::new(AtomicBool::new(false)),
    )
    .ok()?;
    Some(flag)
}

/// No signals to catch: the default handling (the process ends).
#[cfg(not(unix))]
pub fn install() -> Option<Interrupt> {
    let _ = Arc::new(AtomicBool::new(false));
    None
}
