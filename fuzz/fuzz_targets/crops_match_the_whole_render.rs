//! Property: a crop of a render is that region of the whole render, bit for bit, for any
//! image size, antialiasing, method, exitance interpolation, thread count and crop.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    lucent_tests::fuzz_props::crops_match_the_whole_render(data);
});
