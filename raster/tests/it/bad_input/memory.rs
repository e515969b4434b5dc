//! Scenes and images larger than the memory granted: an error naming the buffer, its size and
//! what makes it smaller, never an abort. The binary runs under an address-space limit
//! (`ulimit -v`), which makes the allocator refuse what a smaller machine would.

use super::harness::{CONSTANT, Sandbox, rgb_exr, scene};

/// 1.5 GiB of address space: the binary, its threads and a small scene fit.
const LIMIT_KIB: u64 = 3 << 19;

/// 16384 × 4096 pixels need 4.3 GiB for the shaded pixels alone; the visibility buffer
/// (8 bytes per pixel at aa 1) still fits, so the refusal comes from the pixel buffer.
#[test]
#[cfg(target_os = "linux")]
fn an_image_larger_than_memory_is_an_error() {
    let text = scene("shape = \"sphere\"\nradius = 0.5\nsegments = 24", CONSTANT)
        .replace("width = 32", "width = 16384")
        .replace("height = 32", "height = 4096")
        .replace("aa = 2", "aa = 1");
    let sb = Sandbox::with_scene("memory-image", &text).with_address_space(LIMIT_KIB);
    sb.fails(
        &["scene.toml"],
        1,
        &[
            "out of memory: could not allocate ",
            "GiB for the shaded pixels (lower the resolution or the antialiasing",
        ],
    );
}

/// Four spheres of 1024 segments have 4.2 M triangles: each fits when it is built, but what
/// their triangles need together up to the placed samples (320 bytes each, 1.25 GiB) does
/// not, so the render stops before flattening them.
#[test]
#[cfg(target_os = "linux")]
fn a_scene_larger_than_memory_is_an_error() {
    let sphere = "shape = \"sphere\"\nradius = 0.5\nsegments = 1024\n";
    let objects = format!("{sphere}material = \"m\"\n\n[[object]]\n").repeat(3) + sphere;
    let text = scene(&objects, CONSTANT);
    let sb = Sandbox::with_scene("memory-mesh", &text).with_address_space(LIMIT_KIB / 2);
    let stderr = sb.fails(
        &["scene.toml"],
        1,
        &[
            "out of memory: could not allocate 1.2 GiB for the scene's triangles (use fewer \
             triangles",
        ],
    );
    assert!(!stderr.contains("object["), "{stderr}");
}

/// A sphere of 4096 segments (16.8 M triangles) is refused before its mesh is built: the
/// generation itself would otherwise abort the process under this limit (0.5 GiB).
#[test]
#[cfg(target_os = "linux")]
fn a_shape_larger_than_memory_is_refused_before_it_is_built() {
    let text = scene(
        "shape = \"sphere\"\nradius = 0.5\nsegments = 4096",
        CONSTANT,
    );
    let sb = Sandbox::with_scene("memory-shape", &text).with_address_space(LIMIT_KIB / 3);
    sb.fails(
        &["scene.toml"],
        1,
        &[
            "object[0].segments: out of memory: could not allocate 5.0 GiB for the scene's \
             triangles (use fewer triangles",
        ],
    );
}

/// More sub-samples than the visibility buffer addresses (2²⁸): refused before anything is
/// allocated, naming both ways to lower it.
#[test]
fn too_many_sub_samples_name_the_antialiasing() {
    let sb = Sandbox::new("memory-aa");
    sb.fails(
        &[
            "scene.toml",
            "--width",
            "16384",
            "--height",
            "4096",
            "--aa",
            "3",
        ],
        1,
        &[
            "visibility buffer of 16384×4096 pixels with aa = 3 exceeds",
            "lower the resolution or the antialiasing: 'aa' in [render], or --aa; or render \
             the image in tiles, --crop, and merge them",
        ],
    );
}

/// A render that fits but whose outputs do not: 2048 × 4096 pixels with every EXR layer ask
/// for 124 bytes per pixel (992 MiB) on top of the render's own buffers; nothing is written.
#[test]
#[cfg(target_os = "linux")]
fn outputs_larger_than_memory_are_an_error() {
    let text = scene("shape = \"sphere\"\nradius = 0.5\nsegments = 24", CONSTANT)
        .replace("width = 32", "width = 2048")
        .replace("height = 32", "height = 4096")
        // The objects a few hundred pixels across: the render stays quick.
        .replace("fov = 35.0", "fov = 170.0")
        .replace("aa = 2", "aa = 1")
        .replace(
            "layers = [\"exitance\"]",
            "layers = [\"exitance\", \"local\", \"global\", \"irradiance\", \"depth\"]",
        );
    let sb = Sandbox::with_scene("memory-outputs", &text).with_address_space(LIMIT_KIB);
    sb.fails(
        &["scene.toml"],
        1,
        &[
            "out of memory: could not allocate 992.0 MiB for the output images (lower the \
             resolution, or write fewer EXR layers",
        ],
    );
}

/// An 8 × 8 tile of a 16384 × 4096 image, rendered.
fn small_tile_of_a_huge_image() -> Vec<u8> {
    let render = Sandbox::new("memory-tile-render");
    render.succeeds(&[
        "scene.toml",
        "--width",
        "16384",
        "--height",
        "4096",
        "--aa",
        "1",
        "--crop",
        "0,0,8,8",
        "--exr",
        "tile.exr",
    ]);
    render.read("tile.exr")
}

