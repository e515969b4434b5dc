//! Scene errors: every problem found while loading a scene, located by file, line, column and
//! key.
//!
//! Messages read `FILE:LINE:COLUMN: KEY: what is wrong`, e.g.
//! `scenes/a.toml:12:7: material.skin.eta: must be at least 1 (got 0.8)`. Keys inside arrays
//! of tables carry their index from 0 (`object[2].scale`). Errors inside a referenced file (an
//! OBJ mesh, a PNG texture) are located at the scene key that names the file and give the
//! file's own path, and the OBJ line where it is known, in the message.

use std::fmt;
use std::ops::Range;
use std::sync::Arc;

/// The error behind a [`SceneError`], shared so that scene errors stay cheap to clone.
pub type SceneErrorSource = Arc<dyn std::error::Error + Send + Sync + 'static>;

/// What kind of problem a [`SceneError`] reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SceneErrorKind {
    /// A file (scene, mesh or texture) could not be read.
    Io,
    /// The scene file is not valid TOML.
    Syntax,
    /// A key that the format does not know.
    UnknownKey,
    /// A value of the wrong type (a string where a number is expected, a wrong-length array).
    WrongType,
    /// A required key is absent.
    MissingKey,
    /// A number outside its allowed range, including NaN and infinities.
    OutOfRange,
    /// A name that refers to nothing: material, preset, shape, light type, method, layer.
    UnknownName,
    /// Keys that cannot be used together, or a key that does not apply here.
    Conflict,
    /// A mesh that cannot be used: malformed OBJ, bad indices, NaN vertices, no area, no UVs.
    Mesh,
    /// A texture that cannot be used: a malformed or unsupported image file, absurd size.
    Texture,
}

/// A scene that could not be loaded, with where and why.
///
/// Two errors are equal when they say the same thing at the same place; their sources are
/// not compared (their messages are part of `message` already).
#[derive(Clone, Debug)]
pub struct SceneError {
    /// The classification of the problem.
    pub kind: SceneErrorKind,
    /// The scene file as given (`<built-in>/default.toml` for the embedded default scene).
    pub file: String,
    /// 1-based line and column (in characters) in the scene file, when known.
    pub position: Option<(usize, usize)>,
    /// Dotted key path (`camera.fov`, `object[0].scale`, `material.marble.eta`), when known.
    pub key: Option<String>,
    /// What is wrong, with the offending value where there is one (and the source's message,
    /// if there is a source).
    pub message: String,
    /// The error behind it, if one (a file's I/O error, the TOML parser's, the PNG decoder's,
    /// the OBJ parser's): returned by [`source`](std::error::Error::source).
    pub source: Option<SceneErrorSource>,
}

impl SceneError {
    /// This error with `source` as the error behind it.
    pub fn with_source(mut self, source: impl std::error::Error + Send + Sync + 'static) -> Self {
        self.source = Some(Arc::new(source));
        self
    }
}

impl PartialEq for SceneError {
    fn eq(&self, other: &Self) -> bool {
        (
            &self.kind,
            &self.file,
            &self.position,
            &self.key,
            &self.message,
        ) == (
            &other.kind,
            &other.file,
            &other.position,
            &other.key,
            &other.message,
        )
    }
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file)?;
        if let Some((line, column)) = self.position {
            write!(f, ":{line}:{column}")?;
        }
        if let Some(key) = &self.key {
            write!(f, ": {key}")?;
        }
        write!(f, ": {}", self.message)
    }
}

impl std::error::Error for SceneError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.source
            .as_deref()
            .map(|e| e as &(dyn std::error::Error + 'static))
    }
}

/// The text of a scene file and its display name: turns byte spans into located errors.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Source<'a> {
    /// Display name of the file.
    pub file: &'a str,
    /// The whole file.
    pub text: &'a str,
}

impl<'a> Source<'a> {
    /// 1-based line and column (counted in characters) of a byte offset.
    pub fn line_column(&self, offset: usize) -> (usize, usize) {
        let mut offset = offset.min(self.text.len());
        while !self.text.is_char_boundary(offset) {
            offset -= 1;
        }
        let before = &self.text[..offset];
        let line = before.matches('\n').count() + 1;
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        let column = before[line_start..].chars().count() + 1;
        (line, column)
    }

