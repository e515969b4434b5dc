//! The core's integration tests, one module per subject, in a single test binary: each extra
//! binary in `tests/` would be linked separately, and linking dominates `cargo test`'s time.
//! Add new subjects as modules here, not as new files directly under `core/tests/`.
//!
//! Run one module with a filter, e.g. `cargo test -p lucent-core --test it stress::`.

mod common;

mod cache_build;
mod edge_refined;
mod plane_bias;
mod profiles;
mod queries;
mod stress;
mod uniform_plane;
