//! Integration tests for lucent live in `tests/tests/it/` (one test binary); this library holds
//! their shared helpers, and the properties the fuzz targets in `fuzz/` check ([`fuzz_props`]).

pub mod fuzz_props;
