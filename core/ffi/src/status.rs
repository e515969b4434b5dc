//! Status codes, the thread-local last error message, and the guard every entry point runs its
//! body in: it turns errors into a status plus a message, and catches panics so that none
//! unwinds into the caller's C frames.

use std::any::Any;
use std::cell::RefCell;
use std::ffi::{CString, c_char};
use std::panic::{self, AssertUnwindSafe};

/// What a `lucent_*` call did. Every function that can fail returns one; on anything but
/// `LUCENT_OK`, `lucent_last_error_message()` says why.
#[repr(C)]
#[allow(non_camel_case_types)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LucentStatus {
    /// Success.
    LUCENT_OK = 0,
    /// A required pointer argument is NULL (the message names it).
    LUCENT_NULL_POINTER = 1,
    /// An argument is out of range: a non-finite or negative number, an invalid sample, a
    /// misaligned pointer, a string that is not UTF-8, an unknown method value (the message
    /// names the argument and the value).
    LUCENT_INVALID_ARGUMENT = 2,
    /// `lucent_profile_from_preset` was given a name that is not a measured material.
    LUCENT_UNKNOWN_PRESET = 3,
    /// A valid request that the call cannot serve: an edge-refined plan given to
    /// `lucent_query_point` or `lucent_query_points`, which have no irradiance callback (use
    /// `lucent_query_point_refined`).
    LUCENT_UNSUPPORTED = 4,
    /// An internal error (a panic inside the library) was caught at the boundary. The library
    /// state is unchanged (handles stay valid), but this is a bug: please report the message.
    LUCENT_PANIC = 5,
    /// The caller's irradiance callback returned non-zero: the query was abandoned and nothing
    /// was written (the message names the node and the value returned).
    LUCENT_CALLBACK_FAILED = 6,
}

/// A failed call: its status and a message for `lucent_last_error_message`.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Failure {
    pub(crate) status: LucentStatus,
    pub(crate) message: String,
}

impl Failure {
    /// `LUCENT_NULL_POINTER` naming the argument.
    pub(crate) fn null(argument: &str) -> Failure {
        Failure {
            status: LucentStatus::LUCENT_NULL_POINTER,
            message: format!("{argument} is NULL"),
        }
    }

    /// `LUCENT_INVALID_ARGUMENT` with a message that names the argument.
    pub(crate) fn invalid(message: impl Into<String>) -> Failure {
        Failure {
            status: LucentStatus::LUCENT_INVALID_ARGUMENT,
            message: message.into(),
        }
    }

    /// Any status with a message.
    pub(crate) fn new(status: LucentStatus, message: impl Into<String>) -> Failure {
        Failure {
            status,
            message: message.into(),
        }
    }
}

