//! Bad input never panics: deterministic mutations of valid scene text, OBJ files and PNGs
//! either load or fail with a located error.
//!
//! The `_long` variants are ignored by default (about two minutes in a debug build):
//! `cargo test -p lucent-raster --lib scene::tests::robustness -- --ignored`.

use std::path::Path;

use super::*;
use crate::texture::{Texture, TextureEncoding};

/// A valid scene touching every table, textures and an OBJ file.
fn rich_scene() -> String {
    append(
        "[output]\nexr = 'a.exr'\nlayers = ['depth']\n[render]\nspacing = 0.05\n\
         [material.t]\ntype = 'translucent'\nkd = { texture = 'ramp.png' }\n\
         diffuse_mean_free_path = { texture = 'ramp.png', min = 0.1, max = 2 }\neta = 1.3\n\
         [[object]]\nobj = 'quad.obj'\nmaterial = 't'\n\
         [[light]]\ntype = 'spot'\nposition = [0, 0, 1]\ndirection = [0, 0, -1]\n\
         inner_angle = 10\nouter_angle = 20\nintensity = 3\n",
    )
}

/// Xorshift64: a fixed sequence of pseudo-random numbers.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// Replaces, deletes or inserts one byte from `alphabet` at a random place.
    fn mutate(&mut self, bytes: &mut Vec<u8>, alphabet: &[u8]) {
        let r = self.next();
        let at = (r % bytes.len().max(1) as u64) as usize;
        let with = alphabet[((r >> 32) % alphabet.len() as u64) as usize];
        match (r >> 40) % 3 {
            0 if at < bytes.len() => bytes[at] = with,
            1 if at < bytes.len() => {
                bytes.remove(at);
            }
            _ => bytes.insert(at.min(bytes.len()), with),
        }
    }
}

fn scene_mutations(count: usize) {
    let text = rich_scene();
    assert!(load(&text).is_ok(), "{:?}", load(&text).err());
    let alphabet = b"0-.[]{}=\"'\n#ae,9 1e+nifx_";
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    for _ in 0..count {
        let mut m = text.clone().into_bytes();
        for _ in 0..1 + rng.next() % 3 {
            rng.mutate(&mut m, alphabet);
        }
        if let Ok(t) = std::str::from_utf8(&m)
            && let Err(e) = load(t)
        {
            assert!(e.to_string().starts_with("t.toml"), "{e}");
        }
    }
}

fn obj_and_png_mutations(objs: usize, pngs: usize) {
    let bunny = include_bytes!("../../../../assets/bunny.obj");
    let alphabet = b"0123456789-/ \nvfnt.e";
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for i in 0..objs {
        let mut m = if i % 2 == 0 {
            bunny.to_vec()
        } else {
            QUAD_UV.as_bytes().to_vec()
        };
        for _ in 0..1 + rng.next() % 4 {
            rng.mutate(&mut m, alphabet);
        }
        let _ = obj::parse_obj(&m);
    }
    let png = png_ramp();
    for _ in 0..pngs {
        let mut m = png.clone();
        let r = rng.next();
        let at = (r % m.len() as u64) as usize;
        m[at] = (r >> 32) as u8;
        let _ = Texture::from_bytes(&m, Path::new("x.png"), TextureEncoding::Srgb);
    }
}

#[test]
fn scene_parse_never_panics() {
    scene_mutations(2_000);
}

#[test]
fn obj_and_png_decoding_never_panic() {
    obj_and_png_mutations(20, 2_000);
}

#[test]
#[ignore = "about a minute in debug; run with --ignored"]
fn scene_parse_never_panics_long() {
    scene_mutations(200_000);
}

#[test]
#[ignore = "about a minute in debug; run with --ignored"]
fn obj_and_png_decoding_never_panic_long() {
    obj_and_png_mutations(3_000, 50_000);
}
