//! Property: any sample set builds into a cache that validates (or is rejected as invalid), every
//! query method is finite and non-negative, culling skips at most its tolerance, and with ε = 0 the
//! octree queries equal the exhaustive sums to float rounding.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    lucent_tests::fuzz_props::cache_query_matches_exhaustive(data);
});
