//! Typed errors. Nothing in the core panics on bad input; it returns one of these.

use alloc::string::String;
use core::fmt;

use crate::query::Method;

pub use crate::cache::ValidationError;
pub use crate::query::QueryError;

/// An invalid material parameter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ParamError {
    /// NaN or ±∞.
    NotFinite {
        /// Which parameter.
        name: &'static str,
        /// The offending value.
        value: f32,
    },
    /// Zero or negative where a positive value is required.
    NotPositive {
        /// Which parameter.
        name: &'static str,
        /// The offending value.
        value: f32,
    },
    /// A relative index of refraction below 1 (the dipole's boundary term needs η ≥ 1).
    EtaBelowOne {
        /// The offending value.
        value: f32,
    },
    /// A relative index of refraction above [`crate::Profile::MAX_ETA`], where the dipole's
    /// Fresnel fit (and with it the profile) stops being valid.
    EtaAboveMax {
        /// The offending value.
        value: f32,
    },
    /// A diffuse reflectance K_d outside the open interval (0, 1).
    ReflectanceOutOfRange {
        /// The offending value.
        value: f32,
    },
    /// Valid inputs whose derived quantities leave the f32 range (e.g. a mean free path so
    /// small that Rd(0) overflows).
    OutOfRange {
        /// Which parameter.
        name: &'static str,
        /// The offending value.
        value: f32,
    },
    /// A preset name that is not in the table.
    UnknownPreset,
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            ParamError::NotFinite { name, value } => {
                write!(f, "{name} must be a finite number, got {value}")
            }
            ParamError::NotPositive { name, value } => {
                write!(f, "{name} must be positive, got {value}")
            }
            ParamError::EtaBelowOne { value } => {
                write!(
                    f,
                    "eta (relative index of refraction) must be at least 1, got {value}"
                )
            }
            ParamError::EtaAboveMax { value } => write!(
                f,
                "eta (relative index of refraction) must be at most {}, got {value}",
                crate::dipole::MAX_ETA
            ),
            ParamError::ReflectanceOutOfRange { value } => {
                write!(
                    f,
                    "kd (diffuse reflectance) must lie strictly between 0 and 1, got {value}"
                )
            }
            ParamError::OutOfRange { name, value } => write!(
                f,
                "{name} = {value:e} is outside the range the dipole can represent in single precision"
            ),
            ParamError::UnknownPreset => write!(f, "unknown material preset"),
        }
    }
}

impl core::error::Error for ParamError {}

/// Why an irradiance cache could not be built.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BuildError {
    /// A sample position component is NaN or infinite.
    NonFinitePosition {
        /// Index of the sample in the input.
        index: usize,
    },
    /// A sample's area is negative, NaN or infinite.
    InvalidArea {
        /// Index of the sample in the input.
        index: usize,
        /// The offending value.
        value: f32,
    },
    /// A sample's irradiance has a negative, NaN or infinite channel.
    InvalidIrradiance {
        /// Index of the sample in the input.
        index: usize,
        /// The offending value.
        value: f32,
    },
    /// The samples' total area, or their total flux (irradiance × area) in some channel,
    /// exceeds the f32 range the cache stores its sums in.
    TotalOverflow {
        /// `"area"` or `"flux"`.
        quantity: &'static str,
        /// The total, in double precision.
        value: f64,
    },
    /// More samples than the 32-bit indices can address.
    TooManySamples {
        /// How many were given.
        count: usize,
    },
}

impl fmt::Display for BuildError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            BuildError::NonFinitePosition { index } => {
                write!(f, "sample {index}: position is not finite")
            }
            BuildError::InvalidArea { index, value } => {
                write!(
                    f,
                    "sample {index}: area must be finite and non-negative, got {value}"
                )
            }
            BuildError::InvalidIrradiance { index, value } => write!(
                f,
                "sample {index}: irradiance must be finite and non-negative, got {value}"
            ),
            BuildError::TotalOverflow { quantity, value } => write!(
                f,
                "the samples' total {quantity} {value:e} exceeds single precision (at most {:e})",
                f32::MAX
            ),
            BuildError::TooManySamples { count } => {
                write!(
                    f,
                    "{count} samples exceed the cache's limit of {}",
                    crate::cache::MAX_SAMPLES
                )
            }
        }
    }
}

impl core::error::Error for BuildError {}

/// A method name that is not one of [`Method::ALL`]'s names (from `str::parse::<Method>`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ParseMethodError {
    /// The name that was given.
    pub name: String,
}

impl fmt::Display for ParseMethodError {
    /// `unknown method `NAME` (expected one of: hierarchical, …)`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "unknown method `{}` (expected one of: ", self.name)?;
        for (i, m) in Method::ALL.iter().enumerate() {
            if i > 0 {
                f.write_str(", ")?;
            }
            f.write_str(m.name())?;
        }
        f.write_str(")")
    }
}

impl core::error::Error for ParseMethodError {}

#[cfg(test)]
mod tests {
    extern crate std;

    use alloc::string::ToString;

    use super::*;

    #[test]
    fn every_name_parses_back_and_unknown_names_list_them_all() {
        for m in Method::ALL {
            assert_eq!(m.name().parse::<Method>(), Ok(m));
            assert_eq!(m.to_string(), m.name());
        }
        let err = "fast".parse::<Method>().unwrap_err();
        assert_eq!(
            err.to_string(),
            "unknown method `fast` (expected one of: hierarchical, local-global, edge-aware, \
             edge-refined, exhaustive)"
        );
        // Case and whitespace matter: the scene format and the command line are exact.
        assert!("Edge-Aware".parse::<Method>().is_err());
        assert!(" edge-aware".parse::<Method>().is_err());
    }
}
