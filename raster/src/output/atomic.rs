//! Atomic file replacement: a file is either completely written or not touched at all.
//!
//! [`write_atomically`] writes into a fresh temporary file in the target's directory
//! (`tempfile::NamedTempFile`; the same file system, so the final rename is atomic on POSIX),
//! flushes and fsyncs it, then renames it over the target. On any error — including a panic
//! in the writer closure — the temporary file is removed and an existing target is left
//! byte-identical. A reader never sees a half-written PNG, EXR, PLY, SVG or report, even if
//! `lucent` is killed mid-write. Every file lucent writes goes through here.
//!
//! The target is the file the path names: a symbolic link is followed and the file it points
//! to replaced, not the link; a device (`/dev/null`), pipe or socket is refused, since the
//! rename would put a plain file in its place ([`output_target`]).
//!
//! An existing target whose permissions say read-only is refused ([`OutputError::ReadOnly`])
//! before anything is written: a rename replaces a file whatever its permissions, which would
//! silently overwrite a result its owner protected.

use std::fs::File;
use std::io::{BufWriter, Seek, Write};
use std::path::{Path, PathBuf};

use super::OutputError;

/// A writer that can also seek (the OpenEXR encoder seeks back to fill in its offset table).
pub trait WriteSeek: Write + Seek {}

impl<T: Write + Seek + ?Sized> WriteSeek for T {}

/// Writes `path` atomically: `write` receives a buffered writer onto a temporary file in the
/// same directory; when it returns `Ok`, the data is flushed, fsynced and renamed over `path`.
///
/// Errors name `path` and the step that failed. When `write` fails, its error is returned
/// unchanged. The parent directory must exist (it is not created). An existing `path` that
/// is read-only is not replaced: [`OutputError::ReadOnly`].
pub fn write_atomically<F>(path: &Path, write: F) -> Result<(), OutputError>
where
    F: FnOnce(&mut dyn WriteSeek) -> Result<(), OutputError>,
{
    let Some(file_name) = path.file_name() else {
        return Err(OutputError::invalid(
            path,
            "the output path does not name a file",
        ));
    };
    let target = output_target(path)?;
    let dir = match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    refuse_read_only(&target)?;

    // `.<name>.XXXXXX.tmp`: hidden, and recognisably the target's. The handle deletes the
    // file when dropped — on every early return below and when `write` panics.
    let mut prefix = std::ffi::OsString::from(".");
    prefix.push(file_name);
    prefix.push(".");
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(".tmp");
    // NamedTempFile creates files readable by the owner only; an output file gets the usual
    // permissions (0666 less the umask), like any file the user creates.
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
    let temp = builder.tempfile_in(dir).map_err(|e| {
        OutputError::io(
            path,
            format!("creating a temporary file in '{}' failed", dir.display()),
            e,
        )
    })?;

    let mut writer = BufWriter::new(temp);
    write(&mut writer)?;
    let temp = writer
        .into_inner()
        .map_err(|e| OutputError::io(path, "flushing the temporary file failed", e.into_error()))?;
    temp.as_file()
        .sync_all()
        .map_err(|e| OutputError::io(path, "syncing the temporary file to disk failed", e))?;

    let temp_path = temp.path().to_path_buf();
    // On failure the error hands the temporary file back, and dropping it removes it.
    temp.persist(&target).map_err(|e| {
        OutputError::io(
            path,
            format!(
                "renaming the temporary file '{}' over the target failed",
                temp_path.display()
            ),
            e.error,
        )
    })?;

    // Make the rename itself durable. Best effort: not every platform or file system lets a
    // directory be opened and synced, and the new file is already in place.
    #[cfg(unix)]
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
    Ok(())
}

