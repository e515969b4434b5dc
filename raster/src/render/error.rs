//! [`RenderError`]: why a render failed, keeping the error behind it.

use std::fmt;

use glam::Vec3;
use lucent_core::error::{BuildError, QueryError};

use crate::material::MaterialError;
use crate::memory::OutOfMemory;
use crate::output::OutputError;
use crate::raster::RasterError;
use crate::sampling::SamplingError;

use super::simd::SimdError;

/// Why a render failed. A variant that wraps another error returns it from
/// [`source`](std::error::Error::source).
#[derive(Debug)]
#[non_exhaustive]
pub enum RenderError {
    /// A material's parameters are invalid.
    Material(MaterialError),
    /// Irradiance samples could not be placed.
    Sampling(SamplingError),
    /// The image buffers could not be set up.
    Raster(RasterError),
    /// A baked sample set could not be read.
    BakedFile(OutputError),
    /// A baked sample set does not fit the scene.
    Baked(String),
    /// A scene exceeds an internal limit.
    Limit(String),
    /// The region to render ([`super::RenderOptions::crop`]) does not fit the image.
    Crop(String),
    /// The core rejected a query (a bug if it ever happens: inputs are validated).
    Query {
        /// The shading point.
        position: Vec3,
        /// The core's error.
        source: QueryError,
    },
    /// The core could not build an (empty) irradiance cache (a bug if it ever happens).
    Cache(BuildError),
    /// The finished pixels do not make an image (a bug if it ever happens).
    Image(OutputError),
    /// An internal inconsistency (a bug if it ever happens).
    Core(String),
    /// A buffer that grows with the image or the scene's triangles could not be allocated.
    Memory(OutOfMemory),
    /// The thread pool could not be started.
    Threads(rayon::ThreadPoolBuildError),
    /// `LUCENT_SIMD` asks for a traversal path this CPU cannot run, or none at all.
    Simd(SimdError),
}

impl fmt::Display for RenderError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RenderError::Material(e) => write!(f, "{e}"),
            RenderError::Sampling(e) => write!(f, "irradiance samples: {e}"),
            RenderError::Raster(e) => write!(f, "image: {e}"),
            RenderError::BakedFile(e) => write!(f, "baked samples: {e}"),
            RenderError::Baked(m) => write!(f, "baked samples: {m}"),
            RenderError::Limit(m) => write!(f, "{m}"),
            RenderError::Crop(m) => write!(f, "crop: {m}"),
            RenderError::Query { position, source } => {
                write!(f, "internal error: query at {position}: {source}")
            }
            RenderError::Cache(e) => write!(f, "internal error: empty irradiance cache: {e}"),
            RenderError::Image(e) => write!(f, "internal error: {e}"),
            RenderError::Core(m) => write!(f, "internal error: {m}"),
            RenderError::Memory(e) => write!(f, "{e}"),
            RenderError::Threads(e) => write!(f, "thread pool: {e}"),
            RenderError::Simd(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for RenderError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            RenderError::Material(e) => Some(e),
            RenderError::Sampling(e) => Some(e),
            RenderError::Raster(e) => Some(e),
            RenderError::BakedFile(e) | RenderError::Image(e) => Some(e),
            RenderError::Query { source, .. } => Some(source),
            RenderError::Cache(e) => Some(e),
            RenderError::Memory(e) => Some(e),
            RenderError::Threads(e) => Some(e),
            RenderError::Simd(e) => Some(e),
            RenderError::Baked(_)
            | RenderError::Limit(_)
            | RenderError::Crop(_)
            | RenderError::Core(_) => None,
        }
    }
}

impl From<MaterialError> for RenderError {
    fn from(e: MaterialError) -> Self {
        RenderError::Material(e)
    }
}

impl From<OutOfMemory> for RenderError {
    fn from(e: OutOfMemory) -> Self {
        RenderError::Memory(e)
    }
}

#[cfg(test)]
mod tests {
    use std::error::Error as _;

    use lucent_core::error::ParamError;

    use super::*;
    use crate::render::read_baked;

    #[test]
    fn wrapped_errors_are_the_source_and_messages_stay() {
        let e = RenderError::Query {
            position: Vec3::new(1.0, 2.0, 3.0),
            source: QueryError::NonFinitePosition,
        };
        assert!(
            e.to_string()
                .starts_with("internal error: query at [1, 2, 3]: "),
            "{e}"
        );
        let source = e.source().expect("the query error");
        assert_eq!(
            source.downcast_ref::<QueryError>(),
            Some(&QueryError::NonFinitePosition)
        );

        let e = RenderError::from(MaterialError::Params {
            material: "wax".into(),
            source: ParamError::UnknownPreset,
        });
        let material = e.source().expect("the material error");
        assert_eq!(e.to_string(), material.to_string());
        assert!(e.to_string().starts_with("material 'wax': "), "{e}");
        let param = material.source().expect("the core's error");
        assert_eq!(
            param.downcast_ref::<ParamError>(),
            Some(&ParamError::UnknownPreset)
        );

        assert!(RenderError::Limit("too big".into()).source().is_none());
    }

    #[test]
    fn an_unreadable_baked_file_keeps_the_io_error() {
        let path = std::path::Path::new("/nonexistent/lucent-baked.ply");
        let e = read_baked(path).unwrap_err();
        assert!(matches!(e, RenderError::BakedFile(_)), "{e:?}");
        let message = e.to_string();
        assert!(message.starts_with("baked samples: "), "{message}");
        assert!(message.contains("lucent-baked.ply"), "{message}");
        let output = e.source().expect("the output error");
        let io = output.source().expect("the I/O error");
        assert_eq!(
            io.downcast_ref::<std::io::Error>().map(|e| e.kind()),
            Some(std::io::ErrorKind::NotFound)
        );
    }
}
