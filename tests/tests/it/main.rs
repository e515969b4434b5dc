//! lucent's end-to-end tests, one module per subject, in a single test binary: each extra
//! binary in `tests/` would link the whole renderer again, and linking dominates
//! `cargo test`'s time. Add new subjects as modules here, not as new files directly under
//! `tests/tests/`.
//!
//! Run one module with a filter, e.g. `cargo test -p lucent-tests --test it golden::`.

mod edge_reference;
mod fuzz_corpus;
mod golden;
mod interpolation;
mod meshes;
mod render_physics;
mod shading_aa;
mod tiles;
