//! Bad input to the `lucent` binary: malformed and truncated TOML,
//! OBJ, PNG and PLY files; missing files; textures of the wrong format or size; resolutions
//! of 0 and 100000²; NaN in any number; bad flags; unwritable outputs.
//!
//! Every case runs the real binary (`CARGO_BIN_EXE_lucent`, built once by Cargo for this test
//! target) in a fresh directory whose output files already exist with known contents, and
//! asserts: exit code 1 (2 for usage errors), an `error:` message on stderr naming the
//! problem (file, line, key or flag, value), no panic, and the directory byte-for-byte as it
//! was — nothing written, nothing overwritten, no temporary file left. `docs/errors.md`
//! tabulates the cases and their messages, each row naming the test here that backs it.
//!
//! Run with `cargo test -p lucent-raster --test it bad_input::`.

mod harness;

mod flags;
#[cfg(unix)]
mod gltf_mesh;
mod memory;
mod obj;
mod outputs;
mod ply;
#[cfg(unix)]
mod ply_mesh;
mod scene;
mod texture;
mod tiles;
