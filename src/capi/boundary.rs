//! The panic boundary, the thread-local last error and the checked readers of caller memory.
//!
//! Every exported function runs inside [`boundary!`]: status-returning functions clear the last
//! error on entry, set it on failure and clear it again on success (a progress callback may
//! have made a failing call in between); the few infallible ones (`vsr_version`,
//! `vsr_status_name`, `vsr_last_error_message`, the `_destroy` functions) leave it untouched so
//! that a host can clean up or format a message before it reads the error.

use super::status::VsrStatus;
use crate::error::Error;
use std::cell::RefCell;
use std::ffi::{c_char, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

/// A failed call: the status to return and the one-line message to keep.
#[derive(Debug)]
pub(crate) struct Failure {
    pub status: VsrStatus,
    pub message: String,
}

impl Failure {
    pub fn new(status: VsrStatus, message: impl Into<String>) -> Failure {
        Failure {
            status,
            message: message.into(),
        }
    }

    /// A NULL pointer in slot `name`.
    pub fn null(name: &str) -> Failure {
        Failure::new(VsrStatus::NullPointer, format!("argument `{name}` is NULL"))
    }

    /// An invalid value of argument `name`.
    pub fn invalid(name: &str, reason: impl std::fmt::Display) -> Failure {
        Failure::new(
            VsrStatus::InvalidArgument,
            format!("argument `{name}`: {reason}"),
        )
    }
}

pub(crate) type CResult<T = ()> = Result<T, Failure>;

/// Stores `message` (made one line, without interior NULs) as this thread's last error.
pub(crate) fn set_last_error(message: &str) {
    let line: String = message
        .chars()
        .map(|c| match c {
            '\0' => ' ',
            '\n' | '\r' => ' ',
            c => c,
        })
        .collect();
    let c = CString::new(line).unwrap_or_default();
    LAST_ERROR.with(|e| *e.borrow_mut() = c);
}

/// Pointer to this thread's last error (never NULL; "" when the last call succeeded).
pub(crate) fn last_error_ptr() -> *const c_char {
    LAST_ERROR.with(|e| e.borrow().as_ptr())
}

fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    let what = payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown payload".into());
    format!("internal error (panic) in voussoir: {what}")
}

/// Runs a status-returning body: clears the last error, catches panics. The message is
/// cleared again on success: calls made inside the body (a progress callback's) may have set
/// one, and a successful call always leaves "".
pub(crate) fn run(f: impl FnOnce() -> CResult) -> VsrStatus {
    set_last_error("");
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(())) => {
            set_last_error("");
            VsrStatus::Ok
        }
        Ok(Err(failure)) => {
            set_last_error(&failure.message);
            failure.status
        }
        Err(payload) => {
            set_last_error(&panic_message(payload.as_ref()));
            VsrStatus::Panic
        }
    }
}

/// Runs an infallible body without touching the last error unless it panics.
pub(crate) fn run_value<T>(fallback: T, f: impl FnOnce() -> T) -> T {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(v) => v,
        Err(payload) => {
            set_last_error(&panic_message(payload.as_ref()));
            fallback
        }
    }
}

/// The one boundary every exported function body runs in.
///
/// `boundary!({ ... })` for functions returning `VsrStatus` (body returns `CResult`);
/// `boundary!(keep_error, fallback, { ... })` for the infallible ones.
macro_rules! boundary {
    (keep_error, $fallback:expr, $body:block) => {
        $crate::capi::boundary::run_value($fallback, move || $body)
    };
    ($body:block) => {
        $crate::capi::boundary::run(move || $body)
    };
}
pub(crate) use boundary;

/// `n * per` elements, failing with `LENGTH_OVERFLOW` naming `name` when it overflows or when
/// the byte size of `T` elements exceeds `isize::MAX` (the limit of a Rust slice).
pub(crate) fn checked_len<T>(name: &str, count: &str, n: usize, per: usize) -> CResult<usize> {
    let bytes = n
        .checked_mul(per)
        .and_then(|m| m.checked_mul(std::mem::size_of::<T>()).map(|b| (m, b)));
    match bytes {
        Some((m, b)) if b <= isize::MAX as usize => Ok(m),
        _ => Err(Failure::new(
            VsrStatus::LengthOverflow,
            format!("argument `{name}`: {count} = {n} times {per} overflows the address space"),
        )),
    }
}

