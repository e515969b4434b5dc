//! Property: a crop of a render is, pixel for pixel and bit for bit, the same region of the
//! whole render, whatever the image size, antialiasing, method, exitance interpolation (its
//! step and tolerance), thread count and crop. This is what lets a farm render tiles and
//! `lucent merge` them into the single render's bytes. `tests/tests/it/tiles.rs` checks it
//! for 13 fixed tiles of two fixed images; this target searches the settings around them.
//!
//! The scenes are the repository's shadowed sphere (a shadow edge and a horizon, so that
//! the second shading pass and the interpolation's alikeness test both act near crop
//! borders) and its texture-mapped slab (whose material the interpolation never blends),
//! each with irradiance samples baked once (1 500 and 4 000) and shared by every input,
//! as `lucent bake` and `--samples-from` share them between tiles.
//!
//! Input layout (bytes past the end read as 0):
//!
//! | byte | meaning |
//! |---|---|
//! | 0 | bit 0: the scene (sphere, textured slab); bits 1–2: the method ([`Method::ALL`] but exhaustive) |
//! | 1, 2 | width and height, 1 + byte % 40 |
//! | 3 | antialiasing, 1 + byte % 3 |
//! | 4 | interpolation step, 1 + byte % [`MAX_INTERPOLATION_STEP`] |
//! | 5 | interpolation tolerance, byte / 32 (0 to 8) |
//! | 6 | vertical field of view, 6° + byte / 8 (up to about 38°) |
//! | 7–10 | the crop: x0, y0 within the image, then its width and height (at least one pixel) |
//! | 11 | bit 0: the whole render on one thread and the crop on two, or the other way round |

use std::sync::OnceLock;

use lucent_core::Method;
use lucent_raster::output::Region;
use lucent_raster::render::{ObjectSamples, PixelValue, Render, RenderOptions, bake, render};
use lucent_raster::scene::{MAX_INTERPOLATION_STEP, SampleDensity, Scene, parse_scene};

use super::input::Input;
use super::parse::fuzz_origin;

/// The scenes, by the input's first bit.
const SCENES: [&str; 2] = [
    include_str!("../../../scenes/sphere-shadow.toml"),
    include_str!("../../../scenes/textured-mfp.toml"),
];

/// Samples baked per scene: enough for images of a few dozen pixels, few enough that every
/// render's cache build stays quick.
const SAMPLES: [u32; 2] = [1500, 4000];

/// The largest image side.
const MAX_SIDE: u32 = 40;

/// Scene `index` with its samples, parsed and baked on first use.
fn baked(index: usize) -> &'static (Scene, Vec<ObjectSamples>) {
    static BAKED: [OnceLock<(Scene, Vec<ObjectSamples>)>; 2] = [OnceLock::new(), OnceLock::new()];
    BAKED[index].get_or_init(|| {
        // A coarser sphere (48 segments, not 128): every render builds its BVH.
        let full = SCENES[index];
        assert!(
            index != 0 || full.contains("segments = 128"),
            "the sphere scene no longer says `segments = 128`; update the coarsening"
        );
        let text = full.replace("segments = 128", "segments = 48");
        let mut scene = parse_scene(&text, &fuzz_origin())
            .unwrap_or_else(|e| panic!("scene {index} does not parse: {e}"));
        scene.render.samples = SampleDensity::Count(SAMPLES[index]).into();
        let samples = bake(&scene, false).unwrap_or_else(|e| panic!("scene {index}: {e}"));
        (scene, samples)
    })
}

/// The property of the fuzz target `crops_match_the_whole_render` (see the module docs).
/// Panics when a crop's pixels differ from the whole render's, or when either render fails.
pub fn crops_match_the_whole_render(data: &[u8]) {
    let mut input = Input::new(data);
    let first = input.u8();
    let (base, samples) = baked(usize::from(first & 1));
    let methods = [
        Method::Hierarchical,
        Method::LocalGlobal,
        Method::EdgeAware,
        Method::EdgeRefined,
    ];
    let mut scene = base.clone();
    scene.render.method = methods[usize::from((first >> 1) & 3)];
    scene.camera.width = 1 + u32::from(input.u8()) % MAX_SIDE;
    scene.camera.height = 1 + u32::from(input.u8()) % MAX_SIDE;
    scene.render.aa = 1 + u32::from(input.u8()) % 3;
    scene.render.interpolation = 1 + u32::from(input.u8()) % MAX_INTERPOLATION_STEP;
    scene.render.interpolation_tolerance = f32::from(input.u8()) / 32.0;
    scene.camera.vfov_degrees = 6.0 + f32::from(input.u8()) / 8.0;
    let (width, height) = (scene.camera.width, scene.camera.height);
    let x0 = u32::from(input.u8()) % width;
    let y0 = u32::from(input.u8()) % height;
    let x1 = x0 + 1 + u32::from(input.u8()) % (width - x0);
    let y1 = y0 + 1 + u32::from(input.u8()) % (height - y0);
    let crop = Region { x0, y0, x1, y1 };
    let threads = if input.u8() & 1 == 0 { [1, 2] } else { [2, 1] };

    let run = |threads: usize, crop: Option<Region>| -> Render {
        let mut scene = scene.clone();
        scene.render.threads = Some(threads);
        let options = RenderOptions {
            baked: Some(samples),
            crop,
            ..RenderOptions::default()
        };
        render(&scene, &options).unwrap_or_else(|e| panic!("{crop:?}: the render failed: {e}"))
    };
    let whole = run(threads[0], None);
    let cropped = run(threads[1], Some(crop));
    assert_eq!(cropped.region, crop);
    let expected = crop.cut(&Region::full(width, height), &whole.pixels);
    assert_eq!(cropped.pixels.len(), expected.len(), "crop {crop}");
    for (i, (got, want)) in cropped.pixels.iter().zip(&expected).enumerate() {
        let (x, y) = (x0 + i as u32 % crop.width(), y0 + i as u32 / crop.width());
        assert!(
            bits(got) == bits(want),
            "{width}×{height}, aa {}, {:?}, interpolation {} (tolerance {}), crop {crop}: \
             pixel ({x}, {y}) is {got:?} in the crop and {want:?} in the whole render",
            scene.render.aa,
            scene.render.method,
            scene.render.interpolation,
            scene.render.interpolation_tolerance,
        );
    }
}

/// Every value of a pixel as bits, so that −0 and +0 differ and NaN equals itself.
fn bits(p: &PixelValue) -> [u32; 17] {
    let mut out = [0; 17];
    let values = [p.color, p.exitance, p.local, p.global, p.irradiance]
        .into_iter()
        .flat_map(|v| v.to_array())
        .chain([p.depth, p.coverage]);
    for (slot, v) in out.iter_mut().zip(values) {
        *slot = v.to_bits();
    }
    out
}
