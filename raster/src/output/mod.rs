//! Output files: PNG, OpenEXR, baked sample sets (PLY), and image comparison.
