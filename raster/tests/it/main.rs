//! The renderer's integration tests, one module per subject, in a single test binary: each
//! extra binary in `tests/` would link the whole renderer again, and linking dominates
//! `cargo test`'s time. Add new subjects as modules here, not as new files directly under
//! `raster/tests/`.
//!
//! Run one module with a filter, e.g. `cargo test -p lucent-raster --test it bad_input::`.

mod bad_input;
#[cfg(feature = "harness")]
mod bench_quick;
#[cfg(feature = "harness")]
mod compare_regions;
mod stress;
