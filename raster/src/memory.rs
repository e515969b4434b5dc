//! Fallible allocation of the buffers that grow with the image or with the scene's triangles.
//!
//! A buffer the size of the image (the visibility buffer, the shaded pixels, the output
//! layers) or of the scene's triangles (the shadow rays' BVHs) can be gigabytes at the largest
//! sizes a scene allows. Where the allocator refuses one (an address-space limit
//! such as `ulimit -v`, or a request larger than the machine's memory and swap), the render
//! stops with an [`OutOfMemory`] error naming the buffer and its size, instead of aborting the
//! process.

use std::fmt;

use rayon::prelude::*;

/// A kind of buffer, as an [`OutOfMemory`] error names it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Buffer {
    /// What the buffer holds, e.g. "the shaded pixels".
    pub what: &'static str,
    /// What makes it smaller, e.g. "lower the resolution or the antialiasing".
    pub remedy: &'static str,
}

/// Buffers of one element per pixel.
pub const PIXELS: Buffer = Buffer {
    what: "the shaded pixels",
    remedy: "lower the resolution or the antialiasing",
};

/// The depth and triangle id of every sub-sample.
pub const VISIBILITY: Buffer = Buffer {
    what: "the visibility buffer",
    remedy: "lower the resolution or the antialiasing, or render the image in tiles (--crop)",
};

/// Buffers of one or a few elements per triangle of the scene.
pub const TRIANGLES: Buffer = Buffer {
    what: "the scene's triangles",
    remedy: "use fewer triangles: coarser meshes or fewer segments",
};

/// The images a render writes (PNG, EXR and its layers).
pub const OUTPUTS: Buffer = Buffer {
    what: "the output images",
    remedy: "lower the resolution, or write fewer EXR layers",
};

/// The whole image `lucent merge` assembles from tiles.
pub const MERGED: Buffer = Buffer {
    what: "the merged image",
    remedy: "merge on a machine with more memory, or write fewer EXR layers when rendering the tiles",
};

/// The pixels of an image file being read (`lucent merge`, `lucent compare`).
pub const READ_IMAGE: Buffer = Buffer {
    what: "the image's pixels",
    remedy: "read it on a machine with more memory",
};

/// A file read whole (a mesh, a texture, baked samples).
pub const FILE: Buffer = Buffer {
    what: "the file's contents",
    remedy: "use a smaller file",
};

/// What reading an OBJ file's statements makes (see [`crate::scene::obj`]).
pub const OBJ_STATEMENTS: Buffer = Buffer {
    what: "the OBJ file's vertices and faces",
    remedy: "use a coarser mesh, or a binary format (PLY, glTF)",
};

/// The vertex and face lists a PLY file declares.
pub const PLY_LISTS: Buffer = Buffer {
    what: "the PLY file's vertices and faces",
    remedy: "use a coarser mesh",
};

/// A glTF file's parsed JSON, with the buffers embedded in it as data URIs.
pub const GLTF_JSON: Buffer = Buffer {
    what: "the glTF file's JSON and the buffers embedded in it",
    remedy: "keep large buffers in a .bin file or use a .glb",
};

/// The vertices and triangles a glTF file's accessors hold.
pub const GLTF_ACCESSORS: Buffer = Buffer {
    what: "the glTF file's vertices and triangles",
    remedy: "use a coarser mesh",
};

/// Peak bytes per triangle from the flattened scene to the placed samples: the shadow BVHs,
/// the sampler's tiles and the samples' cells. Measured (peak resident set of a sphere of
/// 1024 segments, 1 M triangles, and of a 7.8 M-triangle OBJ sphere): 239 and 211–218
/// bytes, the mesh itself included.
pub const PEAK_BYTES_PER_TRIANGLE: u64 = 320;

/// The allocator refused a buffer.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct OutOfMemory {
    /// Bytes requested.
    pub bytes: u64,
    /// The buffer refused.
    pub buffer: Buffer,
}

impl fmt::Display for OutOfMemory {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "out of memory: could not allocate {} for {} ({}, or free memory)",
            human_bytes(self.bytes),
            self.buffer.what,
            self.buffer.remedy
        )
    }
}

impl std::error::Error for OutOfMemory {}

/// `len` copies of `value`, or [`OutOfMemory`] if the allocator refuses the buffer.
pub fn filled<T: Clone>(len: usize, value: T, buffer: Buffer) -> Result<Vec<T>, OutOfMemory> {
    let mut v = with_capacity(len, buffer)?;
    v.resize(len, value);
    Ok(v)
}

/// An empty vector with room for `len` elements, or [`OutOfMemory`].
pub fn with_capacity<T>(len: usize, buffer: Buffer) -> Result<Vec<T>, OutOfMemory> {
    let mut v = Vec::new();
    v.try_reserve_exact(len).map_err(|_| OutOfMemory {
        bytes: (len as u64).saturating_mul(size_of::<T>() as u64),
        buffer,
    })?;
    Ok(v)
}

