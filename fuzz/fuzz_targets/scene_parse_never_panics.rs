//! Property: any bytes given to the scene parser yield a sound scene or an error, never a panic.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    lucent_tests::fuzz_props::scene_parse_never_panics(data);
});
