//! The properties behind the fuzz targets in `fuzz/fuzz_targets/`.
//!
//! Each function takes the fuzzer's bytes and panics when its property fails. The fuzz targets
//! are thin wrappers around them, and `tests/tests/it/fuzz_corpus.rs` replays every file of
//! `fuzz/corpus/<target>/` through the same function, so that the committed seeds and
//! minimised crashers run in `cargo test --workspace` without a fuzzer. See `docs/fuzzing.md`.
//!
//! | target | property |
//! |---|---|
//! | [`cache_query_matches_exhaustive`] | cache build/validate and every query method against the exhaustive sum |
//! | [`table_lookup_finite`] | local-integral lookups finite, bounded by Rd_total, monotone in ℓ |
//! | [`scene_parse_never_panics`] | arbitrary bytes → a scene or an error, a scene sound |
//! | [`obj_load_never_panics`] | arbitrary bytes → a mesh or an error, a mesh valid |
//! | [`ply_load_never_panics`] | arbitrary bytes → a PLY mesh or an error, a mesh valid |
//! | [`gltf_load_never_panics`] | arbitrary bytes → a glTF mesh or an error, a mesh valid, its material groups tiling it |
//! | [`raster_triangle_in_bounds`] | arbitrary clip-space triangles → coverage and depth as an oracle says |
//! | [`shadow_rays_match_brute_force`] | BVH any-hit (plain, hinted) and closest hit against a brute-force loop |
//! | [`convexity_is_sound`] | a mesh `cannot_shadow_itself` accepts is flat or convex by an exhaustive check |
//! | [`texture_load_never_panics`] | arbitrary bytes as each texture format → a texture within the caps or an error |
//! | [`exr_tile_read_never_panics`] | arbitrary bytes as an OpenEXR tile (`lucent merge`'s reader) → a tile whose images fit its window, or an error |
//! | [`samples_ply_read_never_panics`] | arbitrary bytes as a baked sample set (`--samples-from`) → a valid set or an error |
//! | [`crops_match_the_whole_render`] | a crop of a render (any size, aa, method, interpolation, threads) is that region of the whole render, bit for bit |

mod cache;
mod convexity;
mod crops;
mod exr_tile;
pub mod input;
mod meshes;
mod parse;
mod raster;
mod samples_ply;
mod shadow;
mod table;
mod texture;

pub use cache::{MAX_FUZZ_SAMPLES, cache_query_matches_exhaustive};
pub use convexity::convexity_is_sound;
pub use crops::crops_match_the_whole_render;
pub use exr_tile::{MAX_EXR_SAMPLES, exr_tile_read_never_panics};
pub use meshes::{gltf_load_never_panics, ply_load_never_panics};
pub use parse::{SMALL_MESH_OBJ, fuzz_origin, obj_load_never_panics, scene_parse_never_panics};
pub use raster::raster_triangle_in_bounds;
pub use samples_ply::samples_ply_read_never_panics;
pub use shadow::shadow_rays_match_brute_force;
pub use table::table_lookup_finite;
pub use texture::{FUZZ_LIMITS, texture_load_never_panics};

/// A property: takes the fuzzer's bytes, panics when the property fails.
pub type Property = fn(&[u8]);

/// Every target by name, with its property: what the replay test and tools iterate over.
pub const TARGETS: [(&str, Property); 13] = [
    (
        "cache_query_matches_exhaustive",
        cache_query_matches_exhaustive,
    ),
    ("table_lookup_finite", table_lookup_finite),
    ("scene_parse_never_panics", scene_parse_never_panics),
    ("obj_load_never_panics", obj_load_never_panics),
    ("ply_load_never_panics", ply_load_never_panics),
    ("gltf_load_never_panics", gltf_load_never_panics),
    ("raster_triangle_in_bounds", raster_triangle_in_bounds),
    (
        "shadow_rays_match_brute_force",
        shadow_rays_match_brute_force,
    ),
    ("convexity_is_sound", convexity_is_sound),
    ("texture_load_never_panics", texture_load_never_panics),
    ("exr_tile_read_never_panics", exr_tile_read_never_panics),
    (
        "samples_ply_read_never_panics",
        samples_ply_read_never_panics,
    ),
    ("crops_match_the_whole_render", crops_match_the_whole_render),
];

/// The error of a reader given fuzz bytes as the file `name`: it starts with `prefix`, which
/// names the file, and says what is wrong after it (more than a dozen characters beyond the
/// name). Panics otherwise.
fn assert_error_names_the_file(message: &str, prefix: &str, name: &str) {
    assert!(
        message.starts_with(prefix) && message.len() > name.len() + 12,
        "unhelpful error: {message}"
    );
}
