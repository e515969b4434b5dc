//! Textures: missing, of no supported format, undecodable, absurd sizes in the header,
//! truncated or corrupt PNG, JPEG and OpenEXR textures that render, and textures on a mesh
//! without UVs.

use super::harness::{
    CONSTANT, SPHERE, Sandbox, png_chunk, png_header_only, render, scene, valid_png,
};

const KD_TEXTURE: &str = "kd = { texture = \"kd.png\" }\nmean_free_path = 0.05";
const ELL_TEXTURE: &str =
    "kd = 0.7\nmean_free_path = { texture = \"kd.png\", min = 0.01, max = 0.1 }";

fn texture_sandbox(tag: &str, material: &str) -> Sandbox {
    let sb = Sandbox::with_scene(tag, &scene(SPHERE, material));
    valid_png(&sb, "kd.png", 4, 4);
    sb
}

#[test]
fn valid_textures_render() {
    for material in [KD_TEXTURE, ELL_TEXTURE] {
        let sb = texture_sandbox("texture-valid", material);
        sb.succeeds(&render(&[]));
    }
}

#[test]
fn missing_texture() {
    for (material, key) in [
        (KD_TEXTURE, "material.m.kd.texture"),
        (ELL_TEXTURE, "material.m.mean_free_path.texture"),
    ] {
        let sb = texture_sandbox("texture-missing", material);
        std::fs::remove_file(sb.path("kd.png")).unwrap();
        sb.fails(
            &render(&[]),
            1,
            &[
                "scene.toml:",
                key,
                "cannot read texture kd.png",
                "No such file",
            ],
        );
    }
}

/// Files of no supported format, that do not decode, or whose header claims an empty or absurd
/// size: rejected before anything is allocated, naming the texture. The content decides the
/// decoder, whatever the name.
#[test]
fn textures_of_the_wrong_format_or_size() {
    let jpeg: Vec<u8> = [
        &[0xff, 0xd8, 0xff, 0xe0, 0x00, 0x10][..],
        b"JFIF\0",
        &[1, 1, 0, 0, 1, 0, 1, 0, 0, 0xff, 0xd9],
    ]
    .concat();
    let exr = [0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0, 0, 0, 0, 0];
    let cases: Vec<(&str, Vec<u8>, &[&str])> = vec![
        (
            "a broken JPEG named .png",
            jpeg,
            &["JPEG decoding failed: "],
        ),
        (
            "a broken OpenEXR named .png",
            exr.to_vec(),
            &["OpenEXR decoding failed: "],
        ),
        (
            "text",
            b"not an image\n".to_vec(),
            &["not a PNG, JPEG, BMP, Radiance HDR or OpenEXR file (it starts with 6e 6f 74"],
        ),
        ("empty", Vec::new(), &["texture kd.png: empty file"]),
        ("0 × 0", png_header_only(0, 0), &["empty image (0 × 0)"]),
        ("0 × 16", png_header_only(0, 16), &["empty image (0 × 16)"]),
        (
            "100000 × 100000",
            png_header_only(100_000, 100_000),
            &["100000 × 100000", "larger than 16384 texels per side"],
        ),
        (
            "16384 × 16384",
            png_header_only(16_384, 16_384),
            &["16384 × 16384", "more than 67108864 texels"],
        ),
        (
            "2³¹ − 1 wide",
            png_header_only(0x7fff_ffff, 1),
            &["2147483647 × 1", "larger than 16384 texels per side"],
        ),
        (
            "4 × 4 without pixel data",
            png_header_only(4, 4),
            &["PNG decoding failed: ", "IDAT"],
        ),
    ];
    for material in [KD_TEXTURE, ELL_TEXTURE] {
        let sb = texture_sandbox("texture-format", material);
        for (what, bytes, needles) in &cases {
            sb.write("kd.png", bytes);
            let mut all = vec!["scene.toml:", "texture kd.png"];
            all.extend_from_slice(needles);
            let message = sb.fails(&render(&[]), 1, &all);
            assert!(!message.contains("internal"), "{what}: {message}");
        }
        // A directory named like the texture.
        std::fs::remove_file(sb.path("kd.png")).unwrap();
        std::fs::create_dir(sb.path("kd.png")).unwrap();
        sb.fails(&render(&[]), 1, &["cannot read texture kd.png"]);
    }
}