/// Borrows `len` elements of caller memory. NULL is accepted only when `len` is 0.
///
/// # Safety
/// When non-NULL, `ptr` must point to `len` readable, initialised elements that stay valid and
/// unmodified for the returned lifetime.
pub(crate) unsafe fn input<'a, T>(name: &str, ptr: *const T, len: usize) -> CResult<&'a [T]> {
    if len == 0 {
        return Ok(&[]);
    }
    if ptr.is_null() {
        return Err(Failure::new(
            VsrStatus::NullPointer,
            format!("argument `{name}` is NULL but its length is {len}"),
        ));
    }
    checked_len::<T>(name, "length", len, 1)?;
    if (ptr as usize) % std::mem::align_of::<T>() != 0 {
        return Err(Failure::invalid(
            name,
            "pointer is not aligned for its type",
        ));
    }
    // SAFETY: non-NULL, aligned, size checked; validity of the memory is the caller's contract.
    Ok(unsafe { std::slice::from_raw_parts(ptr, len) })
}

/// Borrows a handle.
///
/// # Safety
/// When non-NULL, `ptr` must come from the matching `_create` / solve function and not have
/// been destroyed.
pub(crate) unsafe fn handle<'a, T>(name: &str, ptr: *const T) -> CResult<&'a T> {
    // SAFETY: the caller's contract above.
    unsafe { ptr.as_ref() }.ok_or_else(|| Failure::null(name))
}

/// Borrows a handle mutably (same contract as [`handle`], plus exclusive access).
pub(crate) unsafe fn handle_mut<'a, T>(name: &str, ptr: *mut T) -> CResult<&'a mut T> {
    // SAFETY: the caller's contract above.
    unsafe { ptr.as_mut() }.ok_or_else(|| Failure::null(name))
}

/// Checks that an out-pointer is non-NULL; the value is written later, on success only.
pub(crate) fn out_ptr<T>(name: &str, ptr: *mut T) -> CResult<*mut T> {
    if ptr.is_null() {
        Err(Failure::null(name))
    } else {
        Ok(ptr)
    }
}

/// Moves `value` to the heap and gives it to the caller through `out` (checked first): the
/// body of the `_create` functions and of the solves.
///
/// # Safety
/// `out` must be NULL or writable.
pub(crate) unsafe fn give<T>(out: *mut *mut T, value: T) -> CResult {
    let out = out_ptr("out", out)?;
    // SAFETY: non-NULL, writable by the caller's contract.
    unsafe { out.write(Box::into_raw(Box::new(value))) };
    Ok(())
}

/// Frees a handle made by [`give`]; NULL is a no-op: the body of the `_destroy` functions.
///
/// # Safety
/// `ptr` must be NULL or a handle from [`give`] not yet freed, used by no other thread.
pub(crate) unsafe fn free<T>(ptr: *mut T) {
    if !ptr.is_null() {
        // SAFETY: from Box::into_raw in `give`, freed once (caller's contract).
        drop(unsafe { Box::from_raw(ptr) });
    }
}

/// Borrows the handle `name`, checks every out-pointer, then writes `pick(handle)` into
/// them: the body of the getters of several scalars of one type.
///
/// # Safety
/// As [`handle`]; the out-pointers writable.
pub(crate) unsafe fn scalars<H, T: Copy, const N: usize>(
    name: &str,
    ptr: *const H,
    outs: [(&str, *mut T); N],
    pick: impl FnOnce(&H) -> CResult<[T; N]>,
) -> CResult {
    // SAFETY: caller's contract.
    let h = unsafe { handle(name, ptr)? };
    for (name, p) in outs {
        out_ptr(name, p)?;
    }
    let values = pick(h)?;
    for ((_, p), v) in outs.into_iter().zip(values) {
        // SAFETY: non-NULL and writable by the caller's contract.
        unsafe { p.write(v) };
    }
    Ok(())
}

/// Borrows the handle `name` and copies `pick(handle)` out with [`copy_out`]: the body of
/// every array getter.
///
/// # Safety
/// As [`handle`] and [`copy_out`].
pub(crate) unsafe fn copy<H, T: Copy>(
    name: &str,
    ptr: *const H,
    out: *mut T,
    len: usize,
    needed: *mut usize,
    pick: impl FnOnce(&H) -> CResult<Vec<T>>,
) -> CResult {
    // SAFETY: caller's contract.
    let h = unsafe { handle(name, ptr)? };
    let data = pick(h)?;
    // SAFETY: caller's contract.
    unsafe { copy_out(&data, out, len, needed) }
}

/// `text` as a NUL-terminated string for [`copy`] (its NUL bytes, if any, left out).
pub(crate) fn c_string(text: &str) -> Vec<c_char> {
    let mut bytes: Vec<c_char> = text
        .bytes()
        .filter(|&b| b != 0)
        .map(|b| b as c_char)
        .collect();
    bytes.push(0);
    bytes
}

