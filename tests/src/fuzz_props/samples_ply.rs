//! `samples_ply_read_never_panics`: arbitrary bytes read as a baked sample set, the PLY that
//! `lucent bake` writes and `lucent render --samples-from` reads.
//!
//! Reading returns a sample set or an error naming the file, never a panic; the file's size is
//! checked against its header's count before anything is allocated, so memory stays within
//! the file's size. A set passes `SampleSet::validate` (four vectors of one length, finite
//! positions, unit normals, finite non-negative areas and irradiance), holds no more samples
//! than its bytes can store (40 bytes each at least), and a comment never spans a line.

use std::path::Path;

use lucent_raster::output::decode_ply_with_comments;

use super::assert_error_names_the_file;

/// The property of the fuzz target `samples_ply_read_never_panics` (see the module docs).
pub fn samples_ply_read_never_panics(data: &[u8]) {
    let name = "t.ply";
    match decode_ply_with_comments(data, Path::new(name)) {
        Ok((set, comments)) => {
            set.validate().expect("a set read is valid");
            assert!(
                set.len() * 40 <= data.len(),
                "{} samples from {} bytes",
                set.len(),
                data.len()
            );
            for c in &comments {
                assert!(!c.contains('\n'), "comment spans lines: {c:?}");
            }
        }
        Err(e) => {
            assert_error_names_the_file(&e.to_string(), &format!("{name}: "), name);
        }
    }
}
