//! A `#![no_std]` consumer of lucent-core, built in CI to prove the core needs nothing from
//! `std`: it brings its own panic handler and a bump allocator over a static arena.
#![no_std]

extern crate alloc;

use alloc::vec::Vec;
use core::alloc::{GlobalAlloc, Layout};
use core::cell::UnsafeCell;
use core::panic::PanicInfo;
use core::sync::atomic::{AtomicUsize, Ordering};

use lucent_core::glam::Vec3;
use lucent_core::{
    Distance, IrradianceCache, LocalIntegralTable, Method, Profile, QuerySettings, Sample,
    ShadingPoint,
};

#[panic_handler]
fn panic(_info: &PanicInfo) -> ! {
    loop {}
}

const ARENA: usize = 1 << 22;

/// Never frees; enough for the proof's small cache.
struct Bump {
    arena: UnsafeCell<[u8; ARENA]>,
    next: AtomicUsize,
}

// SAFETY: allocation only hands out disjoint ranges, reserved with an atomic bump.
unsafe impl Sync for Bump {}

unsafe impl GlobalAlloc for Bump {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let mut start = 0;
        let reserved = self
            .next
            .fetch_update(Ordering::SeqCst, Ordering::SeqCst, |next| {
                start = next.next_multiple_of(layout.align());
                let end = start.checked_add(layout.size())?;
                (end <= ARENA).then_some(end)
            });
        match reserved {
            // SAFETY: start + size ≤ ARENA, and the range was reserved for this call alone.
            Ok(_) => unsafe { (self.arena.get() as *mut u8).add(start) },
            Err(_) => core::ptr::null_mut(),
        }
    }
    unsafe fn dealloc(&self, _ptr: *mut u8, _layout: Layout) {}
}

#[global_allocator]
static ALLOCATOR: Bump = Bump {
    arena: UnsafeCell::new([0; ARENA]),
    next: AtomicUsize::new(0),
};

/// Builds a small lit patch, queries it with every method and returns the edge-aware exitance's
/// red channel at (x, y, 0), or −1 on any error.
#[unsafe(no_mangle)]
pub extern "C" fn lucent_proof_query(x: f32, y: f32) -> f32 {
    let Ok(profile) = Profile::from_reflectance(
        Vec3::splat(0.6),
        Distance::MeanFreePath(Vec3::splat(0.5)),
        1.3,
    ) else {
        return -1.0;
    };
    let mut samples = Vec::new();
    for i in 0..32 {
        for j in 0..32 {
            let position = Vec3::new(i as f32 * 0.1 - 1.6, j as f32 * 0.1 - 1.6, 0.0);
            samples.push(Sample {
                position,
                area: 0.01,
                irradiance: Vec3::ONE,
            });
        }
    }
    let Ok(cache) = IrradianceCache::build(&samples) else {
        return -1.0;
    };
    if cache.validate().is_err() {
        return -1.0;
    }
    let alpha = cache.smoothing_radius(2.0);
    let Ok(table) = LocalIntegralTable::new(&profile, alpha, alpha / 1024.0) else {
        return -1.0;
    };
    let point = ShadingPoint {
        position: Vec3::new(x, y, 0.0),
        irradiance: Vec3::ONE,
    };
    let local = table.local_term(profile.mean_free_path());
    let mut result = -1.0;
    for method in Method::ALL {
        let settings = QuerySettings {
            method,
            ..QuerySettings::default()
        };
        match cache.query(&profile, &point, local, &settings) {
            Ok(m) => result = m.total.x,
            Err(_) => return -1.0,
        }
    }
    result
}
