//! Property: any bytes read as a baked sample set (`lucent render --samples-from`) yield a
//! valid set no larger than the file allows, or an error naming the file; never a panic.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    lucent_tests::fuzz_props::samples_ply_read_never_panics(data);
});
