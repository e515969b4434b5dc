//! Property: the BVH builds and validates for any triangle soup, and for every ray (valid or not)
//! `occluded`, `occluded_hinted` with a carried and a fresh hint, and `intersect` agree with a
//! brute-force watertight test over the finite triangles: same answer, a hint naming a real
//! blocker, the closest hit with the lowest index among equal t.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    lucent_tests::fuzz_props::shadow_rays_match_brute_force(data);
});
