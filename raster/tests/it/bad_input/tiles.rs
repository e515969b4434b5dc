//! `render --crop` and `merge` on bad input: the crop is checked against the image after
//! --width/--height, and merge refuses tiles that do not make one image; nothing is written.

use super::harness::{Sandbox, render};

#[test]
fn bad_crops() {
    let sb = Sandbox::new("crop");
    let cases: &[(&[&str], i32, &[&str])] = &[
        (
            &["--crop", "0,0,33,8", "--exr", "t.exr"],
            1,
            &[
                "--crop 0,0,33,8: the region 0,0,33,8 is not inside the 32×32 image",
                "the scene's size",
            ],
        ),
        (
            &["--width", "16", "--crop", "0,0,20,8", "--exr", "t.exr"],
            1,
            &["is not inside the 16×32 image", "after --width/--height"],
        ),
        (
            &["--crop", "4,0,4,8", "--exr", "t.exr"],
            2,
            &["the region is empty"],
        ),
        (
            &["--crop", "0,0,8", "--exr", "t.exr"],
            2,
            &["expected four pixel coordinates", "got 3 values"],
        ),
        (
            &["--crop", "0,0,-8,8", "--exr", "t.exr"],
            2,
            &["x1 = '-8' is not a pixel coordinate"],
        ),
        (
            &["--crop", "0,0,8,8"],
            1,
            &["name the tile's file with --exr"],
        ),
    ];
    for (extra, code, needles) in cases {
        sb.fails(&render(extra), *code, needles);
    }
}

#[test]
fn bad_merges() {
    let sb = Sandbox::new("merge");
    for (crop, name) in [
        ("0,0,32,20", "a.exr"),
        ("0,20,32,32", "b.exr"),
        ("0,16,32,32", "c.exr"),
    ] {
        sb.succeeds(&render(&["--aa", "1", "--crop", crop, "--exr", name]));
    }
    sb.succeeds(&render(&[
        "--aa",
        "1",
        "--width",
        "16",
        "--crop",
        "0,20,16,32",
        "--exr",
        "d.exr",
    ]));
    let cases: &[(&[&str], i32, &[&str])] = &[
        (
            &["merge", "a.exr", "-o", "m.png"],
            1,
            &["leave 384 of the 32×32 pixels uncovered (the first at (0, 20)"],
        ),
        (
            &["merge", "a.exr", "c.exr", "-o", "m.png"],
            1,
            &["c.exr (region 0,16,32,32) overlaps a.exr (region 0,0,32,20) in 0,16,32,20"],
        ),
        (
            &["merge", "a.exr", "d.exr", "-o", "m.png"],
            1,
            &["d.exr: its full image is 16x32, a.exr's is 32x32"],
        ),
        (
            &["merge", "a.exr", "a.exr", "-o", "m.png"],
            1,
            &["a.exr: given twice"],
        ),
        (
            &["merge", "a.exr", "b.exr"],
            1,
            &["name the merged image with -o OUT.png and/or --exr OUT.exr"],
        ),
        (
            &["merge", "a.exr", "missing.exr", "-o", "m.png"],
            1,
            &["missing.exr"],
        ),
        (
            &["merge", "a.exr", "b.exr", "-o", "nodir/m.png"],
            1,
            &["the directory 'nodir' does not exist"],
        ),
        (&["merge", "-o", "m.png"], 2, &["TILE.exr"]),
    ];
    for (args, code, needles) in cases {
        sb.fails(args, *code, needles);
    }
    // A whole image merges without an exposure attribute only when told the PNG's exposure.
    sb.succeeds(&render(&[
        "--aa",
        "1",
        "--exr",
        "whole.exr",
        "-o",
        "whole.png",
    ]));
    sb.fails(
        &["merge", "whole.exr", "-o", "m.png"],
        1,
        &["whole.exr: no lucentExposure attribute", "--exposure"],
    );
    sb.succeeds(&["merge", "whole.exr", "-o", "m.png", "--exposure", "0"]);
    assert_eq!(sb.read("m.png"), sb.read("whole.png"));
}
