//! This process's CPU clock.

/// This process's CPU seconds so far (user + system, all its threads); 0
/// where the clock cannot be read.
pub fn cpu_seconds() -> f64 {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: a valid clock id and out-pointer.
    let ok = unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut t) } == 0;
    if ok {
        t.tv_sec as f64 + 1e-9 * t.tv_nsec as f64
    } else {
        0.0
    }
}
