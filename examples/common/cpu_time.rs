//! The calling thread's CPU clock, shared by the benchmark examples (`#[path]` module).

/// The calling thread's CPU time (user + system) in seconds, from `CLOCK_THREAD_CPUTIME_ID` (the
/// clock of CGAL's anchor benchmark, nanosecond resolution), or `None` where it is missing.
#[cfg(all(target_os = "linux", target_pointer_width = "64"))]
pub fn thread_cpu_seconds() -> Option<f64> {
    #[repr(C)]
    struct Timespec {
        tv_sec: i64,
        tv_nsec: i64,
    }
    extern "C" {
        fn clock_gettime(clock: i32, ts: *mut Timespec) -> i32;
    }
    const CLOCK_THREAD_CPUTIME_ID: i32 = 3;
    let mut ts = Timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `ts` is a valid, writable timespec of the platform's layout (64-bit Linux).
    let rc = unsafe { clock_gettime(CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    (rc == 0).then_some(ts.tv_sec as f64 + 1e-9 * ts.tv_nsec as f64)
}

/// Elsewhere: no thread CPU clock; the caller falls back to wall time.
#[cfg(not(all(target_os = "linux", target_pointer_width = "64")))]
pub fn thread_cpu_seconds() -> Option<f64> {
    None
}

/// The calling thread's counters from `/proc/thread-self/stat`: minor page faults, user and
/// system CPU time in clock ticks (10 ms on this host), or `None` where the file is missing.
#[allow(dead_code)] // not every example that includes this module splits user and system time
#[derive(Clone, Copy, Debug, Default)]
pub struct ThreadStat {
    /// Minor page faults (field 10).
    pub minflt: u64,
    /// User-mode ticks (field 14).
    pub utime: u64,
    /// Kernel-mode ticks (field 15).
    pub stime: u64,
}

/// Reads [`ThreadStat`] of the calling thread. The fields after the command name (which may
/// hold spaces) are read from the last ')' on.
#[allow(dead_code)]
pub fn thread_stat() -> Option<ThreadStat> {
    let text = std::fs::read_to_string("/proc/thread-self/stat").ok()?;
    let rest = &text[text.rfind(')')? + 1..];
    // rest starts at field 3 (state): field k is at index k − 3.
    let f: Vec<&str> = rest.split_whitespace().collect();
    let get = |k: usize| f.get(k - 3)?.parse::<u64>().ok();
    Some(ThreadStat { minflt: get(10)?, utime: get(14)?, stime: get(15)? })
}
