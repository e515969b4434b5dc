//! Property: any bytes given to the glTF loader yield a valid mesh whose material groups tile
//! its triangles, or an error, never a panic.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    lucent_tests::fuzz_props::gltf_load_never_panics(data);
});
