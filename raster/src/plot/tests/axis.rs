//! Tests of [`axis`](crate::plot::axis): ranges, tick positions and labels.

use crate::plot::axis::*;

#[test]
fn tick_labels_are_short() {
    let labels = |min, max, log| -> Vec<String> {
        Axis { log, min, max }
            .ticks()
            .into_iter()
            .map(|t| t.1)
            .collect()
    };
    assert_eq!(
        labels(-0.05, 1.05, false),
        ["0", "0.2", "0.4", "0.6", "0.8", "1.0"]
    );
    assert_eq!(labels(-130.0, 20.0, false), ["-100", "-50", "0"]);
    assert_eq!(
        labels(0.0, 4e-5, false),
        ["0", "1e-5", "2e-5", "3e-5", "4e-5"]
    );
    assert_eq!(
        labels(2.4e7, 3.6e7, false),
        [
            "2.4e7", "2.6e7", "2.8e7", "3.0e7", "3.2e7", "3.4e7", "3.6e7"
        ]
    );
    assert_eq!(labels(-0.4, 0.6, true), ["0.5", "1", "2"]);
    assert_eq!(labels(-5.5, 4.2, true), ["1e-4", "0.01", "1", "100", "1e4"]);
    assert_eq!(labels(-301.0, 301.0, true).len(), 7);
    assert_eq!(power_label(2, -3), "2e-3");
    assert_eq!(power_label(5, -2), "0.05");
    assert_eq!(power_label(2, 3), "2000");
    assert_eq!(power_label(1, 4), "1e4");
}

#[test]
fn ranges_are_padded_and_never_empty() {
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs().max(1.0);
    let a = Axis::fit(0.0, 10.0, false);
    assert!(close(a.min, -0.5) && close(a.max, 10.5), "{a:?}");
    // A single value is widened by 10 % of it, or by 1 around zero.
    let a = Axis::fit(-20.0, -20.0, false);
    assert!(close(a.min, -22.0) && close(a.max, -18.0), "{a:?}");
    let a = Axis::fit(0.0, 0.0, false);
    assert_eq!((a.min, a.max), (-1.0, 1.0));
    // Logarithmic: padding in decades; less than one decade is widened to one.
    let a = Axis::fit(1e-3, 10.0, true);
    assert!(close(a.min, -3.2) && close(a.max, 1.2), "{a:?}");
    let a = Axis::fit(2.0, 2.0, true);
    assert!(
        close(a.max - a.min, 1.0) && close(a.min + 0.5, 2f64.log10()),
        "{a:?}"
    );
    // The extremes of f64 still give finite ranges.
    for (lo, hi, log) in [
        (-f64::MAX, f64::MAX, false),
        (f64::MAX, f64::MAX, false),
        (f64::MIN_POSITIVE / 1e10, f64::MAX, true),
    ] {
        let a = Axis::fit(lo, hi, log);
        assert!(
            a.min.is_finite() && a.max.is_finite() && a.max > a.min,
            "{a:?}"
        );
        assert!((0.0..=1.0).contains(&a.fraction(lo).unwrap()), "{a:?}");
        assert!((0.0..=1.0).contains(&a.fraction(hi).unwrap()), "{a:?}");
    }
}

#[test]
fn fractions_map_the_range_to_unit_length() {
    let a = Axis {
        log: true,
        min: -2.0,
        max: 2.0,
    };
    assert_eq!(a.fraction(0.01), Some(0.0));
    assert_eq!(a.fraction(1.0), Some(0.5));
    assert_eq!(a.fraction(100.0), Some(1.0));
    assert_eq!(a.fraction(1e4), Some(1.5));
    assert_eq!(a.fraction(0.0), None);
    assert_eq!(a.fraction(-1.0), None);
    assert_eq!(a.fraction(f64::NAN), None);
    assert_eq!(a.to_axis(1000.0), Some(3.0));
    let a = Axis {
        log: false,
        min: -1.0,
        max: 3.0,
    };
    assert_eq!(a.fraction(0.0), Some(0.25));
    assert_eq!(a.fraction(-1.0), Some(0.0));
    assert_eq!(a.fraction(f64::INFINITY), None);
}

#[test]
fn steps_are_one_two_or_five() {
    let cases = [
        (0.22, 0.2, -1),
        (1.0, 1.0, 0),
        (1.6, 2.0, 0),
        (3.5, 5.0, 0),
        (7.5, 10.0, 1),
        (4e-7, 5e-7, -7),
        (123.0, 100.0, 2),
        (9e-5, 1e-4, -4),
    ];
    for (raw, nice, exponent) in cases {
        let (step, e) = nice_step(raw);
        assert!((step - nice).abs() <= 1e-12 * nice, "{raw}: {step}");
        assert_eq!(e, exponent, "{raw}");
    }
    // Degenerate input falls back to 1.
    for raw in [0.0, -3.0, f64::NAN, f64::INFINITY, 1e-310] {
        assert_eq!(nice_step(raw), (1.0, 0));
    }
}

#[test]
fn ticks_lie_inside_the_range_in_order() {
    for (min, max, log) in [
        (-0.05, 1.05, false),
        (3.3, 3.4, false),
        (-1e300, 1e300, false),
        (-3.2, 1.2, true),
        (0.1, 0.9, true),
        (-320.0, 300.0, true),
    ] {
        let a = Axis { log, min, max };
        let ticks = a.ticks();
        assert!((2..=12).contains(&ticks.len()), "{a:?}: {ticks:?}");
        assert!(ticks.windows(2).all(|t| t[0].0 < t[1].0), "{ticks:?}");
        assert!(ticks.iter().all(|(v, _)| *v >= min && *v <= max));
        let mut labels: Vec<&String> = ticks.iter().map(|t| &t.1).collect();
        labels.dedup();
        assert_eq!(labels.len(), ticks.len(), "repeated labels: {ticks:?}");
    }
}

#[test]
fn minor_ticks_fill_the_decades() {
    let a = Axis {
        log: true,
        min: -0.02,
        max: 2.05,
    };
    let minor = a.minor_ticks();
    // 2..9 in each of the two whole decades; 0.9 (−0.046) and 200 (2.3) are outside.
    assert_eq!(minor.len(), 16);
    assert!((minor[0] - 2f64.log10()).abs() < 1e-12);
    assert!(minor.iter().all(|m| m.fract().abs() > 1e-9));
    assert!(
        Axis {
            log: false,
            min: 0.0,
            max: 1.0
        }
        .minor_ticks()
        .is_empty()
    );
    assert!(
        Axis {
            log: true,
            min: -100.0,
            max: 100.0
        }
        .minor_ticks()
        .is_empty()
    );
}
