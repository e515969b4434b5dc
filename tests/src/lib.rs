//! Integration tests for lucent live in `tests/tests/`; this library holds their shared helpers.
