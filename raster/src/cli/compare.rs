//! `lucent compare`: error statistics between a test image and a reference, over the whole
//! image, the translucent pixels and the shadow-edge band, plus seed noise.
//!
//! The regions come from the reference's layers (see [`crate::output::regions`]): the
//! translucent pixels from `exitance`, the band from `irradiance`. A PNG reference, or an EXR
//! without those layers, gives the whole-image statistics only (and says so).

use std::path::Path;

use super::CompareArgs;
use super::commands::check_outputs;
use crate::output::image::{LAYER_EXITANCE, LAYER_IRRADIANCE};
use crate::output::{
    ErrorMetric, ErrorStats, Frame, HeatmapOptions, HeatmapScale, LayerData, RgbImage,
    compare as compare_images, default_band_radius, error_heatmap, read_exr_framed, read_png,
    seed_noise, shadow_edge_band, translucent_mask,
};

/// An image and, for EXR files, the layers the regions are found from.
struct Loaded {
    image: RgbImage,
    exitance: Option<Vec<glam::Vec3>>,
    irradiance: Option<Vec<glam::Vec3>>,
    /// An EXR's display and data windows: two files must cover the same region.
    frame: Option<Frame>,
}

fn read(path: &Path) -> Result<Loaded, String> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    match ext.as_str() {
        "png" => Ok(Loaded {
            image: read_png(path).map_err(|e| e.to_string())?,
            exitance: None,
            irradiance: None,
            frame: None,
        }),
        "exr" => {
            let (exr, frame) = read_exr_framed(path).map_err(|e| e.to_string())?;
            let layer = |name: &str| {
                exr.layers.iter().find_map(|l| match &l.data {
                    LayerData::Rgb(p) if l.name == name => Some(p.clone()),
                    _ => None,
                })
            };
            Ok(Loaded {
                exitance: layer(LAYER_EXITANCE),
                irradiance: layer(LAYER_IRRADIANCE),
                image: exr.beauty,
                frame: Some(frame),
            })
        }
        _ => Err(format!(
            "{}: unknown image type (expected .exr or .png)",
            path.display()
        )),
    }
}

/// Two EXR files must hold the same pixels of the same image: tiles of one size from
/// different places (`render --crop`) compare pixels that have nothing to do with each other.
fn same_region(test: &Loaded, reference: &Loaded, args: &CompareArgs) -> Result<(), String> {
    let (Some(t), Some(r)) = (test.frame, reference.frame) else {
        return Ok(());
    };
    let describe = |f: Frame| {
        format!(
            "pixels from ({}, {}) of a {}×{} image",
            f.data_origin.0, f.data_origin.1, f.display_size.0, f.display_size.1
        )
    };
    if (t.display_origin, t.display_size, t.data_origin)
        != (r.display_origin, r.display_size, r.data_origin)
    {
        return Err(format!(
            "{} holds {}, {} holds {}: compare images of the same region",
            args.test.display(),
            describe(t),
            args.reference.display(),
            describe(r)
        ));
    }
    Ok(())
}

/// The rows printed for one region.
fn print_stats(region: &str, s: &ErrorStats) -> Result<(), String> {
    outln!(
        "{region:<18} {:>8}  {:>12.6e}  {:>12.6e}  {:>12.6e}  {:>12.6e} at ({}, {}) {}",
        s.pixels,
        s.rmse,
        s.mean_abs,
        s.mean_relative_l1,
        s.max_abs,
        s.max_abs_at.0,
        s.max_abs_at.1,
        ["R", "G", "B"][s.max_abs_channel]
    );
    Ok(())
}

/// `lucent compare`.
pub fn compare(args: &CompareArgs) -> Result<(), String> {
    if let Some(out) = &args.heatmap {
        let mut inputs = vec![args.test.as_path(), args.reference.as_path()];
        inputs.extend(args.noise_with.iter().map(|p| p.as_path()));
        check_outputs(&[out], &inputs)?;
    }
    let test = read(&args.test)?;
    let reference = read(&args.reference)?;
    same_region(&test, &reference, args)?;
    let (width, height) = reference.image.size();
    let whole = compare_images(&test.image, &reference.image, None).map_err(|e| e.to_string())?;
    outln!(
        "{:<18} {:>8}  {:>12}  {:>12}  {:>12}  {:>12}",
        "region",
        "pixels",
        "RMSE",
        "mean |error|",
        "mean rel. L1",
        "max |error|"
    );
    print_stats("all pixels", &whole)?;

    let translucent = reference
        .exitance
        .as_deref()
        .map(translucent_mask)
        .filter(|m| m.contains(&true));
    match &translucent {
        Some(mask) => {
            let s = compare_images(&test.image, &reference.image, Some(mask))
                .map_err(|e| e.to_string())?;
            print_stats("translucent", &s)?;
            match &reference.irradiance {
                Some(e) => {
                    let radius = default_band_radius(width, height);
                    let band = shadow_edge_band(e, mask, width, height, radius)
                        .map_err(|e| e.to_string())?;
                    if band.contains(&true) {
                        let s = compare_images(&test.image, &reference.image, Some(&band))
                            .map_err(|e| e.to_string())?;
                        print_stats(&format!("shadow edge ±{radius}px"), &s)?;
                    } else {
                        outln!("(no shadow edge in the reference's irradiance layer)");
                    }
                }
                None => outln!(
                    "(the reference has no '{LAYER_IRRADIANCE}' layer: no shadow-edge statistics)"
                ),
            }
        }
        None => outln!(
            "(the reference has no '{LAYER_EXITANCE}' layer with translucent pixels: whole-image statistics only)"
        ),
    }

    if !args.noise_with.is_empty() {
        let mut others = Vec::with_capacity(args.noise_with.len());
        for path in &args.noise_with {
            let image = read(path)?.image;
            // Checked here so that the message names the file (the shared check cannot).
            if image.size() != test.image.size() {
                let ((w, h), (tw, th)) = (image.size(), test.image.size());
                return Err(format!(
                    "{}: {w}×{h} pixels, but the test image is {tw}×{th}: seed noise needs renders of one size",
                    path.display()
                ));
            }
            others.push(image);
        }
        let mut renders = vec![&test.image];
        renders.extend(others.iter());
        let noise = seed_noise(&renders, translucent.as_deref()).map_err(|e| e.to_string())?;
        outln!(
            "seed noise over {} renders, {} {} pixels: RMS {:.6e}, mean relative {:.6e}",
            noise.renders,
            noise.pixels,
            if translucent.is_some() {
                "translucent"
            } else {
                "(all)"
            },
            noise.rms,
            noise.mean_relative
        );
    }

    if let Some(out) = &args.heatmap {
        let options = HeatmapOptions {
            metric: if args.relative {
                ErrorMetric::Relative
            } else {
                ErrorMetric::Absolute
            },
            scale: if args.log {
                HeatmapScale::Log { decades: 4.0 }
            } else {
                HeatmapScale::Linear
            },
            max: None,
        };
        let map = error_heatmap(&test.image, &reference.image, None, &options)
            .map_err(|e| e.to_string())?;
        map.write_png(out).map_err(|e| e.to_string())?;
        outln!(
            "heat map           {} (white = {:.3e})",
            out.display(),
            map.white
        );
    }
    Ok(())
}
