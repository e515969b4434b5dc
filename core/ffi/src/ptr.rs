//! Raw pointers from C to Rust references and back: the only dereferences in the crate.
//!
//! Each helper checks what can be checked (NULL, alignment, a length that fits in memory, UTF-8)
//! and returns a [`Failure`] naming the argument; what cannot be checked (that a non-null
//! pointer points to live memory of the right type and length, not aliased by an output) is
//! the caller's contract, stated in each entry point's `# Safety` section.

use std::ffi::{CStr, c_char};
use std::mem::MaybeUninit;

use crate::status::Failure;

fn check_aligned<T>(pointer: *const T, name: &str) -> Result<(), Failure> {
    if pointer.is_aligned() {
        Ok(())
    } else {
        Err(Failure::invalid(format!(
            "{name} is not aligned to {} bytes",
            align_of::<T>()
        )))
    }
}

/// `&T` from `pointer`.
///
/// # Safety
///
/// A non-null, aligned `pointer` must point to an initialised `T` that nothing writes to
/// during `'a`.
pub(crate) unsafe fn reference<'a, T>(pointer: *const T, name: &str) -> Result<&'a T, Failure> {
    check_aligned(pointer, name)?;
    // SAFETY: aligned (checked), and by this function's contract live and initialised when
    // non-null; `as_ref` maps NULL to `None`.
    unsafe { pointer.as_ref() }.ok_or_else(|| Failure::null(name))
}

/// A slot for an output `T` at `pointer`, written with `MaybeUninit::write` (the memory may be
/// uninitialised, as C output arguments usually are).
///
/// # Safety
///
/// A non-null, aligned `pointer` must be valid for writing a `T`, and nothing else may access
/// that memory during `'a`.
pub(crate) unsafe fn output<'a, T>(
    pointer: *mut T,
    name: &str,
) -> Result<&'a mut MaybeUninit<T>, Failure> {
    check_aligned(pointer, name)?;
    // SAFETY: `MaybeUninit<T>` has `T`'s layout, so the cast keeps alignment (checked) and
    // size; by this function's contract the memory is writable and unaliased when non-null.
    unsafe { pointer.cast::<MaybeUninit<T>>().as_mut() }.ok_or_else(|| Failure::null(name))
}

/// Rejects a `count` of `T`s that could not be one allocation (more than `isize::MAX` bytes):
/// `slice::from_raw_parts` requires it.
fn check_count<T>(count: usize, name: &str) -> Result<(), Failure> {
    match count.checked_mul(size_of::<T>()) {
        Some(bytes) if bytes <= isize::MAX as usize => Ok(()),
        _ => Err(Failure::invalid(format!(
            "{name}: count {count} exceeds the address space"
        ))),
    }
}

/// `&[T]` of `count` elements at `pointer`; NULL is accepted when `count` is 0.
///
/// # Safety
///
/// A non-null, aligned `pointer` must point to `count` initialised `T`s in one allocation that
/// nothing writes to during `'a`.
pub(crate) unsafe fn slice<'a, T>(
    pointer: *const T,
    count: usize,
    name: &str,
) -> Result<&'a [T], Failure> {
    if count == 0 {
        return Ok(&[]);
    }
    if pointer.is_null() {
        return Err(Failure::null(name));
    }
    check_aligned(pointer, name)?;
    check_count::<T>(count, name)?;
    // SAFETY: non-null and aligned (checked), `count · size_of::<T>()` ≤ isize::MAX
    // (checked), and by this function's contract `count` initialised, unaliased elements.
    Ok(unsafe { std::slice::from_raw_parts(pointer, count) })
}

/// `count` output slots at `pointer`; NULL is accepted when `count` is 0.
///
/// # Safety
///
/// A non-null, aligned `pointer` must be valid for writing `count` `T`s in one allocation, and
/// nothing else may access that memory during `'a`.
pub(crate) unsafe fn output_slice<'a, T>(
    pointer: *mut T,
    count: usize,
    name: &str,
) -> Result<&'a mut [MaybeUninit<T>], Failure> {
    if count == 0 {
        return Ok(&mut []);
    }
    if pointer.is_null() {
        return Err(Failure::null(name));
    }
    check_aligned(pointer, name)?;
    check_count::<T>(count, name)?;
    // SAFETY: as in `slice`; `MaybeUninit<T>` has `T`'s layout and may be uninitialised.
    Ok(unsafe { std::slice::from_raw_parts_mut(pointer.cast::<MaybeUninit<T>>(), count) })
}

/// The UTF-8 string at `pointer`.
///
/// # Safety
///
/// A non-null `pointer` must point to a NUL-terminated string that nothing writes to during
/// `'a`.
pub(crate) unsafe fn utf8<'a>(pointer: *const c_char, name: &str) -> Result<&'a str, Failure> {
    if pointer.is_null() {
        return Err(Failure::null(name));
    }
    // SAFETY: non-null (checked); NUL-terminated and unchanged during 'a by this function's
    // contract.
    let bytes = unsafe { CStr::from_ptr(pointer) };
    bytes
        .to_str()
        .map_err(|_| Failure::invalid(format!("{name} is not UTF-8")))
}

/// Moves `value` to the heap and hands the C caller its address (freed by [`free`]).
pub(crate) fn into_handle<T>(value: T) -> *mut T {
    Box::into_raw(Box::new(value))
}

/// Frees a handle made by [`into_handle`]; NULL is a no-op.
///
/// # Safety
///
/// A non-null `handle` must come from [`into_handle`] for the same `T`, not be freed yet, and
/// not be used by anything afterwards.
pub(crate) unsafe fn free<T>(handle: *mut T) {
    if !handle.is_null() {
        // SAFETY: by this function's contract the pointer is a live `Box<T>` allocation that
        // nobody else owns or uses any more.
        drop(unsafe { Box::from_raw(handle) });
    }
}
