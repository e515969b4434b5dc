//! lucent-core: point-based subsurface scattering, `#![no_std]` + `alloc`.
#![no_std]

extern crate alloc;
