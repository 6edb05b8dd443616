//! The stable C ABI (`include/voussoir.h`): opaque handles, status codes, copy-out getters.
//!
//! This is the only module with `unsafe`. It does no math: it checks what crosses the boundary
//! (NULL, length overflow, index range, finiteness, enum values), builds the Rust types and
//! calls [`crate::analyse`] / [`crate::form_find`] / [`crate::assess`]. Every exported
//! function body runs inside one `boundary!` (clear the thread-local last error,
//! `catch_unwind`, map failures to a [`VsrStatus`] and a one-line message). Outputs are
//! written only on success.
//!
//! The header is generated from these doc comments by cbindgen (`tests/capi_header.rs`; run
//! it with `VSR_BLESS=1` to rewrite `include/voussoir.h`).
#![allow(unsafe_code)]

mod boundary;
mod enum_args;
mod files;
mod mesh;
mod result;
mod settings;
mod solid;
mod solve;
mod status;
// Masonry assessment, after the rest: new functions come last in the header.
mod assess;
mod assessment;

pub use assess::*;
pub use assessment::*;
pub use files::*;
pub use mesh::*;
pub use result::*;
pub use settings::*;
pub use solid::*;
pub use solve::*;
pub use status::{
    VsrBoundKind, VsrEdgeScope, VsrFormulation, VsrHoleMode, VsrLoadRule, VsrMethod, VsrObjective,
    VsrQpSolver, VsrResultKind, VsrStatus, VsrStressStatus, VsrTauMode, VsrTermination,
};

use boundary::boundary;
use std::ffi::c_char;

/// Version of the C ABI. It changes only when a function, type or constant of the header is
/// removed or changes meaning; additions keep it. It is the number in the shared library's
/// SONAME (`libvoussoir.so.1`).
pub const VSR_ABI_VERSION: u32 = 1;

const VERSION: &std::ffi::CStr = match std::ffi::CStr::from_bytes_with_nul(
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_bytes(),
) {
    Ok(v) => v,
    Err(_) => panic!("version string"),
};

/// The library's version, "MAJOR.MINOR.PATCH" (equal to `VSR_VERSION_STRING` of the header it
/// was built with). Static storage: never free it. Leaves the last error untouched.
#[unsafe(no_mangle)]
pub extern "C" fn vsr_version() -> *const c_char {
    boundary!(keep_error, c"".as_ptr(), { VERSION.as_ptr() })
}

/// The library's C ABI version (`VSR_ABI_VERSION` of the header it was built with). A program
/// compiled against another ABI version must not use this library. Leaves the last error
/// untouched.
#[unsafe(no_mangle)]
pub extern "C" fn vsr_abi_version() -> u32 {
    boundary!(keep_error, 0, { VSR_ABI_VERSION })
}

/// A one-line, NUL-terminated UTF-8 message about the last failed call on this thread, naming
/// the argument, vertex, face or edge at fault; "" when the last status-returning call
/// succeeded, even if a call made inside it (by a progress callback) failed. Never NULL. The string belongs to the library and stays valid until the next
/// status-returning call on the same thread; copy it to keep it. Calls to `vsr_version`,
/// `vsr_abi_version`, `vsr_status_name`, `vsr_last_error_message` and the `_destroy`
/// functions leave it untouched.
#[unsafe(no_mangle)]
pub extern "C" fn vsr_last_error_message() -> *const c_char {
    boundary!(keep_error, c"".as_ptr(), { boundary::last_error_ptr() })
}

/// The name of a status as a static NUL-terminated string ("VSR_STATUS_OK", ...), or
/// "VSR_STATUS_UNKNOWN" for a value that is not a status. Never NULL; never free it. Leaves
/// the last error untouched.
#[unsafe(no_mangle)]
pub extern "C" fn vsr_status_name(status: u32) -> *const c_char {
    boundary!(keep_error, c"VSR_STATUS_UNKNOWN".as_ptr(), {
        VsrStatus::ALL
            .iter()
            .find(|s| **s as u32 == status)
            .map_or(c"VSR_STATUS_UNKNOWN".as_ptr(), |s| s.name().as_ptr())
    })
}