/// JPEG, TGA and OpenEXR textures (the shipped scenes' files and a hand-made TGA) render as
/// colour and as data, whatever their names say.
#[test]
fn jpeg_tga_and_exr_textures_render() {
    let jpeg = include_bytes!("../../../../scenes/textures/kd-checker.jpg").to_vec();
    let exr = include_bytes!("../../../../scenes/textures/mfp-disc.exr").to_vec();
    // 2 × 1 uncompressed true-colour TGA: B, G, R per pixel.
    let mut tga = vec![0u8, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 1, 0, 24, 0];
    tga.extend_from_slice(&[40, 80, 160, 200, 100, 50]);
    for (file, bytes) in [
        ("kd.jpg", &jpeg),
        ("kd.png", &jpeg),
        ("kd.tga", &tga),
        ("kd.exr", &exr),
    ] {
        for material in [KD_TEXTURE, ELL_TEXTURE] {
            let material = material.replace("kd.png", file);
            let sb = Sandbox::with_scene("texture-formats", &scene(SPHERE, &material));
            sb.write(file, bytes);
            sb.succeeds(&render(&[]));
        }
    }
    // The same TGA bytes without the extension that identifies them: refused, naming both.
    let sb = texture_sandbox("texture-formats", KD_TEXTURE);
    sb.write("kd.png", &tga);
    sb.fails(
        &render(&[]),
        1,
        &[
            "texture kd.png: not a PNG, JPEG, BMP, Radiance HDR or OpenEXR file",
            "nor named .tga",
        ],
    );
}

/// A valid PNG cut at every byte: each prefix is an error naming the texture (the decoder
/// needs the image data, and with it the file is complete but for the end chunk).
#[test]
fn truncated_png() {
    let sb = texture_sandbox("texture-truncated", KD_TEXTURE);
    let png = sb.read("kd.png");
    let iend = png.len() - 12;
    for cut in 0..png.len() {
        sb.write("kd.png", &png[..cut]);
        if cut < iend {
            sb.fails(&render(&[]), 1, &["scene.toml:", "texture kd.png"]);
        } else {
            sb.succeeds_or_fails(&render(&[]), "texture kd.png");
        }
    }
}

/// Corrupt image data with valid chunk CRCs (the zlib stream damaged) and a damaged CRC:
/// errors naming the texture.
#[test]
fn corrupt_png() {
    let sb = texture_sandbox("texture-corrupt", KD_TEXTURE);
    let png = sb.read("kd.png");
    // Locate the IDAT chunk: length, type, data, CRC.
    let at = png.windows(4).position(|w| w == b"IDAT").unwrap() - 4;
    let len = u32::from_be_bytes(png[at..at + 4].try_into().unwrap()) as usize;
    let data = &png[at + 8..at + 8 + len];
    let rest = &png[at + 12 + len..];
    for flip in [0, 1, len / 2, len - 1] {
        let mut bad = data.to_vec();
        bad[flip] ^= 0x5a;
        let rebuilt = [&png[..at], &png_chunk(b"IDAT", &bad), rest].concat();
        sb.write("kd.png", &rebuilt);
        sb.succeeds_or_fails(&render(&[]), "texture kd.png");
    }
    // A broken zlib header is always fatal.
    let mut bad = data.to_vec();
    bad[0] = 0xff;
    bad[1] = 0xff;
    sb.write(
        "kd.png",
        &[&png[..at], &png_chunk(b"IDAT", &bad), rest].concat(),
    );
    sb.fails(&render(&[]), 1, &["texture kd.png"]);
    // A damaged CRC in the header chunk.
    let mut bad = png.clone();
    bad[29] ^= 0xff;
    sb.write("kd.png", &bad);
    sb.fails(&render(&[]), 1, &["texture kd.png"]);
}

