//! Chart axes: the visible range of the data, and the ticks and their labels.
//!
//! An [`Axis`] covers the range of the drawable data plus 5 % on each side. A range of a
//! single value (or of values equal to 12 digits) is widened by 10 % of the value, or ±1
//! around zero; a logarithmic range is made at least one decade wide. Arithmetic is arranged
//! so that data anywhere in the finite `f64` range gives a finite, non-empty range.
//!
//! Ticks: on a linear axis about five at "nice" steps (1, 2 or 5 times a power of ten); on a
//! logarithmic axis one per decade (every n-th decade when there are many), with 2× and 5×
//! ticks added when the range spans less than three decades, and unlabelled minor ticks
//! (2× to 9×) when there are at most a dozen decades. Labels are short: on logarithmic axes
//! `0.01`, `0.1`, `1`, `10`, `1000` from 0.01 to 1000 and `1e-3`, `2e4` beyond; on linear
//! axes decimals with as many places as the step needs, or `2.5e-5`-style numbers for very
//! small steps or large values.

/// The visible range of one axis, in axis units: data values on a linear axis, their
/// base-10 logarithms on a logarithmic one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Axis {
    /// Whether the axis is logarithmic.
    pub log: bool,
    /// The axis value at the start (left or bottom) of the plot area.
    pub min: f64,
    /// The axis value at the end (right or top) of the plot area; greater than `min`.
    pub max: f64,
}

impl Axis {
    /// The range shown for data from `lo` to `hi` (finite, `lo ≤ hi`, positive on a
    /// logarithmic axis): padded by 5 % each side, widened when it is (nearly) a single value.
    pub(super) fn fit(lo: f64, hi: f64, log: bool) -> Axis {
        if log {
            let (lo, hi) = (lo.log10(), hi.log10());
            let span = hi - lo;
            let (min, max) = if span < 1.0 {
                let centre = 0.5 * (lo + hi);
                (centre - 0.5, centre + 0.5)
            } else {
                (lo - 0.05 * span, hi + 0.05 * span)
            };
            return Axis { log, min, max };
        }
        // Halves keep the arithmetic finite for data near ±f64::MAX.
        let half_span = 0.5 * hi - 0.5 * lo;
        let magnitude = lo.abs().max(hi.abs());
        let (min, max) = if half_span <= magnitude * 1e-12 {
            let centre = 0.5 * lo + 0.5 * hi;
            let widen = if centre == 0.0 {
                1.0
            } else {
                0.1 * centre.abs()
            };
            (centre - widen, centre + widen)
        } else {
            (lo - 0.1 * half_span, hi + 0.1 * half_span)
        };
        Axis {
            log,
            min: min.max(f64::MIN),
            max: max.min(f64::MAX),
        }
    }

    /// The axis value of the data value `v`, or `None` when `v` cannot be shown (non-finite,
    /// or not positive on a logarithmic axis).
    pub fn to_axis(&self, v: f64) -> Option<f64> {
        if !v.is_finite() || (self.log && !(v > 0.0)) {
            return None;
        }
        Some(if self.log { v.log10() } else { v })
    }

    /// Where the data value `v` lies along the axis: 0 at `min`, 1 at `max` (outside [0, 1]
    /// beyond the range); `None` when `v` cannot be shown.
    pub fn fraction(&self, v: f64) -> Option<f64> {
        Some(self.unit(self.to_axis(v)?))
    }

    /// Where the axis value `a` lies: 0 at `min`, 1 at `max` (halves keep the arithmetic
    /// finite for ranges near ±f64::MAX).
    pub(super) fn unit(&self, a: f64) -> f64 {
        (0.5 * a - 0.5 * self.min) / (0.5 * self.max - 0.5 * self.min)
    }

    /// The labelled ticks inside the range, as (axis value, label), in increasing order.
    pub fn ticks(&self) -> Vec<(f64, String)> {
        if self.log {
            self.log_ticks()
        } else {
            self.linear_ticks()
        }
    }

    fn linear_ticks(&self) -> Vec<(f64, String)> {
        let (step, exponent) = nice_step(0.4 * (0.5 * self.max - 0.5 * self.min));
        let magnitude = self.min.abs().max(self.max.abs());
        let first = (self.min / step).ceil();
        let mut ticks = Vec::new();
        let mut k = first;
        while k * step <= self.max && ticks.len() < 50 {
            let v = k * step;
            let label = if v.abs() < 1e-6 * step {
                "0".to_string()
            } else if (-4..=5).contains(&exponent) && magnitude < 1e6 {
                format!("{v:.*}", (-exponent).max(0) as usize)
            } else {
                let digits = (v.abs().log10().floor() as i32 - exponent).clamp(0, 15);
                format!("{v:.*e}", digits as usize)
            };
            ticks.push((v, label));
            k += 1.0;
        }
        ticks
    }

    fn log_ticks(&self) -> Vec<(f64, String)> {
        let (first, last) = (self.min.ceil() as i64, self.max.floor() as i64);
        let decades = last - first + 1;
        let mut ticks = Vec::new();
        if decades >= 3 {
            let step = (nice_step(decades as f64 / 6.0).0 as i64).max(1);
            let mut k = first.div_euclid(step) * step;
            while k <= last {
                if k >= first {
                    ticks.push((k as f64, power_label(1, k)));
                }
                k += step;
            }
        } else {
            for k in first - 1..=last {
                for m in [1, 2, 5] {
                    let a = k as f64 + f64::from(m).log10();
                    if a >= self.min && a <= self.max {
                        ticks.push((a, power_label(m, k)));
                    }
                }
            }
        }
        ticks
    }

    /// The unlabelled minor ticks of a logarithmic axis (2× to 9× in every decade) when its
    /// decades are labelled one by one; none otherwise.
    pub(super) fn minor_ticks(&self) -> Vec<f64> {
        let (first, last) = (self.min.floor() as i64, self.max.ceil() as i64);
        if !self.log || last - first > 12 {
            return Vec::new();
        }
        let labelled = self.ticks();
        (first..last)
            .flat_map(|k| (2..10).map(move |m| k as f64 + f64::from(m).log10()))
            .filter(|a| *a >= self.min && *a <= self.max)
            .filter(|a| !labelled.iter().any(|(t, _)| (t - a).abs() < 1e-9))
            .collect()
    }
}

/// The "nice" step nearest to `raw` (positive and finite, else 1 is used): 1, 2 or 5 times
/// a power of ten, returned with that power's exponent.
pub(super) fn nice_step(raw: f64) -> (f64, i32) {
    let raw = if raw >= f64::MIN_POSITIVE && raw.is_finite() {
        raw
    } else {
        1.0
    };
    let mut exponent = raw.log10().floor() as i32;
    let norm = raw / 10f64.powi(exponent);
    let nice = if norm < 1.5 {
        1.0
    } else if norm < 3.0 {
        2.0
    } else if norm < 7.0 {
        5.0
    } else {
        exponent += 1;
        1.0
    };
    (nice * 10f64.powi(exponent), exponent)
}

/// The label of `m · 10^k`: plain decimals from 0.01 to 1000, `me-k` / `mek` beyond.
pub(super) fn power_label(m: u32, k: i64) -> String {
    match k {
        0..=3 => (u64::from(m) * 10u64.pow(k as u32)).to_string(),
        -2..=-1 => format!("{:.*}", (-k) as usize, f64::from(m) * 10f64.powi(k as i32)),
        _ => format!("{m}e{k}"),
    }
}
