//! Property: any bytes read as an OpenEXR tile (`lucent merge`'s reader) yield a tile whose
//! images fill its data window inside its display window, or an error naming the file; never a
//! panic or unbounded memory.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    lucent_tests::fuzz_props::exr_tile_read_never_panics(data);
});
