//! Wavefront `.mtl` material libraries, read with `tobj`: lucent takes only each material's
//! diffuse texture (`map_Kd`), for scene materials that ask for it with `kd = "mtl"`.

use std::io::BufReader;

use super::obj::{ObjError, utf8_lines};

/// One `newmtl` of a library: its name and its `map_Kd` path (relative to the library), if
/// any.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MtlMaterial {
    /// The `newmtl` name (what `usemtl` refers to).
    pub name: String,
    /// The `map_Kd` file, if the material has one.
    pub map_kd: Option<String>,
}

/// Parses a `.mtl` file held in memory. Bytes that are not UTF-8 are accepted in comments
/// only. A colour (`Ka`, `Kd`, `Ks`, `Ke`) needs three numbers. A `map_Kd` with options (`-s`, `-o`, `-clamp`, ...) is an error: lucent would ignore
/// them and map the texture differently from the file's intent.
pub fn parse_mtl(bytes: &[u8]) -> Result<Vec<MtlMaterial>, ObjError> {
    let text = utf8_lines(bytes, &[])?;
    for (number, line) in text.lines().enumerate() {
        let fail = |message: String| ObjError {
            line: Some(number + 1),
            message,
            source: None,
        };
        let mut words = line.split_whitespace();
        match words.next() {
            Some("map_Kd") if words.next().is_some_and(|w| w.starts_with('-')) => {
                return Err(fail(
                    "map_Kd options (-s, -o, -clamp, ...) are not supported: give only the \
                     texture file"
                        .to_string(),
                ));
            }
            // `tobj` panics on a colour with fewer than three numbers.
            Some(colour @ ("Ka" | "Kd" | "Ks" | "Ke")) if words.clone().count() < 3 => {
                return Err(fail(format!("{colour} needs three numbers (r g b)")));
            }
            _ => {}
        }
    }
    let mut reader = BufReader::new(text.as_bytes());
    let (materials, _) = tobj::load_mtl_buf(&mut reader).map_err(|e| ObjError {
        line: None,
        message: format!("malformed MTL: {e}"),
        source: Some(e),
    })?;
    Ok(materials
        .into_iter()
        .map(|m| MtlMaterial {
            name: m.name,
            map_kd: m.diffuse_texture,
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_diffuse_textures_are_read() {
        let text = b"# caf\xe9 latin-1 comment\nnewmtl skin\nKd 0.8 0.6 0.5\nmap_Kd tex/skin.png\n\
                     newmtl lens\nKd 0 0 0\n";
        let m = parse_mtl(text).expect("parses");
        assert_eq!(
            m,
            vec![
                MtlMaterial {
                    name: "skin".into(),
                    map_kd: Some("tex/skin.png".into())
                },
                MtlMaterial {
                    name: "lens".into(),
                    map_kd: None
                }
            ]
        );
    }

    #[test]
    fn options_bad_bytes_and_malformed_lines_are_errors() {
        let e = parse_mtl(b"newmtl a\nmap_Kd -s 2 2 1 a.png\n").unwrap_err();
        assert_eq!(e.line, Some(2));
        assert!(e.message.contains("options"), "{e}");
        let e = parse_mtl(b"newmtl a\nnewmtl caf\xe9\n").unwrap_err();
        assert_eq!(e.line, Some(2));
        assert!(e.message.contains("UTF-8"), "{e}");
        let e = parse_mtl(b"newmtl a\nKd x y z\n").unwrap_err();
        assert!(e.message.contains("malformed MTL"), "{e}");
        // Found by fuzzing: two numbers made `tobj` panic.
        let e = parse_mtl(b"newmtl a\nKd 0 1\n").unwrap_err();
        assert_eq!(e.line, Some(2));
        assert!(e.message.contains("three numbers"), "{e}");
    }
}
