//! SIGTERM and SIGINT as a request to stop at the next load-step boundary.
//!
//! PETSc installs a handler for SIGTERM that aborts the MPI job at once.
//! A batch system's `scancel`, `mpirun` forwarding Ctrl-C, or `kill` would
//! then end a rank wherever it is, also inside an HDF5 metadata write, and
//! the result file can be left unreadable. This module replaces PETSc's
//! handler for these two signals with one that only records the signal; the
//! load-step loop asks all ranks at every step boundary (an agreement in
//! the solve driver) and ends the run there, with the file closed and
//! holding every converged step.
//!
//! The handler is one-shot (`SA_RESETHAND`): a second signal gets the
//! default action, so a user who does not want to wait for the step to end
//! can press Ctrl-C again. Other signals keep PETSc's handler.

use std::sync::atomic::{AtomicBool, AtomicI32, Ordering};

/// The first termination signal received, 0 while none.
static RECEIVED: AtomicI32 = AtomicI32::new(0);
/// Whether this process prints the notice (rank 0 only, set at install).
static NOTIFY: AtomicBool = AtomicBool::new(false);

const NOTICE: &[u8] =
    b"contactlink: stop requested; ending after the current load step (signal again to end now)\n";

/// The signal handler: an atomic store and one `write(2)`, both
/// async-signal-safe. No allocation, no lock, no Rust I/O.
extern "C" fn record(signal: libc::c_int) {
    RECEIVED.store(signal, Ordering::SeqCst);
    if NOTIFY.load(Ordering::SeqCst) {
        // SAFETY: write(2) is async-signal-safe; the buffer is a static
        // byte string valid for its whole length. A failed write is ignored
        // (nothing can be done about it inside a handler).
        unsafe {
            libc::write(libc::STDERR_FILENO, NOTICE.as_ptr().cast(), NOTICE.len());
        }
    }
}

/// Replaces the handlers of SIGTERM and SIGINT (after PETSc's start-up,
/// which installs its own). `notify`: print the one-line notice when the
/// first signal arrives (rank 0).
pub(crate) fn defer_termination(notify: bool) -> std::io::Result<()> {
    NOTIFY.store(notify, Ordering::SeqCst);
    for signal in [libc::SIGTERM, libc::SIGINT] {
        // SAFETY: `action` is zero-initialised (a valid `sigaction`: empty
        // mask, no flags) and then filled with a handler of the signature
        // `sa_handler` expects without SA_SIGINFO; sigemptyset and sigaction
        // only read and write the structs passed to them.
        let rc = unsafe {
            let mut action: libc::sigaction = std::mem::zeroed();
            action.sa_sigaction = record as extern "C" fn(libc::c_int) as libc::sighandler_t;
            // SA_RESTART: system calls interrupted by the signal (MPI's
            // polling, file I/O) resume instead of failing with EINTR.
            action.sa_flags = libc::SA_RESTART | libc::SA_RESETHAND;
            libc::sigemptyset(&mut action.sa_mask);
            libc::sigaction(signal, &action, std::ptr::null_mut())
        };
        if rc != 0 {
            return Err(std::io::Error::last_os_error());
        }
    }
    Ok(())
}

/// The first termination signal this process received, if any. Rank-local:
/// the caller agrees on it with the other ranks before acting.
pub fn received() -> Option<i32> {
    match RECEIVED.load(Ordering::SeqCst) {
        0 => None,
        s => Some(s),
    }
}

/// The conventional name of a termination signal, for messages.
pub fn name(signal: i32) -> &'static str {
    match signal {
        libc::SIGTERM => "SIGTERM",
        libc::SIGINT => "SIGINT",
        _ => "a termination signal",
    }
}
