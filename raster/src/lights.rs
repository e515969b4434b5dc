//! Light sources and the irradiance they deliver, with shadows.
