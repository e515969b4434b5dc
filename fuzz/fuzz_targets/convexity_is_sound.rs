//! Property: `cannot_shadow_itself` never panics, and a mesh it accepts is flat or convex by an
//! exhaustive f64 vertex-against-face-plane test (twice its relative tolerance); a closed
//! built-in shape with a face removed is accepted only if flat.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    lucent_tests::fuzz_props::convexity_is_sound(data);
});