/// The file that writing `path` replaces: `path` itself, or the file a symbolic link names
/// (which must exist). Refused: a directory, and anything else that is not a regular file — a
/// device such as `/dev/null`, a pipe or a socket, which the rename of [`write_atomically`]
/// would replace with a plain file (as the superuser, even `/dev/null`).
pub fn output_target(path: &Path) -> Result<PathBuf, OutputError> {
    // `out.png/` names a directory: the rename would fail only after the render.
    if path.to_string_lossy().ends_with(std::path::is_separator) {
        return Err(OutputError::invalid(
            path,
            "the output path ends with a separator, so it names a directory, not a file",
        ));
    }
    let target = match std::fs::symlink_metadata(path) {
        Ok(meta) if meta.file_type().is_symlink() => std::fs::canonicalize(path).map_err(|e| {
            OutputError::io(
                path,
                "following the symbolic link failed (the file it names must exist)",
                e,
            )
        })?,
        _ => path.to_path_buf(),
    };
    match std::fs::metadata(&target) {
        Ok(meta) if meta.is_dir() => Err(OutputError::invalid(
            path,
            "cannot write there: it is a directory",
        )),
        Ok(meta) if !meta.is_file() => Err(OutputError::invalid(
            path,
            "cannot write there: it is not a regular file (a device, pipe or socket), which \
             lucent would replace with a plain file",
        )),
        _ => Ok(target),
    }
}

/// Writes the text `text` to `path` atomically (see [`write_atomically`]): reports, CSV
/// tables, SVG charts.
pub fn write_text_atomically(path: &Path, text: &str) -> Result<(), OutputError> {
    write_atomically(path, |w| {
        w.write_all(text.as_bytes())
            .map_err(|e| OutputError::io(path, "writing the file failed", e))
    })
}

