//! The panic boundary and the argument checks every entry point goes through.
//!
//! Since Rust 1.81 a panic unwinding out of an `extern "C"` function aborts the host
//! process, so every entry point runs its body inside [`status_call`] or [`value_call`],
//! which catch the panic and turn it into `CURVETET_ERR_PANIC` with the panic message.
//!
//! A caught panic is the caller's to report, through the status and the message: Rust's
//! default panic hook would also print it to the host's stderr. So the first entry point
//! called wraps the process's panic hook once ([`quiet_hook`]): a panic on a thread that
//! is inside an entry point, or on one of curvetet's worker threads, prints nothing and
//! leaves its location for the message; any other panic goes to the previous hook as
//! before (the host's own panics, if the host is Rust, are untouched).

use super::status::{clear_last_error, curvetet_status, set_last_error};
use crate::{Error, Result};
use std::any::Any;
use std::cell::{Cell, RefCell};
use std::panic::{catch_unwind, AssertUnwindSafe};

thread_local! {
    /// How many entry points this thread is inside (callbacks may call back in).
    static IN_CALL: Cell<u32> = const { Cell::new(0) };
    /// Where this thread's last caught panic happened, for its message.
    static PANIC_AT: RefCell<Option<String>> = const { RefCell::new(None) };
}

/// Install [`quiet_hook`] once, in front of whatever hook the process has.
fn install_quiet_hook() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| quiet_hook(info, &*previous)));
    });
}

/// The panic hook of the module docs.
fn quiet_hook(
    info: &std::panic::PanicHookInfo,
    previous: &(dyn Fn(&std::panic::PanicHookInfo) + Send + Sync),
) {
    let ours = IN_CALL.try_with(|c| c.get() > 0).unwrap_or(false)
        || std::thread::current()
            .name()
            .is_some_and(|n| n.starts_with(crate::threads::WORKER_PREFIX));
    if !ours {
        return previous(info);
    }
    let at = info
        .location()
        .map(|l| format!("{}:{}", l.file(), l.line()));
    let _ = PANIC_AT.try_with(|p| p.try_borrow_mut().map(|mut p| *p = at));
}

/// Runs `body` as an entry point's: inside it this thread's panics are quiet.
fn in_call<T>(body: impl FnOnce() -> T) -> std::thread::Result<T> {
    install_quiet_hook();
    let _ = PANIC_AT.try_with(|p| p.try_borrow_mut().map(|mut p| *p = None));
    let _ = IN_CALL.try_with(|c| c.set(c.get() + 1));
    let r = catch_unwind(AssertUnwindSafe(body));
    let _ = IN_CALL.try_with(|c| c.set(c.get().saturating_sub(1)));
    r
}

/// The text of a panic payload (`panic!` gives `&str` or `String`).
fn panic_message(payload: &(dyn Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "(non-string panic payload)".to_string()
    }
}

/// Record a caught panic and drop its payload without letting a second panic escape.
fn record_panic(func: &str, payload: Box<dyn Any + Send>) {
    let at = PANIC_AT
        .try_with(|p| p.try_borrow_mut().ok().and_then(|mut p| p.take()))
        .ok()
        .flatten()
        .map(|l| format!(" at {l}"))
        .unwrap_or_default();
    set_last_error(&format!(
        "{func}: internal error (panic{at}): {}; please report this as a bug",
        panic_message(&*payload)
    ));
    // A payload whose destructor panics must not unwind into C either.
    let _ = catch_unwind(AssertUnwindSafe(move || drop(payload)));
}

/// A failed call: its status and message. Every [`Error`] converts into one (so `?`
/// works in entry points); a few calls build their own for a more precise message.
#[derive(Debug)]
pub(crate) struct Failure {
    pub status: curvetet_status,
    pub msg: String,
}

impl From<Error> for Failure {
    fn from(e: Error) -> Failure {
        Failure {
            status: curvetet_status::of(&e),
            msg: e.to_string(),
        }
    }
}

/// Run the body of a status-returning entry point `func`: `Ok` clears the last error and
/// gives `CURVETET_OK`; an error records its message (prefixed with `func`) and gives its
/// status code; a panic gives `CURVETET_ERR_PANIC`.
pub(crate) fn status_call(
    func: &str,
    body: impl FnOnce() -> std::result::Result<(), Failure>,
) -> curvetet_status {
    match in_call(body) {
        Ok(Ok(())) => {
            clear_last_error();
            curvetet_status::CURVETET_OK
        }
        Ok(Err(f)) => {
            set_last_error(&format!("{func}: {}", f.msg));
            f.status
        }
        Err(payload) => {
            record_panic(func, payload);
            curvetet_status::CURVETET_ERR_PANIC
        }
    }
}

