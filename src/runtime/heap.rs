//! The C heap that PETSc, MPI and the program allocate from (glibc's malloc).
//!
//! libsuperlu_dist, which Debian's PETSc links (this program never calls
//! it), sets `M_MMAP_MAX = 0` and `M_TRIM_THRESHOLD = -1` with `mallopt` in
//! a constructor that runs when the library is loaded, before `main`
//! (found with a breakpoint on `mallopt`). Then no block is ever mapped on
//! its own and the heap is never trimmed: every matrix, vector and PETSc
//! temporary comes from one `brk` heap, and what is freed stays resident
//! until a later allocation happens to fit into it. The 167k-DOF plain
//! sphere on 4 ranks ended its load step with 71 MiB free inside rank 0's
//! heap, and the first Jacobian's off-rank stash (freed after assembly)
//! stayed resident on the ranks that send it. [`restore_malloc_defaults`]
//! puts glibc's defaults back.
//!
//! glibc's own default threshold is dynamic (it grows when a mapped block is
//! freed); any explicit setting, such as the library's, switches that off
//! for good, so the threshold is set to glibc's starting value, fixed.

/// glibc's defaults: blocks of 128 KiB and more are mapped on their own
/// (and unmapped when freed), at most 65,536 of them, and the heap's free
/// top beyond 128 KiB goes back to the system.
const MMAP_THRESHOLD: i32 = 128 * 1024;
const MMAP_MAX: i32 = 65_536;
const TRIM_THRESHOLD: i32 = 128 * 1024;

/// Undoes libsuperlu_dist's malloc settings (see the module). Call it once,
/// early in `main`, before MPI and PETSc allocate; a no-op off glibc.
pub fn restore_malloc_defaults() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only changes the allocator's parameters; these are
    // valid values for each and take effect for later allocations.
    unsafe {
        libc::mallopt(libc::M_MMAP_MAX, MMAP_MAX);
        libc::mallopt(libc::M_MMAP_THRESHOLD, MMAP_THRESHOLD);
        libc::mallopt(libc::M_TRIM_THRESHOLD, TRIM_THRESHOLD);
    }
}

#[cfg(all(test, target_os = "linux", target_env = "gnu"))]
mod tests {
    use super::*;

    /// Bytes malloc gives a 4 MiB + 1 byte block beyond what was asked: a
    /// block mapped on its own is rounded up to whole pages, one from the
    /// heap to 16 bytes.
    fn slack_of_a_large_block() -> usize {
        let n = (4 << 20) + 1;
        // black_box: the optimiser would drop an allocation nothing reads.
        let block = std::hint::black_box(vec![1u8; n]);
        // SAFETY: a live block from malloc (Rust's system allocator, which a
        // byte vector reaches with malloc itself).
        let usable = unsafe { libc::malloc_usable_size(block.as_ptr() as *mut libc::c_void) };
        usable - n
    }

    /// Set in the child process [`slack_in_a_fresh_process`] starts: which
    /// settings it allocates under.
    const CHILD_ENV: &str = "CONTACTLINK_HEAP_TEST_CHILD";
    /// What the child prints before the slack.
    const SLACK_MARK: &str = "large-block-slack=";

    /// The slack of a large block in a fresh process (this test binary run
    /// again for [`child_block_slack`]): a heap that other tests' threads
    /// have used may serve the block from memory freed earlier, mapped or not.
    fn slack_in_a_fresh_process(mode: &str) -> usize {
        let out = std::process::Command::new(std::env::current_exe().unwrap())
            .args([
                "--exact",
                "runtime::heap::tests::child_block_slack",
                "--ignored",
                "--nocapture",
                "--test-threads=1",
            ])
            .env(CHILD_ENV, mode)
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stdout);
        text.lines()
            .find_map(|l| l.split_once(SLACK_MARK))
            .and_then(|(_, v)| v.trim().parse().ok())
            .unwrap_or_else(|| panic!("the child printed no slack: {text}"))
    }

    #[test]
    #[ignore = "run in a fresh process by the test below"]
    fn child_block_slack() {
        let Ok(mode) = std::env::var(CHILD_ENV) else {
            return;
        };
        // What libsuperlu_dist's constructor does (whether or not this
        // test binary loads it).
        // SAFETY: as in restore_malloc_defaults.
        unsafe {
            libc::mallopt(libc::M_MMAP_MAX, 0);
            libc::mallopt(libc::M_TRIM_THRESHOLD, -1);
        }
        if mode == "restored" {
            restore_malloc_defaults();
        }
        // On a line of its own: libtest prints the test's name before it.
        println!("\n{SLACK_MARK}{}", slack_of_a_large_block());
    }

    #[test]
    fn large_blocks_are_mapped_on_their_own_after_the_restore() {
        let heap = slack_in_a_fresh_process("superlu");
        assert!(heap < 64, "with M_MMAP_MAX = 0: {heap} bytes of slack");
        let mapped = slack_in_a_fresh_process("restored");
        assert!(mapped >= 1024, "after the restore: {mapped} bytes of slack");
    }
}
