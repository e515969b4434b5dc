//! The scene's tables are tables: `[camera]` written as `camera = [ … ]` is an error.
//!
//! serde's derived structs also accept an array of their fields in declaration order, so
//! without this check `camera = [[0, -5, 1], [0, 0, 0], [0, 0, 1], 35, 512, 512]` would load
//! as a camera, and `render = ["edge-aware", 500]` would fail with a message naming an
//! internal type. The check runs on the parsed document before deserialisation and names the
//! key, its line and what it should be.

use toml::Spanned;
use toml::de::{DeTable, DeValue};

use super::error::{SceneError, SceneErrorKind, Source};

/// What a key of the format must hold.
#[derive(Clone, Copy)]
enum Shape {
    /// `[key]` or `key = { … }`.
    Table,
    /// `[[key]]`: an array of tables.
    Tables,
    /// `[key.NAME]`: a table whose every value is a table.
    NamedTables,
}

/// The top-level keys that hold tables, and their shapes.
const TOP: [(&str, Shape); 6] = [
    ("camera", Shape::Table),
    ("render", Shape::Table),
    ("output", Shape::Table),
    ("object", Shape::Tables),
    ("light", Shape::Tables),
    ("material", Shape::NamedTables),
];

/// Keys inside a `[material.NAME]` table that hold tables.
const MATERIAL: [&str; 1] = ["specular"];

/// Checks that every key of the format that holds a table (or tables) does in the parsed
/// document `root`; other keys and unknown keys are left to deserialisation.
pub(crate) fn check_tables(root: &DeTable<'_>, src: &Source<'_>) -> Result<(), SceneError> {
    for (key, value) in root {
        let Some(&(name, shape)) = TOP.iter().find(|(name, _)| *name == key.get_ref().as_ref())
        else {
            continue;
        };
        match shape {
            Shape::Table => {
                expect_table(src, name, value)?;
            }
            Shape::Tables => {
                let DeValue::Array(items) = value.get_ref() else {
                    let expected = format!("an array of tables ([[{name}]])");
                    return Err(wrong(src, name, value, &expected));
                };
                for (i, item) in items.iter().enumerate() {
                    expect_table(src, &format!("{name}[{i}]"), item)?;
                }
            }
            Shape::NamedTables => {
                let DeValue::Table(tables) = value.get_ref() else {
                    let expected = format!("a table of tables ([{name}.NAME])");
                    return Err(wrong(src, name, value, &expected));
                };
                for (inner, table) in tables {
                    let path = format!("{name}.{}", inner.get_ref());
                    for (k, v) in expect_table(src, &path, table)? {
                        if MATERIAL.contains(&k.get_ref().as_ref()) {
                            expect_table(src, &format!("{path}.{}", k.get_ref()), v)?;
                        }
                    }
                }
            }
        }
    }
    Ok(())
}

/// The table `value` holds, or an error naming `key`.
fn expect_table<'v, 'i>(
    src: &Source<'_>,
    key: &str,
    value: &'v Spanned<DeValue<'i>>,
) -> Result<&'v DeTable<'i>, SceneError> {
    match value.get_ref() {
        DeValue::Table(table) => Ok(table),
        _ => Err(wrong(
            src,
            key,
            value,
            &format!("a table ([{key}] or {{ … }})"),
        )),
    }
}

fn wrong(src: &Source<'_>, key: &str, value: &Spanned<DeValue<'_>>, expected: &str) -> SceneError {
    let found = match value.get_ref() {
        DeValue::String(_) => "a string",
        DeValue::Integer(_) => "an integer",
        DeValue::Float(_) => "a number",
        DeValue::Boolean(_) => "a boolean",
        DeValue::Datetime(_) => "a date",
        DeValue::Array(_) => "an array",
        DeValue::Table(_) => "a table",
    };
    src.error(
        SceneErrorKind::WrongType,
        value.span(),
        key,
        format!("expected {expected}, got {found}"),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(text: &str) -> Result<(), String> {
        let src = Source {
            file: "s.toml",
            text,
        };
        let root = DeTable::parse(text).expect("valid TOML");
        check_tables(root.get_ref(), &src).map_err(|e| e.to_string())
    }

    #[test]
    fn tables_written_as_other_values_name_the_key_and_line() {
        let cases = [
            (
                "camera = [1, 2]",
                "s.toml:1:10: camera: expected a table ([camera] or { … }), got an array",
            ),
            (
                "render = 5",
                "render: expected a table ([render] or { … }), got an integer",
            ),
            (
                "output = \"o.png\"",
                "output: expected a table ([output] or { … }), got a string",
            ),
            (
                "object = { shape = \"sphere\" }",
                "object: expected an array of tables ([[object]]), got a table",
            ),
            (
                "light = [{ type = \"point\" }, 2.5]",
                "light[1]: expected a table ([light[1]] or { … }), got a number",
            ),
            (
                "material = [1]",
                "material: expected a table of tables ([material.NAME]), got an array",
            ),
            (
                "[material]\nm = true",
                "s.toml:2:5: material.m: expected a table ([material.m] or { … }), got a boolean",
            ),
            (
                "[material.m]\nspecular = [60, 0.4]",
                "s.toml:2:12: material.m.specular: expected a table",
            ),
        ];
        for (text, expected) in cases {
            let err = check(text).expect_err(text);
            assert!(err.contains(expected), "{text}: {err}");
        }
    }

    #[test]
    fn tables_and_other_keys_pass() {
        let ok = [
            "[camera]\nfov = 35",
            "camera = { fov = 35 }",
            "[[object]]\nname = \"a\"\n[[object]]\nname = \"b\"",
            "[material.m]\nspecular = { exponent = 60 }\nkd = [0.5, 0.5, 0.5]",
            // Unknown keys and wrong scalars are deserialisation's to report.
            "frobnicate = [1]\n[camera]\nfov = \"wide\"",
        ];
        for text in ok {
            assert_eq!(check(text), Ok(()), "{text}");
        }
    }
}
