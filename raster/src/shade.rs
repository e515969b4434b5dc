//! Shading a visible surface point: translucent through the core, opaque Lambert.
