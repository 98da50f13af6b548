//! The worker pool of the parallel stages, with each worker optionally kept on its own
//! CPU.
//!
//! Why pin: the pool's workers sleep through the front (which runs on the calling
//! thread) and between the optimizer's batches, and Linux wakes a sleeping thread on the
//! waker's CPU. On a machine with few CPUs two workers then share one CPU in
//! scheduler time slices until the load balancer moves one, and two threads are no
//! faster than one; with worker i on the i-th CPU the process may use, the high-order
//! stage takes about a third less time (docs/benchmarks.md).
//!
//! Why not by default: a library inside a host process (VTK, ParaView, MeshLab, Gmsh)
//! must not place threads the host may be placing itself. So pinning is asked for
//! ([`crate::Options::pin_threads`]; the `curvetet` command asks), and even then only a
//! pool with exactly one worker per CPU the process may use is pinned: a smaller pool is
//! left free, so that concurrent calls with a few threads each do not all crowd onto the
//! first CPUs. `CURVETET_PIN_THREADS` overrides the request: `0`/`false`/`no`/`off` never
//! pins, `1`/`true`/`yes`/`on` pins as if asked. The result never depends on it.

use crate::{Error, Result};

/// The name of the pool's workers, followed by their index: a panic on one is always
/// handed to the thread that called into curvetet (rayon resumes it there).
pub(crate) const WORKER_PREFIX: &str = "curvetet-worker-";

/// The hard upper bound of [`max_threads`], whatever the machine.
pub const THREADS_HARD_MAX: usize = 1024;

/// The most worker threads a caller may ask for: 4 per CPU the process may use, at most
/// [`THREADS_HARD_MAX`]. More gain nothing (the work is CPU bound) and a mistyped count
/// would otherwise start thousands of threads before failing.
pub fn max_threads() -> usize {
    let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
    cpus.saturating_mul(4).min(THREADS_HARD_MAX)
}

/// An [`Error::InvalidArgument`] when `threads` is above [`max_threads`] (0, all CPUs, is
/// always accepted).
pub fn check_threads(threads: usize) -> Result<()> {
    let max = max_threads();
    if threads > max {
        return Err(Error::InvalidArgument(format!(
            "{threads} threads: at most {max} (4 per CPU, at most {THREADS_HARD_MAX}); 0 uses \
             every CPU"
        )));
    }
    Ok(())
}

/// A rayon pool of `threads` workers (0: as many as rayon chooses, one per CPU by
/// default), pinned as the module docs say when `pin` (or `CURVETET_PIN_THREADS`) asks.
/// More than [`max_threads`] is an error.
pub fn pool(threads: usize, pin: bool) -> Result<rayon::ThreadPool> {
    check_threads(threads)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .thread_name(|i| format!("{WORKER_PREFIX}{i}"))
        .build()
        .map_err(|e| Error::InvalidArgument(format!("cannot start {threads} threads: {e}")))?;
    let n = pool.current_num_threads();
    if n > 1 && pinning_wanted(pin) {
        let cpus = allowed_cpus();
        if n == cpus.len() {
            // Every worker runs this once, with its own index.
            pool.broadcast(|ctx| pin_current_thread(cpus[ctx.index()]));
        }
    }
    Ok(pool)
}

/// The environment variable that overrides [`crate::Options::pin_threads`].
pub const PIN_THREADS_ENV: &str = "CURVETET_PIN_THREADS";

/// `asked`, unless `CURVETET_PIN_THREADS` says otherwise (`0`, `false`, `no`, `off`: no;
/// `1`, `true`, `yes`, `on`: yes; anything else leaves `asked`).
fn pinning_wanted(asked: bool) -> bool {
    match std::env::var(PIN_THREADS_ENV).as_deref().map(str::trim) {
        Ok("0" | "false" | "no" | "off") => false,
        Ok("1" | "true" | "yes" | "on") => true,
        _ => asked,
    }
}

/// The CPUs the calling thread may run on, in order (empty where unknown).
#[cfg(target_os = "linux")]
fn allowed_cpus() -> Vec<usize> {
    // SAFETY: cpu_set_t is plain data; sched_getaffinity writes at most its size.
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        if libc::sched_getaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &mut set) != 0 {
            return Vec::new();
        }
        (0..libc::CPU_SETSIZE as usize)
            .filter(|&c| libc::CPU_ISSET(c, &set))
            .collect()
    }
}

#[cfg(not(target_os = "linux"))]
fn allowed_cpus() -> Vec<usize> {
    Vec::new()
}

/// Keep the calling thread on `cpu` (best effort: a failure leaves it unpinned).
#[cfg(target_os = "linux")]
fn pin_current_thread(cpu: usize) {
    // SAFETY: as above; sched_setaffinity only reads the set.
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        libc::CPU_SET(cpu, &mut set);
        libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set);
    }
}

#[cfg(not(target_os = "linux"))]
fn pin_current_thread(_cpu: usize) {}

#[cfg(test)]
mod tests {
    use super::*;

    /// The CPUs each worker of `p` may run on, by worker index.
    #[cfg(target_os = "linux")]
    fn worker_cpus(p: &rayon::ThreadPool) -> Vec<Vec<usize>> {
        p.broadcast(|_| allowed_cpus())
    }

    #[test]
    fn thread_counts_above_the_cap_are_refused_at_once() {
        let max = max_threads();
        assert!((4..=THREADS_HARD_MAX).contains(&max), "{max}");
        assert!(check_threads(0).is_ok() && check_threads(max).is_ok());
        let t = std::time::Instant::now();
        for n in [max + 1, 100_000, usize::MAX] {
            let e = pool(n, false).unwrap_err();
            assert!(matches!(e, Error::InvalidArgument(_)), "{e}");
            assert!(e.to_string().contains(&format!("at most {max}")), "{e}");
        }
        assert!(t.elapsed() < std::time::Duration::from_secs(1));
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn a_pool_of_one_worker_per_cpu_is_pinned_when_asked_a_smaller_one_is_not() {
        let cpus = allowed_cpus();
        assert!(!cpus.is_empty());
        if cpus.len() < 2 || std::env::var_os(PIN_THREADS_ENV).is_some() {
            return; // nothing to pin on this machine, or the environment decides
        }
        // Not asked (the library's default): every worker may run on every CPU.
        let free = worker_cpus(&pool(cpus.len(), false).unwrap());
        assert_eq!(free.len(), cpus.len());
        assert!(free.iter().all(|w| w == &cpus), "{free:?}");
        let on = worker_cpus(&pool(cpus.len(), true).unwrap());
        assert_eq!(on.len(), cpus.len());
        for (i, w) in on.iter().enumerate() {
            assert_eq!(w, &vec![cpus[i]], "worker {i}");
        }
        if cpus.len() > 2 {
            let on = worker_cpus(&pool(cpus.len() - 1, true).unwrap());
            assert!(on.iter().all(|w| w == &cpus), "{on:?}");
        }
    }
}