thread_local! {
    /// The message of the last call on this thread ("" after a success).
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

/// Replaces this thread's message. Interior NUL bytes (impossible in the library's own
/// messages, possible in an echoed argument) become U+FFFD so that the C string is whole.
/// Runs outside `catch_unwind`, so it cannot panic: during thread teardown, when the slot is
/// gone, the message is dropped.
fn set_last_error(message: String) {
    let message = CString::new(message).unwrap_or_else(|e| {
        let cleaned = String::from_utf8_lossy(&e.into_vec()).replace('\0', "\u{fffd}");
        CString::new(cleaned).unwrap_or_default()
    });
    let _ = LAST_ERROR.try_with(|slot| {
        if let Ok(mut slot) = slot.try_borrow_mut() {
            *slot = message;
        }
    });
}

/// The text of a panic payload (`panic!` gives a `&str` or a `String`).
fn panic_text(payload: &(dyn Any + Send)) -> &str {
    if let Some(s) = payload.downcast_ref::<&str>() {
        s
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s
    } else {
        "a panic without a message"
    }
}

/// Runs one entry point's body: records its message (or clears it), and catches a panic as
/// `LUCENT_PANIC`. The body writes its outputs only once everything has succeeded, so a panic
/// leaves them untouched; the handles it reads are immutable, so they stay valid.
pub(crate) fn guard(body: impl FnOnce() -> Result<(), Failure>) -> LucentStatus {
    let outcome = panic::catch_unwind(AssertUnwindSafe(body));
    let (status, message) = match outcome {
        Ok(Ok(())) => (LucentStatus::LUCENT_OK, String::new()),
        Ok(Err(failure)) => (failure.status, failure.message),
        Err(payload) => (
            LucentStatus::LUCENT_PANIC,
            format!("internal error: {}", panic_text(payload.as_ref())),
        ),
    };
    set_last_error(message);
    status
}

/// [`guard`] for the `*_free` functions, which return nothing: a panic (of a destructor) is
/// caught and recorded as the thread's message.
pub(crate) fn guard_void(body: impl FnOnce()) {
    guard(|| {
        body();
        Ok(())
    });
}

/// The message of the last failed `lucent_*` call on the calling thread, or "" if that call
/// succeeded. Never NULL. The string belongs to the library and stays valid until the next
/// `lucent_*` call on the same thread (this function excepted); copy it to keep it.
#[unsafe(no_mangle)]
pub extern "C" fn lucent_last_error_message() -> *const c_char {
    // Cannot panic: no `with` (which panics during thread teardown), no `borrow` (which
    // panics while the slot is being written; nothing here re-enters).
    LAST_ERROR
        .try_with(|slot| slot.try_borrow().map(|message| message.as_ptr()).ok())
        .ok()
        .flatten()
        .unwrap_or(c"".as_ptr())
}

#[cfg(test)]
mod tests {
    use std::ffi::CStr;

    use super::*;

    fn last_message() -> String {
        // SAFETY: `lucent_last_error_message` returns a NUL-terminated string owned by this
        // thread's slot, alive until the next call on this thread; it is copied at once.
        unsafe { CStr::from_ptr(lucent_last_error_message()) }
            .to_str()
            .unwrap()
            .to_owned()
    }

    #[test]
    fn a_panic_in_the_body_becomes_a_status_and_a_message() {
        let status = guard(|| panic!("deep inside"));
        assert_eq!(status, LucentStatus::LUCENT_PANIC);
        assert_eq!(last_message(), "internal error: deep inside");
        let status = guard(|| panic!("formatted {}", 42));
        assert_eq!(status, LucentStatus::LUCENT_PANIC);
        assert_eq!(last_message(), "internal error: formatted 42");
        let status = guard(|| std::panic::panic_any(7_u8));
        assert_eq!(status, LucentStatus::LUCENT_PANIC);
        assert_eq!(last_message(), "internal error: a panic without a message");
    }

    #[test]
    fn a_panic_deep_in_a_callee_is_caught_too() {
        fn index_out_of_bounds(v: &[f32], i: usize) -> f32 {
            v[i]
        }
        let status = guard(|| {
            let x = index_out_of_bounds(&[1.0], 3);
            Err(Failure::invalid(format!("unreachable {x}")))
        });
        assert_eq!(status, LucentStatus::LUCENT_PANIC);
        assert!(
            last_message().contains("index out of bounds"),
            "{}",
            last_message()
        );
    }

    #[test]
    fn success_clears_the_message_and_failures_set_it() {
        assert_eq!(
            guard(|| Err(Failure::null("samples"))),
            LucentStatus::LUCENT_NULL_POINTER
        );
        assert_eq!(last_message(), "samples is NULL");
        assert_eq!(guard(|| Ok(())), LucentStatus::LUCENT_OK);
        assert_eq!(last_message(), "");
    }

    #[test]
    fn messages_are_per_thread() {
        guard(|| Err(Failure::invalid("main thread")));
        std::thread::spawn(|| {
            assert_eq!(last_message(), "");
            guard(|| Err(Failure::invalid("other thread")));
            assert_eq!(last_message(), "other thread");
        })
        .join()
        .unwrap();
        assert_eq!(last_message(), "main thread");
    }

    #[test]
    fn a_panic_in_a_destructor_is_caught_and_reported() {
        struct Exploding;
        impl Drop for Exploding {
            fn drop(&mut self) {
                panic!("drop");
            }
        }
        let doomed = Exploding;
        guard_void(move || drop(doomed));
        assert_eq!(last_message(), "internal error: drop");
        guard_void(|| ());
        assert_eq!(last_message(), "");
    }

    #[test]
    fn interior_nul_bytes_do_not_truncate_or_drop_the_message() {
        guard(|| Err(Failure::invalid("name \"a\0b\" is unknown")));
        assert_eq!(last_message(), "name \"a\u{fffd}b\" is unknown");
    }
}
