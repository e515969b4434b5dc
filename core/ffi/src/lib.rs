//! # lucent-ffi
//!
//! The C interface of lucent-core, for renderers and engines written in C or C++: material
//! profiles and irradiance caches behind opaque handles, and subsurface-scattering queries on
//! arrays of plain structs. The header is `include/lucent.h` (generated from this crate by
//! cbindgen; a test keeps it current); `README.md` beside this crate shows how to build, link
//! and call it.
//!
//! Conventions of every `lucent_*` function:
//!
//! - it returns a [`LucentStatus`]; on anything but `LUCENT_OK`,
//!   [`lucent_last_error_message`] says why (per thread, valid until the next call);
//! - NULL for any pointer argument is an error (`LUCENT_NULL_POINTER`), never a crash, and
//!   NULL is a no-op for the `*_free` functions;
//! - outputs are written only on success (creators set `*out` to NULL on failure);
//! - no panic crosses the boundary: one is caught and reported as `LUCENT_PANIC`.
//!
//! The handles are immutable once made, so any number of threads may query one cache with
//! one plan at once.
//!
//! Every call into lucent-core goes through one module (`bridge`), so that the C interface
//! stays put while the core's Rust API moves.
#![warn(missing_docs)]

mod bridge;
mod cache;
mod profile;
mod ptr;
mod query;
mod status;
mod types;

pub use cache::{
    LucentCache, lucent_cache_build, lucent_cache_free, lucent_cache_len,
    lucent_cache_smoothing_radius,
};
pub use profile::{
    LucentProfile, lucent_profile_free, lucent_profile_from_coefficients,
    lucent_profile_from_preset, lucent_profile_local_integral, lucent_profile_mean_free_path,
    lucent_profile_radiance, lucent_profile_total_reflectance,
};
pub use query::{
    LucentIrradianceFn, LucentQuery, lucent_method_from_name, lucent_query_free,
    lucent_query_local_integral, lucent_query_new, lucent_query_options_init, lucent_query_point,
    lucent_query_point_refined, lucent_query_points, lucent_query_smoothing_radius,
};
pub use status::{LucentStatus, lucent_last_error_message};
pub use types::{
    LucentCoefficients, LucentExitance, LucentMethod, LucentQueryOptions, LucentSample,
    LucentShadingPoint,
};
