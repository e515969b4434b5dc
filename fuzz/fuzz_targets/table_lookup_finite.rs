//! Property: for any K_d, η, α, ℓ_min, every local-integral lookup is finite, in [0, Rd_total],
//! exact at the nodes ℓ = α·2^k, and non-increasing in ℓ.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    lucent_tests::fuzz_props::table_lookup_finite(data);
});
