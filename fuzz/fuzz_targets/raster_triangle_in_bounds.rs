//! Property: any clip-space triangle rasterises without panic or overflow, covering only in-buffer
//! sub-samples with depths in [0, 1], exactly as the top-left rule / a margin oracle say, and the
//! depth test keeps the nearest, earliest triangle.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    lucent_tests::fuzz_props::raster_triangle_in_bounds(data);
});