/// A tile that claims a whole image of 16384 × 4096 pixels, merged under 200 MiB of address
/// space: the coverage check needs no buffer of the image's size, so the missing tiles are
/// named instead of the process aborting on a per-pixel map.
#[test]
#[cfg(target_os = "linux")]
fn a_tile_of_a_huge_image_is_checked_without_its_memory() {
    let merge = Sandbox::new("memory-tile-merge").with_address_space(200 << 10);
    merge.write("tile.exr", &small_tile_of_a_huge_image());
    merge.fails(
        &["merge", "tile.exr", "-o", "out.png"],
        1,
        &["the tiles leave 67108800 of the 16384×4096 pixels uncovered (the first at (8, 0)"],
    );
}

/// An EXR whose header promises 8192 × 4096 pixels of seven channels (its data window
/// widened, its pixel data still an 8 × 8 tile's): the reader asks for what decoding it
/// would take (1.8 GiB) before the decoder allocates it, and names the file.
#[test]
#[cfg(target_os = "linux")]
fn an_exr_larger_than_memory_is_refused_before_it_is_decoded() {
    let mut exr = small_tile_of_a_huge_image();
    let key = b"dataWindow\0box2i\0";
    let at = exr
        .windows(key.len())
        .position(|w| w == key)
        .expect("the tile has a data window")
        + key.len()
        + 4;
    for (i, v) in [0i32, 0, 8191, 4095].into_iter().enumerate() {
        exr[at + 4 * i..at + 4 * i + 4].copy_from_slice(&v.to_le_bytes());
    }
    let sb = Sandbox::new("memory-exr").with_address_space(LIMIT_KIB / 2);
    sb.write("big.exr", &exr);
    sb.fails(
        &["merge", "big.exr", "-o", "out.png"],
        1,
        &["big.exr: out of memory: could not allocate 1.8 GiB for the image's pixels"],
    );
}

/// A 64 × 64 OpenEXR of one uncompressed tile whose header then declares tiles of
/// 64 × 16 449 600 pixels, and whose one chunk claims 1.06 GB: what the `exr` decoder would
/// zero-fill before finding the file short (a fuzzed texture's shape, 49.6 KB).
fn exr_with_a_tile_larger_than_its_image() -> Vec<u8> {
    use exr::prelude::{Blocks, Compression, Encoding, FlatSamples, LineOrder, Vec2};
    const SIDE: usize = 64;
    let encoding = Encoding {
        compression: Compression::Uncompressed,
        blocks: Blocks::Tiles(Vec2(SIDE, SIDE)),
        line_order: LineOrder::Increasing,
    };
    let mut exr = rgb_exr(SIDE, FlatSamples::F32(vec![0.5; SIDE * SIDE]), encoding);
    let tiles = exr
        .windows(15)
        .position(|w| w == b"tiles\0tiledesc\0")
        .expect("the file is tiled");
    // Then the attribute's size (u32), the tile's width and height (u32 each).
    let height = tiles + 15 + 4 + 4;
    exr[height..height + 4].copy_from_slice(&16_449_600u32.to_le_bytes());
    // The one chunk, last: tile x, y, level x, y (i32 each), its byte count, its pixels.
    let data = SIDE * SIDE * 3 * 4;
    let count = exr.len() - data - 4;
    assert_eq!(exr[count..count + 4], (data as i32).to_le_bytes());
    exr[count..count + 4].copy_from_slice(&1_060_000_000i32.to_le_bytes());
    exr
}

/// An EXR whose tiles are far larger than its image is refused from its header by `merge`
/// and `compare` (under 0.5 GiB of address space, where the decoder's gigabyte would abort).
#[test]
#[cfg(target_os = "linux")]
fn an_exr_tile_larger_than_its_image_is_refused_before_it_is_decoded() {
    let sb = Sandbox::new("memory-exr-tile").with_address_space(LIMIT_KIB / 3);
    sb.write("tiles.exr", &exr_with_a_tile_larger_than_its_image());
    let message = "tiles.exr: OpenEXR part of 64 × 64 pixels declares tiles of 64 × 16449600 \
                   pixels (12633292800 bytes each, more than the 67108864 bytes lucent allows a \
                   block of this part)";
    sb.fails(&["merge", "tiles.exr", "-o", "out.png"], 1, &[message]);
    sb.fails(&["compare", "tiles.exr", "tiles.exr"], 1, &[message]);
}

/// An OBJ larger than memory is refused with the size of what it needs: under 0.75 GiB of
/// address space, its 1 GiB of text; under 1.2 GiB, which holds 512 MiB of text, what reading
/// its statements may need (twice the text, asked for before the reading starts).
#[test]
#[cfg(all(target_os = "linux", target_pointer_width = "64"))]
fn an_obj_larger_than_memory_is_refused_before_it_is_read() {
    let text = scene("obj = \"mesh.obj\"", CONSTANT);
    let small = Sandbox::with_scene("memory-obj-text", &text).with_address_space(LIMIT_KIB / 2);
    super::obj::write_padded_octahedron(&small, (1u64 << 30) + (1 << 20));
    small.fails(
        &["scene.toml"],
        1,
        &[
            "object[0].obj",
            "cannot read mesh mesh.obj: out of memory: could not allocate 1.0 GiB for the \
             file's contents (use a smaller file, or free memory)",
        ],
    );
    let larger =
        Sandbox::with_scene("memory-obj-statements", &text).with_address_space(LIMIT_KIB * 4 / 5);
    super::obj::write_padded_octahedron(&larger, 1 << 29);
    larger.fails(
        &["scene.toml"],
        1,
        &[
            "object[0].obj",
            "mesh.obj: out of memory: could not allocate 1.0 GiB for the OBJ file's vertices \
             and faces (use a coarser mesh, or a binary format (PLY, glTF), or free memory)",
        ],
    );
}
