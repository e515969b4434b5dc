//! Atomic file replacement: a file is either completely written or not touched at all.
//!
//! [`write_atomically`] writes into a fresh temporary file in the target's directory (same
//! file system, so the final rename is atomic on POSIX), flushes and fsyncs it, then renames
//! it over the target. On any error — including a panic in the writer closure — the temporary
//! file is removed and an existing target is left byte-identical. A reader never sees a
//! half-written PNG, EXR or PLY, even if `lucent` is killed mid-write.

use std::fs::{self, File, OpenOptions};
use std::io::{self, BufWriter, Seek, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use super::OutputError;

/// A writer that can also seek (the OpenEXR encoder seeks back to fill in its offset table).
pub trait WriteSeek: Write + Seek {}

impl<T: Write + Seek + ?Sized> WriteSeek for T {}

/// Distinguishes temporary files of concurrent writes within one process.
static COUNTER: AtomicU64 = AtomicU64::new(0);

/// How many temporary names to try before giving up (only collisions with stale files from
/// crashed processes of the same pid can make the first one fail).
const NAME_ATTEMPTS: u32 = 64;

/// Removes the temporary file on drop unless disarmed.
struct TempGuard {
    path: PathBuf,
    armed: bool,
}

impl Drop for TempGuard {
    fn drop(&mut self) {
        if self.armed {
            // Nothing sensible can be done if removal fails; the original error is reported.
            let _ = fs::remove_file(&self.path);
        }
    }
}

/// Writes `path` atomically: `write` receives a buffered writer onto a temporary file in the
/// same directory; when it returns `Ok`, the data is flushed, fsynced and renamed over `path`.
///
/// Errors name `path` and the step that failed. When `write` fails, its error is returned
/// unchanged. The parent directory must exist (it is not created).
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
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };

    let (file, temp_path) = create_temp(path, dir, file_name)?;
    let mut guard = TempGuard {
        path: temp_path,
        armed: true,
    };

    let mut writer = BufWriter::new(file);
    write(&mut writer)?;
    let file = writer
        .into_inner()
        .map_err(|e| OutputError::io(path, "flushing the temporary file failed", e.into_error()))?;
    file.sync_all()
        .map_err(|e| OutputError::io(path, "syncing the temporary file to disk failed", e))?;
    drop(file);

    fs::rename(&guard.path, path).map_err(|e| {
        OutputError::io(
            path,
            format!(
                "renaming the temporary file '{}' over the target failed",
                guard.path.display()
            ),
            e,
        )
    })?;
    guard.armed = false;

    // Make the rename itself durable. Best effort: not every platform or file system lets a
    // directory be opened and synced, and the new file is already in place.
    #[cfg(unix)]
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
    Ok(())
}

/// Creates a new, empty temporary file `.<name>.<pid>-<n>.tmp` in `dir`.
fn create_temp(
    target: &Path,
    dir: &Path,
    file_name: &std::ffi::OsStr,
) -> Result<(File, PathBuf), OutputError> {
    let pid = std::process::id();
    let mut last_error = None;
    for _ in 0..NAME_ATTEMPTS {
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let mut name = std::ffi::OsString::from(".");
        name.push(file_name);
        name.push(format!(".{pid}-{n}.tmp"));
        let temp = dir.join(name);
        match OpenOptions::new().write(true).create_new(true).open(&temp) {
            Ok(f) => return Ok((f, temp)),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => last_error = Some(e),
            Err(e) => {
                return Err(OutputError::io(
                    target,
                    format!("creating a temporary file in '{}' failed", dir.display()),
                    e,
                ));
            }
        }
    }
    Err(OutputError::io(
        target,
        format!("no free temporary file name in '{}'", dir.display()),
        last_error.unwrap_or_else(|| io::Error::from(io::ErrorKind::AlreadyExists)),
    ))
}

#[cfg(test)]
pub(crate) mod tests {
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
}