/// Fails with [`OutputError::ReadOnly`] when `path` exists and its permissions are
/// read-only. The permission bits are checked, not a write attempted: the superuser may
/// write any file, and the rename would replace it anyway. [`write_atomically`] checks this
/// first; a command that writes several files checks them all before writing any.
pub fn refuse_read_only(path: &Path) -> Result<(), OutputError> {
    match std::fs::metadata(path) {
        Ok(meta) if meta.is_file() && meta.permissions().readonly() => Err(OutputError::ReadOnly {
            path: path.to_path_buf(),
        }),
        // A missing target is the usual case; any other problem with it (a directory, no
        // access) surfaces with its own message when the rename fails.
        _ => Ok(()),
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use std::fs;
    use std::io;
    use std::path::PathBuf;
    use std::sync::atomic::{AtomicU64, Ordering};

    use super::*;

    /// A fresh, empty directory under the system temp dir, removed on drop.
    pub(crate) struct TestDir(pub PathBuf);

    impl TestDir {
        pub(crate) fn new(tag: &str) -> Self {
            static N: AtomicU64 = AtomicU64::new(0);
            let n = N.fetch_add(1, Ordering::Relaxed);
            let dir = std::env::temp_dir()
                .join(format!("lucent-output-{tag}-{}-{n}", std::process::id()));
            let _ = fs::remove_dir_all(&dir);
            fs::create_dir_all(&dir).expect("create test dir");
            TestDir(dir)
        }

        pub(crate) fn path(&self, name: &str) -> PathBuf {
            self.0.join(name)
        }

        pub(crate) fn entries(&self) -> Vec<String> {
            let mut v: Vec<String> = fs::read_dir(&self.0)
                .expect("read test dir")
                .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
                .collect();
            v.sort();
            v
        }
    }

    impl Drop for TestDir {
        fn drop(&mut self) {
            let _ = fs::remove_dir_all(&self.0);
        }
    }

    #[test]
    fn writes_new_file_and_replaces_existing() {
        let dir = TestDir::new("atomic-ok");
        let target = dir.path("a.bin");
        write_atomically(&target, |w| {
            w.write_all(b"first")
                .map_err(|e| OutputError::io(&target, "write", e))
        })
        .unwrap();
        assert_eq!(fs::read(&target).unwrap(), b"first");
        write_atomically(&target, |w| {
            w.write_all(b"second!")
                .map_err(|e| OutputError::io(&target, "write", e))
        })
        .unwrap();
        assert_eq!(fs::read(&target).unwrap(), b"second!");
        assert_eq!(dir.entries(), vec!["a.bin".to_string()]);
    }

    #[test]
    fn failing_writer_leaves_target_untouched_and_no_temp_file() {
        let dir = TestDir::new("atomic-fail");
        let target = dir.path("keep.png");
        let original: Vec<u8> = (0..=255u8).cycle().take(10_000).collect();
        fs::write(&target, &original).unwrap();

        let err = write_atomically(&target, |w| {
            // Write a lot (more than the buffer) so bytes really reach the temp file.
            w.write_all(&[0u8; 100_000])
                .map_err(|e| OutputError::io(&target, "write", e))?;
            Err(OutputError::invalid(&target, "encoder failed half-way"))
        })
        .unwrap_err();
        assert!(err.to_string().contains("encoder failed half-way"), "{err}");
        assert_eq!(fs::read(&target).unwrap(), original);
        assert_eq!(dir.entries(), vec!["keep.png".to_string()]);
    }

    #[test]
    fn panicking_writer_leaves_no_temp_file() {
        let dir = TestDir::new("atomic-panic");
        let target = dir.path("p.bin");
        let result = std::panic::catch_unwind(|| {
            let _ = write_atomically(&target, |w| {
                w.write_all(&[1u8; 50_000]).ok();
                panic!("writer bug");
            });
        });
        assert!(result.is_err());
        assert!(dir.entries().is_empty(), "{:?}", dir.entries());
    }

    #[test]
    fn missing_directory_is_a_clear_error() {
        let dir = TestDir::new("atomic-missing");
        let target = dir.path("no/such/dir/out.exr");
        let err = write_atomically(&target, |_| Ok(())).unwrap_err();
        let msg = err.to_string();
        assert!(msg.contains("no/such/dir/out.exr"), "{msg}");
        assert!(msg.contains("creating a temporary file"), "{msg}");
        match err {
            OutputError::Io { source, .. } => assert_eq!(source.kind(), io::ErrorKind::NotFound),
            other => panic!("unexpected {other:?}"),
        }
        assert!(!dir.path("no").exists());
    }

    #[test]
    fn path_without_file_name_is_rejected() {
        let err = write_atomically(Path::new("/"), |_| Ok(())).unwrap_err();
        assert!(err.to_string().contains("does not name a file"), "{err}");
        let dir = TestDir::new("atomic-slash");
        let slash = dir.0.join("out.png/");
        let err = write_atomically(&slash, |_| Ok(())).unwrap_err();
        assert!(err.to_string().contains("ends with a separator"), "{err}");
        assert!(dir.entries().is_empty(), "{:?}", dir.entries());
    }

    #[test]
    fn bare_file_name_cleans_up_in_current_directory() {
        // A bare file name has an empty parent: the temporary file goes into ".". A failing
        // writer must leave nothing behind there either.
        let name = format!("lucent-atomic-{}.test-output", std::process::id());
        let err = write_atomically(Path::new(&name), |w| {
            w.write_all(&[7u8; 20_000])
                .map_err(|e| OutputError::io(&name, "write", e))?;
            Err(OutputError::invalid(&name, "deliberate"))
        })
        .unwrap_err();
        assert!(err.to_string().contains("deliberate"));
        assert!(!Path::new(&name).exists());
        let leftovers: Vec<_> = fs::read_dir(".")
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().contains(&name))
            .collect();
        assert!(leftovers.is_empty(), "{leftovers:?}");
    }

    #[test]
    fn read_only_target_is_refused_and_kept() {
        let dir = TestDir::new("atomic-readonly");
        let target = dir.path("protected.png");
        fs::write(&target, b"precious").unwrap();
        let mut permissions = fs::metadata(&target).unwrap().permissions();
        permissions.set_readonly(true);
        fs::set_permissions(&target, permissions).unwrap();

        let mut called = false;
        let err = write_atomically(&target, |w| {
            called = true;
            w.write_all(b"replacement")
                .map_err(|e| OutputError::io(&target, "write", e))
        })
        .unwrap_err();
        let msg = err.to_string();
        assert!(matches!(err, OutputError::ReadOnly { .. }), "{err:?}");
        assert!(msg.contains("protected.png"), "{msg}");
        assert!(msg.contains("read-only"), "{msg}");
        assert!(!called, "nothing is written for a refused target");
        // Checked by the bits: as root, the OS alone would let the write through.
        assert!(fs::metadata(&target).unwrap().permissions().readonly());
        assert_eq!(fs::read(&target).unwrap(), b"precious");
        assert_eq!(dir.entries(), vec!["protected.png".to_string()]);

        // Made writable again, it is replaced as usual.
        let mut permissions = fs::metadata(&target).unwrap().permissions();
        #[allow(clippy::permissions_set_readonly_false)]
        permissions.set_readonly(false);
        fs::set_permissions(&target, permissions).unwrap();
        write_atomically(&target, |w| {
            w.write_all(b"new")
                .map_err(|e| OutputError::io(&target, "write", e))
        })
        .unwrap();
        assert_eq!(fs::read(&target).unwrap(), b"new");
    }

    #[cfg(unix)]
    #[test]
    fn a_symbolic_link_is_followed_and_kept() {
        let dir = TestDir::new("atomic-symlink");
        let target = dir.path("real.png");
        fs::write(&target, b"old").unwrap();
        let link = dir.path("link.png");
        std::os::unix::fs::symlink(&target, &link).unwrap();
        write_atomically(&link, |w| {
            w.write_all(b"new")
                .map_err(|e| OutputError::io(&link, "write", e))
        })
        .unwrap();
        assert!(
            fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(fs::read(&target).unwrap(), b"new");
        assert_eq!(
            dir.entries(),
            vec!["link.png".to_string(), "real.png".to_string()]
        );

        let dangling = dir.path("dangling.png");
        std::os::unix::fs::symlink(dir.path("missing.png"), &dangling).unwrap();
        let err = write_atomically(&dangling, |_| Ok(())).unwrap_err();
        assert!(err.to_string().contains("symbolic link"), "{err}");
        assert!(!dir.path("missing.png").exists());
    }

    #[cfg(unix)]
    #[test]
    fn pipes_are_refused() {
        // A pipe stands for every non-regular file (a device is not tried: were the check
        // broken, the test would replace it).
        let dir = TestDir::new("atomic-special");
        let fifo = dir.path("pipe.png");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        assert!(made.is_ok_and(|s| s.success()), "mkfifo failed");
        let mut called = false;
        let err = write_atomically(&fifo, |_| {
            called = true;
            Ok(())
        })
        .unwrap_err();
        assert!(err.to_string().contains("not a regular file"), "{err}");
        assert!(!called);
        let kind = fs::symlink_metadata(&fifo).unwrap().file_type();
        assert!(std::os::unix::fs::FileTypeExt::is_fifo(&kind));
        assert_eq!(dir.entries(), vec!["pipe.png".to_string()]);
    }

    #[cfg(unix)]
    #[test]
    fn new_files_get_the_usual_permissions() {
        use std::os::unix::fs::PermissionsExt;
        let dir = TestDir::new("atomic-mode");
        let target = dir.path("m.bin");
        write_atomically(&target, |_| Ok(())).unwrap();
        let mode = fs::metadata(&target).unwrap().permissions().mode();
        // Readable by the owner and, unless the umask forbids it (it never removes the
        // owner's bits), not restricted to 0600 as a bare temporary file would be.
        assert_eq!(mode & 0o600, 0o600, "{mode:o}");
        let umask_allows_group_read = {
            let probe = dir.path("probe");
            fs::File::create(&probe).unwrap();
            let m = fs::metadata(&probe).unwrap().permissions().mode();
            fs::remove_file(&probe).unwrap();
            m & 0o077
        };
        assert_eq!(mode & 0o077, umask_allows_group_read, "{mode:o}");
    }
}