/// Run the body of an accessor `func` that returns a value rather than a status: an
/// error or a panic records the message and gives `fallback`; success leaves the last
/// error as it was (so it can still be read after a failed call).
pub(crate) fn value_call<T>(func: &str, fallback: T, body: impl FnOnce() -> Result<T>) -> T {
    match in_call(body) {
        Ok(Ok(v)) => v,
        Ok(Err(e)) => {
            set_last_error(&format!("{func}: {e}"));
            fallback
        }
        Err(payload) => {
            record_panic(func, payload);
            fallback
        }
    }
}

/// An invalid-argument error.
pub(crate) fn invalid(msg: impl Into<String>) -> Error {
    Error::InvalidArgument(msg.into())
}

/// `p` as a shared reference, or an error naming the parameter when it is NULL or
/// misaligned.
///
/// # Safety
/// A non-NULL `p` must point to a live `T` for the lifetime the caller picks.
pub(crate) unsafe fn deref<'a, T>(p: *const T, name: &str) -> Result<&'a T> {
    check_ptr(p, name)?;
    // SAFETY: non-NULL and aligned (checked); validity is the caller's contract.
    Ok(unsafe { &*p })
}

/// Error when `p` is NULL or not aligned for `T`.
pub(crate) fn check_ptr<T>(p: *const T, name: &str) -> Result<()> {
    if p.is_null() {
        return Err(invalid(format!("{name} is NULL")));
    }
    if !p.is_aligned() {
        return Err(invalid(format!(
            "{name} ({p:p}) is not aligned to {} bytes",
            std::mem::align_of::<T>()
        )));
    }
    Ok(())
}

/// `len` elements of `T` starting at `p` as a slice. `p` may be NULL only when `len` is
/// 0. `what` names the parameter and `count` the count it was derived from.
///
/// # Safety
/// A non-NULL `p` must point to `len` initialised `T`s that stay unchanged while the
/// slice is used.
pub(crate) unsafe fn input_slice<'a, T>(p: *const T, len: usize, what: &str) -> Result<&'a [T]> {
    if len == 0 {
        return Ok(&[]);
    }
    check_ptr(p, what)?;
    if len
        .checked_mul(std::mem::size_of::<T>())
        .map_or(true, |b| b > isize::MAX as usize)
    {
        return Err(invalid(format!("{what}: {len} elements is too many")));
    }
    // SAFETY: non-NULL, aligned, size fits isize (checked); contents are the caller's
    // contract (documented in the header).
    Ok(unsafe { std::slice::from_raw_parts(p, len) })
}

/// Error unless `num_nodes` and `num_triangles` fit the library's 32-bit node indices
/// (checked before any slice is made or memory is reserved from them).
pub(crate) fn check_counts(num_nodes: usize, num_triangles: usize) -> Result<()> {
    for (what, n) in [("num_nodes", num_nodes), ("num_triangles", num_triangles)] {
        if n > u32::MAX as usize {
            return Err(invalid(format!(
                "{what} is {n}: at most {} (node indices are 32-bit)",
                u32::MAX
            )));
        }
    }
    Ok(())
}

/// `src` copied into a new vector of `N`-element groups, or an error (not an abort) when
/// the memory cannot be reserved.
pub(crate) fn copy_groups<T: Copy + Default, const N: usize>(
    src: &[T],
    what: &str,
) -> Result<Vec<[T; N]>> {
    let n = src.len() / N;
    let mut v = Vec::new();
    v.try_reserve_exact(n)
        .map_err(|e| invalid(format!("{what}: cannot reserve memory for {n} items ({e})")))?;
    v.extend(src.chunks_exact(N).map(|c| {
        let mut a = [T::default(); N];
        a.copy_from_slice(c);
        a
    }));
    Ok(v)
}

/// `n * k` elements, or an error when it overflows.
pub(crate) fn times(n: usize, k: usize, what: &str) -> Result<usize> {
    n.checked_mul(k)
        .ok_or_else(|| invalid(format!("{what}: count {n} overflows")))
}

/// Copy `values` to the caller's buffer `out`, which must hold `values.len()` elements.
/// `out` may be NULL only when there is nothing to copy.
///
/// # Safety
/// A non-NULL `out` must be valid for writing `values.len()` elements.
pub(crate) unsafe fn copy_out<T: Copy>(values: &[T], out: *mut T, name: &str) -> Result<()> {
    if values.is_empty() {
        return Ok(());
    }
    check_ptr(out.cast_const(), name)?;
    // SAFETY: `out` is non-NULL and aligned (checked) and holds values.len() elements by
    // the documented contract; a Rust slice never overlaps a caller's buffer we write.
    unsafe { std::ptr::copy_nonoverlapping(values.as_ptr(), out, values.len()) };
    Ok(())
}
