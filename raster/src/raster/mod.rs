//! Fixed-point scanline rasterisation into a supersampled visibility buffer.
