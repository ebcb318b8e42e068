//! The command line's one piece of allocator tuning.
//!
//! glibc's malloc gives a thread that finds the arenas in use an arena of its own, up to eight
//! per core, and hands little of a thread arena's freed memory back to the system. The rewrite
//! spawns its worker threads anew for each parallel step, so a long `vtg` run leaves freed
//! buffers (whole-file outputs, race samples) spread over many arenas: on the 34 MB corpus file
//! with the dynamics model the peak resident memory was 740–793 MiB, 80–180 MiB over what the
//! heap held at its peak (heaptrack: 618 MB). As many arenas as the work has threads bring it to
//! 705–716 MiB at the same speed; a single arena made the threads wait on its lock (21.5 s
//! against 18.3 s). Measurements in `docs/measurements/vtg.md` (*Speed*).

/// Caps glibc's malloc arenas at `threads` (at least one). Other C libraries (musl, macOS,
/// Windows) keep their own allocators' ways: this is a no-op there.
pub fn cap_arenas(threads: usize) {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        let n = libc::c_int::try_from(threads.max(1)).unwrap_or(libc::c_int::MAX);
        // SAFETY: `mallopt` sets one of the allocator's tuning parameters from two integers; it
        // reads and writes no memory of ours and is safe to call from any thread at any time.
        #[allow(unsafe_code)]
        unsafe {
            libc::mallopt(libc::M_ARENA_MAX, n);
        }
    }
    #[cfg(not(all(target_os = "linux", target_env = "gnu")))]
    let _ = threads;
}
