//! Property: any bytes given to the PLY loader yield a valid mesh or an error, never a panic.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    lucent_tests::fuzz_props::ply_load_never_panics(data);
});
