//! CPU time: what a stage cost, not how long it waited for a core. On a machine shared with
//! other work, wall time per stage over-counts (a worker that waits still ages), so stage
//! figures are CPU seconds of the thread that did the work.

use std::time::Instant;

#[cfg(unix)]
fn clock(id: libc::clockid_t) -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec; the clock ids used exist on every unix.
    let rc = unsafe { libc::clock_gettime(id, &mut ts) };
    if rc != 0 {
        return f64::NAN;
    }
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

/// CPU seconds the calling thread has used (NaN where the platform cannot tell).
pub fn thread_seconds() -> f64 {
    #[cfg(unix)]
    {
        clock(libc::CLOCK_THREAD_CPUTIME_ID)
    }
    #[cfg(not(unix))]
    {
        f64::NAN
    }
}

/// CPU seconds the whole process has used, all threads (NaN where unknown).
pub fn process_seconds() -> f64 {
    #[cfg(unix)]
    {
        clock(libc::CLOCK_PROCESS_CPUTIME_ID)
    }
    #[cfg(not(unix))]
    {
        f64::NAN
    }
}

/// Wall and thread CPU time since it started.
#[derive(Clone, Copy, Debug)]
pub struct Stopwatch {
    wall: Instant,
    cpu: f64,
}

impl Stopwatch {
    /// Start now, on the calling thread.
    pub fn start() -> Stopwatch {
        Stopwatch {
            wall: Instant::now(),
            cpu: thread_seconds(),
        }
    }

    /// Wall milliseconds since the start.
    pub fn wall_ms(&self) -> f64 {
        self.wall.elapsed().as_secs_f64() * 1e3
    }

    /// CPU milliseconds of the calling thread since the start (call it on the thread
    /// that started it); wall milliseconds where the platform has no thread clock.
    pub fn cpu_ms(&self) -> f64 {
        let d = (thread_seconds() - self.cpu) * 1e3;
        if d.is_finite() { d } else { self.wall_ms() }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cpu_time_counts_work_not_sleep() {
        let sw = Stopwatch::start();
        std::thread::sleep(std::time::Duration::from_millis(30));
        let slept = sw.cpu_ms();
        let mut x = 0u64;
        let busy = Stopwatch::start();
        while busy.wall_ms() < 30.0 {
            x = x.wrapping_add(std::hint::black_box(1));
        }
        assert!(x > 0);
        // Sleeping costs (almost) no CPU; spinning costs some (the thread may be preempted,
        // so no lower bound near 30 ms is certain).
        assert!(slept < 10.0, "slept {slept} ms of CPU");
        assert!(busy.cpu_ms() > 0.0 && busy.cpu_ms() <= busy.wall_ms() + 1.0);
        assert!(process_seconds() >= thread_seconds());
    }
}
