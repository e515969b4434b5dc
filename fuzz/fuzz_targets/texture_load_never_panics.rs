//! Property: any bytes decoded as any texture format (or detected) yield a texture within the
//! size caps, with finite texels, or an error naming the file; never a panic or unbounded memory.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    lucent_tests::fuzz_props::texture_load_never_panics(data);
});
