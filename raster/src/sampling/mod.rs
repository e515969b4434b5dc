//! Blue-noise irradiance sample placement over triangle meshes.

pub mod rng;
