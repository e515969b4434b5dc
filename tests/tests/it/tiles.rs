//! Tiles: a render cut into regions of uneven size (`RenderOptions::crop`, what `lucent render
//! --crop` does), written as EXR tiles and merged (`lucent merge`), gives the same bytes as a
//! single render: the PNG, and the EXR with its alpha and every layer. At `aa = 1` and with the
//! second shading pass (`aa = 3`), whose contrast test reads each pixel's neighbours, so that
//! the shadow edge crossing the tile borders tests the margin the tiles render; and with
//! exitance interpolation, whose grid crosses the tile borders. The fuzz target
//! `crops_match_the_whole_render` searches other sizes, settings and crops.

use std::path::{Path, PathBuf};

use lucent_raster::output::{
    ExrTile, Placement, Region, merge_tiles, read_exr_tile, write_exr, write_exr_tile, write_png,
};
use lucent_raster::render::{ObjectSamples, RenderOptions, bake, render};
use lucent_raster::scene::{ExrLayers, SampleDensity, Scene, load_scene};

/// Regions of uneven size that cover a 40 × 30 image exactly once, some of them narrow strips
/// along and across the edges that the second pass refines (the horizon in row 15, the
/// sphere's shadow around columns 20–28), so that the pixels it refines have neighbours in
/// other tiles.
const TILES: [&str; 13] = [
    "0,0,13,7",
    "13,0,40,7",
    "0,7,14,15",
    "0,15,14,16",
    "0,16,14,30",
    "14,7,15,30",
    "15,7,17,30",
    "17,7,20,30",
    "20,7,29,15",
    "20,15,29,16",
    "20,16,29,22",
    "29,7,40,22",
    "20,22,40,30",
];

fn scene(aa: u32, interpolation: u32) -> Scene {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut scene = load_scene(&root.join("scenes/sphere-shadow.toml")).unwrap();
    scene.camera.width = 40;
    scene.camera.height = 30;
    scene.render.samples = SampleDensity::Count(1500).into();
    scene.render.aa = aa;
    scene.render.interpolation = interpolation;
    if interpolation > 1 {
        // The sphere fills the view (a radius of about 25 pixels), so that blocks of its
        // surface are flat enough to blend; the shadow edge still runs down the middle. The
        // wide tolerance blends across the 1500 samples' pixel-to-pixel scatter.
        scene.camera.vfov_degrees = 10.0;
        scene.render.interpolation_tolerance = 1.0;
    }
    scene.render.threads = Some(2);
    scene.render.exposure = 0.75;
    scene.output.layers = ExrLayers {
        exitance: true,
        local: true,
        global: true,
        irradiance: true,
        depth: true,
    };
    scene
}

struct Dir(PathBuf);

impl Dir {
    fn new(tag: &str) -> Dir {
        let dir = std::env::temp_dir().join(format!("lucent-tiles-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Dir(dir)
    }

    fn path(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }
}

impl Drop for Dir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn options(baked: &[ObjectSamples], crop: Option<Region>) -> RenderOptions<'_> {
    RenderOptions {
        baked: Some(baked),
        crop,
        ..RenderOptions::default()
    }
}

fn check_tiles_merge_to_the_whole_render(aa: u32, interpolation: u32) {
    let dir = Dir::new(&format!("aa{aa}-{interpolation}"));
    let scene = scene(aa, interpolation);
    let baked = bake(&scene, false).unwrap();
    let whole = render(&scene, &options(&baked, None)).unwrap();
    let layers = whole.layers(&scene.output.layers);
    write_png(&dir.path("whole.png"), &whole.image, scene.render.exposure).unwrap();
    write_exr(
        &dir.path("whole.exr"),
        &whole.image,
        Some(&whole.alpha()),
        &layers,
    )
    .unwrap();
    if interpolation > 1 {
        assert!(
            whole.stats.interpolated > 200,
            "every {interpolation} pixels: {} blended, so the tiles would not test it",
            whole.stats.interpolated
        );
    }
    if aa > 1 {
        assert!(
            whole.stats.refined_pixels > 0,
            "aa = {aa}: the second pass refined nothing, so the tiles would not test it"
        );
    }

    let full = Region::full(40, 30);
    let mut tiles: Vec<(PathBuf, ExrTile)> = Vec::new();
    for text in TILES {
        let region = Region::parse(text).unwrap();
        let tile = render(&scene, &options(&baked, Some(region))).unwrap();
        assert_eq!(tile.region, region);
        // Every pixel and layer value bit for bit the whole render's.
        assert!(
            tile.pixels == region.cut(&full, &whole.pixels),
            "aa = {aa}: tile {region} differs from the whole render"
        );
        let path = dir.path(&format!("tile-{text}.exr"));
        let placement = Placement {
            display: (40, 30),
            region,
            exposure: scene.render.exposure,
        };
        let tile_layers = tile.layers(&scene.output.layers);
        write_exr_tile(
            &path,
            &placement,
            &tile.image,
            Some(&tile.alpha()),
            &tile_layers,
        )
        .unwrap();
        let read = read_exr_tile(&path).unwrap();
        assert_eq!((read.display, read.region), ((40, 30), region));
        assert_eq!(read.exposure, Some(scene.render.exposure));
        tiles.push((path, read));
    }
    // In another order than rendered.
    tiles.reverse();
    let merged = merge_tiles(&tiles).unwrap();
    let image = &merged.image;
    assert_eq!(image.layers.len(), 5);
    assert!(image.alpha.is_some());
    write_png(
        &dir.path("merged.png"),
        &image.beauty,
        merged.exposure.unwrap(),
    )
    .unwrap();
    write_exr(
        &dir.path("merged.exr"),
        &image.beauty,
        image.alpha.as_deref(),
        &image.layers,
    )
    .unwrap();
    for name in ["png", "exr"] {
        let read = |stem: &str| std::fs::read(dir.path(&format!("{stem}.{name}"))).unwrap();
        assert!(
            read("merged") == read("whole"),
            "aa = {aa}: the merged {name} differs from the single render's"
        );
    }
}

#[test]
fn tiles_merge_to_the_whole_render_at_aa_1() {
    check_tiles_merge_to_the_whole_render(1, 1);
}

#[test]
fn tiles_merge_to_the_whole_render_with_the_second_pass() {
    check_tiles_merge_to_the_whole_render(3, 1);
}

/// The grid of every 4th pixel (the last column and row clamped to the image) crosses the tile
/// borders: each tile queries the grid pixels around it.
#[test]
fn tiles_merge_to_the_whole_render_with_interpolation() {
    check_tiles_merge_to_the_whole_render(1, 4);
}

#[test]
fn tiles_merge_to_the_whole_render_with_interpolation_and_the_second_pass() {
    check_tiles_merge_to_the_whole_render(3, 3);
}

#[test]
fn crops_outside_the_image_are_errors() {
    let scene = scene(2, 1);
    for text in ["0,0,41,30", "39,29,40,31", "40,0,41,1"] {
        let crop = Region::parse(text).unwrap();
        let e = render(
            &scene,
            &RenderOptions {
                crop: Some(crop),
                ..RenderOptions::default()
            },
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains(&format!(
                "crop: the region {text} is not inside the 40×30 image"
            )),
            "{e}"
        );
    }
}