/// The items of `iter` (at most `len` of them), collected into a buffer allocated fallibly.
pub fn collect<T>(
    len: usize,
    iter: impl IntoIterator<Item = T>,
    buffer: Buffer,
) -> Result<Vec<T>, OutOfMemory> {
    let mut v = with_capacity(len, buffer)?;
    v.extend(iter);
    Ok(v)
}

/// [`collect`] on every thread: the items of `iter`, in order, in a buffer allocated fallibly.
pub fn par_collect<T: Send>(
    iter: impl IndexedParallelIterator<Item = T>,
    buffer: Buffer,
) -> Result<Vec<T>, OutOfMemory> {
    let mut v = with_capacity(iter.len(), buffer)?;
    // The capacity is there already: rayon writes the items in place.
    v.par_extend(iter);
    Ok(v)
}

/// Whether the allocator grants `bytes` at once, asked and given back before work that will
/// need about that much in many smaller buffers. It reserves address space without touching
/// it, so it is cheap; it catches an address-space limit (`ulimit -v`) or a request beyond
/// the machine's memory and swap, not memory that other processes take meanwhile.
pub fn probe(bytes: u64, buffer: Buffer) -> Result<(), OutOfMemory> {
    let len = usize::try_from(bytes).map_err(|_| OutOfMemory { bytes, buffer })?;
    let v = with_capacity::<u8>(len, buffer)?;
    // Without this the optimiser may drop the allocation and its failure with it.
    std::hint::black_box(&v);
    Ok(())
}

/// `bytes` in the largest binary unit that keeps it at least 1, e.g. "272.0 MiB".
fn human_bytes(bytes: u64) -> String {
    const UNITS: [&str; 6] = ["KiB", "MiB", "GiB", "TiB", "PiB", "EiB"];
    if bytes < 1024 {
        return format!("{bytes} bytes");
    }
    let mut value = bytes as f64 / 1024.0;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < UNITS.len() {
        value /= 1024.0;
        unit += 1;
    }
    format!("{value:.1} {}", UNITS[unit])
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEST: Buffer = Buffer {
        what: "the test buffer",
        remedy: "ask for less",
    };

    #[test]
    fn a_refused_buffer_is_an_error_naming_it_and_its_size() {
        // 8 EiB: no allocator grants it, and nothing is touched.
        let err = filled(usize::MAX / 16, 0u64, TEST).unwrap_err();
        assert_eq!(err.buffer, TEST);
        assert_eq!(err.bytes, (usize::MAX / 16) as u64 * 8);
        assert_eq!(
            err.to_string(),
            "out of memory: could not allocate 8.0 EiB for the test buffer (ask for less, \
             or free memory)"
        );
        assert!(with_capacity::<u8>(usize::MAX, TEST).is_err());
        assert!(collect(usize::MAX / 2, [1u32], TEST).is_err());
        let refused = par_collect((0..usize::MAX / 8).into_par_iter().map(|i| i as u32), TEST);
        assert_eq!(refused.unwrap_err().bytes, (usize::MAX / 8) as u64 * 4);
        let err = probe(u64::MAX, TEST).unwrap_err();
        assert_eq!(err.bytes, u64::MAX);
        assert!(probe(1 << 63, TEST).is_err());
    }

    #[test]
    fn granted_buffers_hold_what_was_asked() {
        assert_eq!(filled(3, 7u8, TEST).unwrap(), vec![7, 7, 7]);
        assert_eq!(collect(2, [1, 2], TEST).unwrap(), vec![1, 2]);
        let squares = par_collect(
            (0..100_000u32).into_par_iter().map(|i| i as u64 * i as u64),
            TEST,
        )
        .unwrap();
        assert!(
            squares
                .iter()
                .enumerate()
                .all(|(i, &s)| s == (i * i) as u64)
        );
        assert_eq!(squares.len(), 100_000);
        assert!(with_capacity::<f32>(10, TEST).unwrap().capacity() >= 10);
        assert_eq!(probe(1 << 20, TEST), Ok(()));
    }

    #[test]
    fn sizes_are_given_in_binary_units() {
        assert_eq!(human_bytes(0), "0 bytes");
        assert_eq!(human_bytes(1023), "1023 bytes");
        assert_eq!(human_bytes(1024), "1.0 KiB");
        assert_eq!(human_bytes(285_212_672), "272.0 MiB");
        assert_eq!(human_bytes(13 << 30), "13.0 GiB");
        assert_eq!(human_bytes(5 << 40), "5.0 TiB");
        assert_eq!(human_bytes(u64::MAX), "16.0 EiB");
    }
}
