//! lucent-ffi's integration tests, one module per subject, in a single test binary. They call
//! the `extern "C"` functions directly, as a C caller would (they are plain Rust functions
//! too), through raw pointers.

mod common;

mod cache;
mod errors;
// Needs cbindgen: `cargo test -p lucent-ffi --features header-check --test it header::`.
#[cfg(feature = "header-check")]
mod header;
mod profile;
mod query;
mod refined;