/// Copies `data` into the caller's buffer `out` of capacity `len` elements and reports
/// `data.len()` through `needed` (optional).
///
/// `out == NULL && len == 0` is a size query (OK, only `needed` written). A short buffer
/// returns `BUFFER_TOO_SMALL`, writes `needed` and leaves `out` untouched.
///
/// # Safety
/// `out` must be NULL or point to `len` writable elements; `needed` NULL or writable.
pub(crate) unsafe fn copy_out<T: Copy>(
    data: &[T],
    out: *mut T,
    len: usize,
    needed: *mut usize,
) -> CResult {
    if out.is_null() && len != 0 {
        return Err(Failure::new(
            VsrStatus::NullPointer,
            format!("argument `out` is NULL but `len` is {len}"),
        ));
    }
    let n = data.len();
    let report = || {
        if !needed.is_null() {
            // SAFETY: non-NULL; writable by the caller's contract.
            unsafe { needed.write(n) };
        }
    };
    if out.is_null() {
        report();
        return Ok(());
    }
    if len < n {
        report();
        return Err(Failure::new(
            VsrStatus::BufferTooSmall,
            format!("argument `len`: the buffer `out` holds {len} entries, {n} are needed"),
        ));
    }
    if (out as usize) % std::mem::align_of::<T>() != 0 {
        return Err(Failure::invalid(
            "out",
            "pointer is not aligned for its type",
        ));
    }
    // SAFETY: `out` holds at least `len >= n` writable elements (caller's contract); `data`
    // is Rust-owned memory, so the two cannot overlap.
    unsafe { std::ptr::copy_nonoverlapping(data.as_ptr(), out, n) };
    report();
    Ok(())
}

/// Maps a library error to a status and a message prefixed with the argument at fault.
pub(crate) fn from_error(arg: &str, e: Error) -> Failure {
    use Error::*;
    let (status, arg) = match &e {
        // Its own wording starts "invalid argument `name`": said once.
        InvalidArgument { name, reason } => {
            return Failure::new(
                VsrStatus::InvalidArgument,
                format!("argument `{name}`: {reason}"),
            )
        }
        // The caller names the empty input: an array, or the file read.
        EmptyMesh => (VsrStatus::EmptyMesh, arg),
        IndexOutOfRange { .. } => (VsrStatus::IndexOutOfRange, "triangles"),
        InvalidAnchor { reason, .. } => (
            if *reason == "out of range" {
                VsrStatus::IndexOutOfRange
            } else {
                VsrStatus::InvalidArgument
            },
            "anchored",
        ),
        NonFiniteCoordinate { .. } => (VsrStatus::NonFinite, "positions"),
        RepeatedVertexInFace { .. }
        | DuplicateFace { .. }
        | NonManifoldEdge { .. }
        | NonManifoldVertex { .. }
        | InconsistentOrientation { .. }
        | HoleNotCuttable { .. } => (VsrStatus::InvalidTopology, "triangles"),
        DegenerateFaces { .. }
        | FlippedFaces { .. }
        | OverlappingPlan { .. }
        | OverlappingFaces { .. } => (VsrStatus::InvalidPlan, "positions"),
        UnsupportedComponent { .. } | NoSupports => (VsrStatus::NoSupport, "anchored"),
        Numerical { .. } => (VsrStatus::Numerical, arg),
        Io { .. } | Parse { .. } | Malformed { .. } => (VsrStatus::InvalidArgument, arg),
    };
    Failure::new(status, format!("argument `{arg}`: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn last_error() -> String {
        // SAFETY: the pointer is this thread's NUL-terminated last error.
        unsafe { std::ffi::CStr::from_ptr(last_error_ptr()) }
            .to_string_lossy()
            .into_owned()
    }

    #[test]
    fn a_panic_becomes_a_status_and_a_one_line_message() {
        let status = run(|| panic!("boom\nsecond line"));
        assert_eq!(status, VsrStatus::Panic);
        let message = last_error();
        assert!(
            message.contains("panic") && message.contains("boom"),
            "{message}"
        );
        assert!(!message.contains('\n'));
        // Infallible functions return their fallback and keep a message.
        assert_eq!(run_value(7, || -> i32 { panic!("again") }), 7);
        assert!(last_error().contains("again"));
        // A successful call clears it.
        assert_eq!(run(|| Ok(())), VsrStatus::Ok);
        assert_eq!(last_error(), "");
        // Also when a call inside it (a progress callback's) failed.
        let status = run(|| {
            assert_eq!(run(|| Err(Failure::null("inner"))), VsrStatus::NullPointer);
            Ok(())
        });
        assert_eq!(status, VsrStatus::Ok);
        assert_eq!(last_error(), "");
    }

    #[test]
    fn messages_never_hold_nul_bytes() {
        let status = run(|| Err(Failure::invalid("x", "a\0b")));
        assert_eq!(status, VsrStatus::InvalidArgument);
        assert_eq!(last_error(), "argument `x`: a b");
    }
}
