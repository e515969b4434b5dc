//! Value checks with located errors: every number read from a scene passes through here, so
//! NaN, infinities and out-of-range values are reported with their file, line and key, and the
//! value as the file writes it (`1e39`, not `1000000000000000000000000000000000000000`).

use glam::Vec3;
use toml::Spanned;

use super::error::{SceneError, SceneErrorKind, Source};
use super::format::Components;

/// Result of a check.
pub(crate) type Checked<T> = Result<T, SceneError>;

/// Validates values of one scene file.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Check<'a> {
    /// The scene text, to turn spans into lines.
    pub src: Source<'a>,
}

impl<'a> Check<'a> {
    /// An out-of-range error at `v`.
    pub fn range<T>(&self, key: &str, v: &Spanned<T>, message: impl Into<String>) -> SceneError {
        self.src
            .error(SceneErrorKind::OutOfRange, v.span(), key, message)
    }

    /// The text of `v` as the scene file has it (`1e20`, not `100000000000000000000`).
    pub fn written<T>(&self, v: &Spanned<T>) -> &'a str {
        self.src.text.get(v.span()).unwrap_or("").trim()
    }

    /// Any error at `v`.
    pub fn at<T>(
        &self,
        kind: SceneErrorKind,
        key: &str,
        v: &Spanned<T>,
        message: impl Into<String>,
    ) -> SceneError {
        self.src.error(kind, v.span(), key, message)
    }

    /// A finite number that fits an `f32`.
    pub fn num(&self, key: &str, v: &Spanned<f64>) -> Checked<f32> {
        let x = *v.get_ref();
        let y = x as f32;
        if !x.is_finite() {
            return Err(self.range(
                key,
                v,
                format!("must be a finite number (got {})", self.written(v)),
            ));
        }
        if !y.is_finite() {
            return Err(self.range(
                key,
                v,
                format!("{} is too large for single precision", self.written(v)),
            ));
        }
        Ok(y)
    }

    /// A finite number satisfying `ok`, else `requirement` ("must be > 0") is reported.
    pub fn num_where(
        &self,
        key: &str,
        v: &Spanned<f64>,
        ok: impl Fn(f32) -> bool,
        requirement: &str,
    ) -> Checked<f32> {
        let x = self.num(key, v)?;
        if ok(x) {
            Ok(x)
        } else {
            Err(self.range(key, v, format!("{requirement} (got {})", self.written(v))))
        }
    }

    /// A number > 0.
    pub fn positive(&self, key: &str, v: &Spanned<f64>) -> Checked<f32> {
        self.num_where(key, v, |x| x > 0.0, "must be greater than 0")
    }

    /// A number ≥ 0.
    pub fn non_negative(&self, key: &str, v: &Spanned<f64>) -> Checked<f32> {
        self.num_where(key, v, |x| x >= 0.0, "must be at least 0")
    }

    /// An integer in `lo..=hi`.
    pub fn int(&self, key: &str, v: &Spanned<i64>, lo: i64, hi: i64) -> Checked<i64> {
        let x = *v.get_ref();
        if (lo..=hi).contains(&x) {
            Ok(x)
        } else {
            Err(self.range(
                key,
                v,
                format!("must be in {lo}..={hi} (got {})", self.written(v)),
            ))
        }
    }

    /// A vector `[x, y, z]` of finite numbers (exactly three; a single number is not a vector).
    pub fn vec3(&self, key: &str, v: &Spanned<Components>) -> Checked<Vec3> {
        if let Components::Scalar(x) = v.get_ref() {
            return Err(self.at(
                SceneErrorKind::WrongType,
                key,
                v,
                format!("expected an array [x, y, z], got the number {x}"),
            ));
        }
        let values = self.components(key, v, 3)?;
        Ok(Vec3::new(values[0], values[1], values[2]))
    }

    /// A number or `[a, b, c]`, each finite and satisfying `ok`. A single number applies to
    /// every component.
    pub fn rgb(
        &self,
        key: &str,
        v: &Spanned<Components>,
        ok: impl Fn(f32) -> bool,
        requirement: &str,
    ) -> Checked<Vec3> {
        let values = self.components(key, v, 3)?;
        let out = Vec3::new(values[0], values[1], values[2]);
        if out.to_array().iter().all(|&x| ok(x)) {
            Ok(out)
        } else {
            Err(self.range(key, v, format!("{requirement} (got {})", self.written(v))))
        }
    }

    /// `n` finite components from a number (repeated) or an array of exactly `n` numbers.
    pub fn components(&self, key: &str, v: &Spanned<Components>, n: usize) -> Checked<Vec<f32>> {
        let values = match v.get_ref() {
            Components::Scalar(x) => vec![*x; n],
            Components::List(list) if list.len() == n => list.clone(),
            Components::List(list) => {
                return Err(self.at(
                    SceneErrorKind::WrongType,
                    key,
                    v,
                    format!(
                        "expected an array of {n} numbers, got an array of {}",
                        list.len()
                    ),
                ));
            }
        };
        values
            .iter()
            .map(|&x| {
                if x.is_finite() && (x as f32).is_finite() {
                    Ok(x as f32)
                } else {
                    Err(self.range(
                        key,
                        v,
                        format!("must be finite numbers (got {})", self.written(v)),
                    ))
                }
            })
            .collect()
    }

    /// Rejects a key that does not apply (`what` says why), if present.
    pub fn forbid<T>(&self, key: &str, v: &Option<Spanned<T>>, what: &str) -> Checked<()> {
        match v {
            Some(v) => Err(self.at(
                SceneErrorKind::Conflict,
                key,
                v,
                format!("does not apply to {what}"),
            )),
            None => Ok(()),
        }
    }

    /// Requires a key (reported at `table`, the enclosing table, when absent).
    pub fn require<'v, T, U>(
        &self,
        key: &str,
        v: &'v Option<Spanned<T>>,
        table: &Spanned<U>,
        what: &str,
    ) -> Checked<&'v Spanned<T>> {
        v.as_ref().ok_or_else(|| {
            self.at(
                SceneErrorKind::MissingKey,
                key,
                table,
                format!("missing required key for {what}"),
            )
        })
    }
}
