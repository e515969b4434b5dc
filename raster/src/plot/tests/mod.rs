//! Tests of the [`plot`](super) module, one file per module.

mod axis;
mod canvas;
mod chart;
mod demo;
mod sheet;
mod xml;

use super::*;

#[test]
fn messages_name_the_problem() {
    let size = PlotError::Size {
        width: 0,
        height: 20,
    };
    assert!(size.to_string().contains("0x20"), "{size}");
    assert!(size.to_string().contains("16384"), "{size}");
    let len = check_rgb_len(2, 3, &[0; 17]).unwrap_err();
    assert_eq!(
        len.to_string(),
        "an 8-bit RGB image of 2x3 pixels needs 18 bytes, got 17"
    );
    assert!(check_rgb_len(2, 3, &[0; 18]).is_ok());
    let crop = PlotError::EmptyCrop {
        x0: 50,
        y0: 1,
        w: 4,
        h: 4,
        width: 40,
        height: 30,
    };
    assert!(crop.to_string().contains("(50, 1)"), "{crop}");
    assert!(crop.to_string().contains("40x30"), "{crop}");
}
