//! The render pipeline: samples → irradiance → cache → rasterise → shade.
