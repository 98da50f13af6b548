//! The worker pool of the parallel stages, with each worker kept on its own CPU.
//!
//! Why pin: the pool's workers sleep through the front (which runs on the calling
//! thread) and between the optimizer's batches, and Linux wakes a sleeping thread on the
//! waker's CPU. On the 2-vCPU machines here both workers then shared one CPU in 4 ms time
//! slices until the load balancer moved one: single patches of the high-order stage took
//! 2-5 ms instead of 0.2 ms, and two threads were no faster than one. With worker i on
//! the i-th CPU the process may use, the high-order stage takes 30-35% less time on the
//! torus, tube, lv and hinge (medians of 7 runs).
//!
//! Only a pool with exactly one worker per CPU the process may use is pinned (the
//! default, `threads` = 0): a smaller pool is left free, so that concurrent calls with
//! a few threads each do not all crowd onto the first CPUs. `CURVETET_PIN_THREADS=0`
//! turns pinning off (for a host application that places its threads itself). The
//! result never depends on it.

use crate::{Error, Result};

/// A rayon pool of `threads` workers (0: as many as rayon chooses, one per CPU by
/// default), pinned as the module docs say.
pub fn pool(threads: usize) -> Result<rayon::ThreadPool> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Error::InvalidArgument(format!("cannot start {threads} threads: {e}")))?;
    let n = pool.current_num_threads();
    if n > 1 && pinning_wanted() {
        let cpus = allowed_cpus();
        if n == cpus.len() {
            // Every worker runs this once, with its own index.
            pool.broadcast(|ctx| pin_current_thread(cpus[ctx.index()]));
        }
    }
    Ok(pool)
}

/// False when `CURVETET_PIN_THREADS` is `0`, `false`, `no` or `off`.
fn pinning_wanted() -> bool {
    match std::env::var("CURVETET_PIN_THREADS") {
        Ok(v) => !matches!(v.trim(), "0" | "false" | "no" | "off"),
        Err(_) => true,
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

    #[cfg(target_os = "linux")]
    #[test]
    fn a_pool_of_one_worker_per_cpu_is_pinned_a_smaller_one_is_not() {
        let cpus = allowed_cpus();
        assert!(!cpus.is_empty());
        if cpus.len() < 2 || !pinning_wanted() {
            return; // nothing to pin on this machine, or pinning turned off
        }
        let on = worker_cpus(&pool(cpus.len()).unwrap());
        assert_eq!(on.len(), cpus.len());
        for (i, w) in on.iter().enumerate() {
            assert_eq!(w, &vec![cpus[i]], "worker {i}");
        }
        if cpus.len() > 2 {
            let on = worker_cpus(&pool(cpus.len() - 1).unwrap());
            assert!(on.iter().all(|w| w == &cpus), "{on:?}");
        }
    }
}