/// A textured material on an OBJ without texture coordinates.
#[test]
fn texture_on_mesh_without_uvs() {
    let sb = Sandbox::with_scene("texture-no-uv", &scene("obj = \"mesh.obj\"", KD_TEXTURE));
    valid_png(&sb, "kd.png", 4, 4);
    sb.write("mesh.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    sb.fails(
        &render(&[]),
        1,
        &["object[0].obj", "no texture coordinates", "kd"],
    );
    // The same mesh with a constant material renders.
    sb.write(
        "scene.toml",
        scene("obj = \"mesh.obj\"", CONSTANT).as_bytes(),
    );
    sb.succeeds(&render(&[]));
}

/// A square facing the camera whose UVs all lie in UDIM tile 1002 (u in [1.05, 1.95]).
const QUAD_IN_TILE_1002: &[u8] = b"v -0.5 0 -0.5\nv 0.5 0 -0.5\nv 0.5 0 0.5\nv -0.5 0 0.5\n\
vt 1.05 0.05\nvt 1.95 0.05\nvt 1.95 0.95\nvt 1.05 0.95\nvn 0 -1 0\n\
f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n";

/// A UDIM set: each point reads the tile its UVs fall in. On a square whose UVs lie in tile
/// 1002 the set renders the bytes of tile 1002's file alone (a single texture repeats, so the
/// same texels and weights), and not those of tile 1001's. The two tiles hold the same codes
/// in reverse order, so that K_d spans the same range either way.
#[test]
fn udim_sets_read_each_points_tile() {
    let with_kd = |file: &str| scene("obj = \"quad.obj\"", &KD_TEXTURE.replace("kd.png", file));
    let sb = Sandbox::with_scene("texture-udim", &with_kd("kd.<UDIM>.png"));
    sb.write("quad.obj", QUAD_IN_TILE_1002);
    let codes: Vec<u8> = (0..16u8)
        .flat_map(|i| [40 + 12 * i, 200 - 9 * i, 90 + (i % 4) * 30])
        .collect();
    let reversed: Vec<u8> = codes.chunks_exact(3).rev().flatten().copied().collect();
    let png = |name: &str, rgb: &[u8]| {
        lucent_raster::output::png::write_png_rgb8(&sb.path(name), 4, 4, rgb).expect("write a tile")
    };
    png("kd.1002.png", &codes);
    png("kd.1001.png", &reversed);
    // Not tiles of the set: no four-digit number, or not a tile's.
    png("kd.1000.png", &reversed);
    png("kd.102.png", &reversed);
    let image = |file: &str| {
        sb.write("scene.toml", with_kd(file).as_bytes());
        sb.succeeds(&render(&[]));
        sb.read("out.png")
    };
    let set = image("kd.<UDIM>.png");
    assert_eq!(set, image("kd.1002.png"), "the set against its tile 1002");
    assert_ne!(set, image("kd.1001.png"), "the set against its tile 1001");
}

/// A UDIM set without a tile, with the token in a folder's name, or as an environment map
/// (one latitude-longitude image) is refused, naming it.
#[test]
fn udim_sets_that_cannot_be_used() {
    let udim = KD_TEXTURE.replace("kd.png", "kd.<UDIM>.png");
    let sb = Sandbox::with_scene("texture-udim-bad", &scene(SPHERE, &udim));
    valid_png(&sb, "kd.png", 4, 4);
    valid_png(&sb, "kd.1000.png", 4, 4);
    sb.fails(
        &render(&[]),
        1,
        &[
            "material.m.kd.texture",
            "no file matches the UDIM set",
            "kd.<UDIM>.png (tiles 1001 to 1100)",
        ],
    );
    let in_folder = KD_TEXTURE.replace("kd.png", "t<UDIM>/kd.png");
    sb.write("scene.toml", scene(SPHERE, &in_folder).as_bytes());
    sb.fails(&render(&[]), 1, &["<UDIM> must be in the file name"]);
    valid_png(&sb, "sky.1001.png", 4, 2);
    let sky = format!(
        "{}\n[[light]]\ntype = \"environment\"\nmap = \"sky.<UDIM>.png\"\n",
        scene(SPHERE, CONSTANT)
    );
    sb.write("scene.toml", sky.as_bytes());
    sb.fails(
        &render(&[]),
        1,
        &["map", "a UDIM set is not a latitude-longitude map"],
    );
}
