//! Image textures over mesh UVs.

use std::path::PathBuf;

use glam::{Vec2, Vec3};

/// A decoded RGB texture with linear values.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// Where it was loaded from.
    pub path: PathBuf,
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Row-major texels, top row first, linear RGB.
    pub texels: Vec<Vec3>,
}

impl Texture {
    /// Bilinear lookup with repeat wrapping. `uv = (0, 0)` is the bottom-left corner of the
    /// image (the OBJ convention), `(1, 1)` the top-right.
    pub fn sample(&self, uv: Vec2) -> Vec3 {
        let _ = uv;
        todo!("texture sampling")
    }
}
