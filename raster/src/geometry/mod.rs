//! Rays and the bounding volume hierarchy used for shadow rays.