    /// An error located at a span of the scene file.
    pub fn error(
        &self,
        kind: SceneErrorKind,
        span: Range<usize>,
        key: impl Into<String>,
        message: impl Into<String>,
    ) -> SceneError {
        SceneError {
            kind,
            file: self.file.to_string(),
            position: Some(self.line_column(span.start)),
            key: Some(key.into()),
            message: message.into(),
            source: None,
        }
    }

    /// An error about the whole file (no position, maybe no key).
    pub fn file_error(
        &self,
        kind: SceneErrorKind,
        key: Option<String>,
        message: impl Into<String>,
    ) -> SceneError {
        SceneError {
            kind,
            file: self.file.to_string(),
            position: None,
            key,
            message: message.into(),
            source: None,
        }
    }

    /// Converts a TOML syntax error (from parsing the document).
    pub fn syntax_error(&self, err: &toml::de::Error) -> SceneError {
        let (position, key) = match err.span() {
            Some(span) => (Some(self.line_column(span.start)), None),
            None => (None, None),
        };
        SceneError {
            kind: SceneErrorKind::Syntax,
            file: self.file.to_string(),
            position,
            key,
            message: format!("TOML syntax error: {}", err.message().trim()),
            source: Some(Arc::new(err.clone())),
        }
    }

    /// Converts a deserialisation error (unknown key, wrong type, missing key, bad name).
    /// `arrays` names the top-level arrays of tables, whose element index is added to the key.
    pub fn data_error(&self, err: &toml::de::Error, arrays: &[&str]) -> SceneError {
        let message = err.message().trim().to_string();
        let kind = classify(&message);
        let mut keys = error_keys(err);
        // The missing key is named in the message; the key path (where it was expected) is the
        // enclosing table's.
        if let Some(missing) = backticked(&message, "missing field ") {
            keys.push(missing.to_string());
        }
        if let Some(unknown) = backticked(&message, "unknown field ")
            && keys.last().map(String::as_str) != Some(unknown)
        {
            keys.push(unknown.to_string());
        }
        let position = err.span().map(|s| self.line_column(s.start));
        if let (Some(first), Some(span)) = (keys.first_mut(), err.span())
            && arrays.contains(&first.as_str())
            && let Some(index) = self.array_index(first, span.start)
        {
            *first = format!("{first}[{index}]");
        }
        let key = (!keys.is_empty()).then(|| keys.join("."));
        SceneError {
            kind,
            file: self.file.to_string(),
            position,
            key,
            message: friendly(&message),
            source: Some(Arc::new(err.clone())),
        }
    }

    /// Which element of the top-level array `name` contains byte `offset`: the last element
    /// that starts at or before it (array-of-tables elements start at their `[[name]]` header).
    fn array_index(&self, name: &str, offset: usize) -> Option<usize> {
        let root = toml::de::DeTable::parse(self.text).ok()?;
        let (_, value) = root.get_ref().iter().find(|(k, _)| k.get_ref() == name)?;
        let array = value.get_ref().as_array()?;
        let mut index = None;
        for (i, element) in array.iter().enumerate() {
            if element.span().start <= offset {
                index = Some(i);
            }
        }
        // Array-of-tables elements: count the `[[name]]` headers up to the end of the line
        // holding `offset` (an error about a whole element points at its header).
        let start = offset.min(self.text.len());
        let end = self.text.as_bytes()[start..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(self.text.len(), |i| start + i);
        let headers = self.text[..end]
            .lines()
            .filter(|l| {
                let t = l.trim_start();
                t.strip_prefix("[[")
                    .map(str::trim_start)
                    .and_then(|t| t.strip_prefix(name))
                    .is_some_and(|t| t.trim_start().starts_with("]]"))
            })
            .count();
        match (index, headers) {
            (_, h) if h > 0 => Some(h - 1),
            (i, _) => i,
        }
    }
}

/// The key path toml recorded in the error (available only through its `Display`).
fn error_keys(err: &toml::de::Error) -> Vec<String> {
    let mut bare = err.clone();
    bare.set_input(None);
    let shown = bare.to_string();
    shown
        .lines()
        .rev()
        .find_map(|l| l.strip_prefix("in `").and_then(|r| r.strip_suffix('`')))
        .map(|path| path.split('.').map(str::to_string).collect())
        .unwrap_or_default()
}

/// The first backticked word after `prefix` in a serde message.
fn backticked<'m>(message: &'m str, prefix: &str) -> Option<&'m str> {
    let rest = message.split(prefix).nth(1)?.strip_prefix('`')?;
    rest.split('`').next()
}

fn classify(message: &str) -> SceneErrorKind {
    if message.starts_with("unknown field") {
        SceneErrorKind::UnknownKey
    } else if message.starts_with("missing field") {
        SceneErrorKind::MissingKey
    } else if message.starts_with("unknown variant") {
        SceneErrorKind::UnknownName
    } else {
        SceneErrorKind::WrongType
    }
}

/// Rewords serde's vocabulary ("field", "variant") into the scene format's ("key", "value").
fn friendly(message: &str) -> String {
    message
        .replace("unknown field", "unknown key")
        .replace("missing field", "missing required key")
        .replace("unknown variant", "unknown value")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_and_column_count_characters() {
        let s = Source {
            file: "f.toml",
            text: "a = 1\nbé = 2\nc = 3",
        };
        assert_eq!(s.line_column(0), (1, 1));
        assert_eq!(s.line_column(6), (2, 1));
        // 'é' is two bytes: "= 2" starts at character 4 of line 2 (byte offset 10).
        assert_eq!(s.line_column(10), (2, 4));
        assert_eq!(s.line_column(1000), (3, 6));
    }

    #[test]
    fn the_error_behind_is_the_source() {
        use std::error::Error as _;
        let dir = std::env::temp_dir().join(format!("lucent-scene-source-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // A missing file: the I/O error.
        let e = crate::scene::load_scene(&dir.join("missing.toml")).unwrap_err();
        assert!(e.to_string().contains("cannot read scene: "), "{e}");
        let io = e.source().and_then(|s| s.downcast_ref::<std::io::Error>());
        assert_eq!(io.map(|e| e.kind()), Some(std::io::ErrorKind::NotFound));
        // TOML syntax: the parser's error.
        std::fs::write(dir.join("bad.toml"), "[camera\n").unwrap();
        let e = crate::scene::load_scene(&dir.join("bad.toml")).unwrap_err();
        assert!(e.to_string().contains("TOML syntax error"), "{e}");
        assert!(
            e.source()
                .and_then(|s| s.downcast_ref::<toml::de::Error>())
                .is_some()
        );
        // A mesh that does not exist: the I/O error, named at the scene key.
        let shipped = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/default.toml");
        let text = std::fs::read_to_string(shipped).unwrap();
        assert!(text.contains("\"../assets/bunny.obj\""));
        let text = text.replace("\"../assets/bunny.obj\"", "\"nowhere.obj\"");
        std::fs::write(dir.join("mesh.toml"), text).unwrap();
        let e = crate::scene::load_scene(&dir.join("mesh.toml")).unwrap_err();
        assert_eq!(e.kind, SceneErrorKind::Io, "{e}");
        assert!(e.to_string().contains("cannot read mesh"), "{e}");
        assert!(e.to_string().contains("nowhere.obj"), "{e}");
        let io = e.source().and_then(|s| s.downcast_ref::<std::io::Error>());
        assert_eq!(io.map(|e| e.kind()), Some(std::io::ErrorKind::NotFound));
        let _ = std::fs::remove_dir_all(&dir);
        // Equality ignores the source.
        let plain = SceneError {
            kind: SceneErrorKind::Io,
            file: "a.toml".into(),
            position: None,
            key: None,
            message: "m".into(),
            source: None,
        };
        let with = plain.clone().with_source(std::io::Error::other("x"));
        assert_eq!(plain, with);
        assert!(with.source().is_some() && plain.source().is_none());
    }

    #[test]
    fn display_has_file_position_key_and_message() {
        let e = SceneError {
            kind: SceneErrorKind::OutOfRange,
            file: "a.toml".into(),
            position: Some((3, 7)),
            key: Some("camera.fov".into()),
            message: "must be in (0, 180) degrees (got 200)".into(),
            source: None,
        };
        assert_eq!(
            e.to_string(),
            "a.toml:3:7: camera.fov: must be in (0, 180) degrees (got 200)"
        );
    }
}
