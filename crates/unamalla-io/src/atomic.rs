//! Atomic file replacement, shared by every writer of this crate.
//!
//! [`atomic_write`] writes into a fresh temporary file **in the target's directory** (so the
//! final rename never crosses a file system), named
//! `.<file name (first 64 characters)>.tmp-<pid>-<counter>-<nanos>` and created with
//! `create_new` (never clobbering anything). After the content is written it
//! is flushed and `fsync`ed, then renamed over the target; on Unix the directory is `fsync`ed
//! too (best effort). If anything fails — including the caller's closure — the temporary file is
//! removed and the target is left exactly as it was (absent, or with its previous content).
//! Readers therefore see either the old file or the complete new one, never a half-written file.

use std::fs::{self, File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{SystemTime, UNIX_EPOCH};

use crate::error::IoError;

static COUNTER: AtomicU64 = AtomicU64::new(0);

/// Writes `path` atomically: `write` receives a buffered writer on a temporary file, which
/// replaces `path` only if `write` and the flush/sync all succeed.
///
/// To abort with a typed error from inside `write`, return `Err(std::io::Error::other(e))` with
/// `e: IoError`; `atomic_write` unwraps it and returns `e` itself. Any other `io::Error` is
/// reported as [`IoError::Io`] with the **target** path.
///
/// Writers should validate their input *before* calling this function where possible, so that
/// invalid input never touches the file system.
pub fn atomic_write<F>(path: &Path, write: F) -> Result<(), IoError>
where
    F: FnOnce(&mut dyn Write) -> io::Result<()>,
{
    let io_err = |source: io::Error| IoError::Io {
        path: path.to_path_buf(),
        source,
    };
    let file_name = path.file_name().ok_or_else(|| {
        io_err(io::Error::new(
            io::ErrorKind::InvalidInput,
            "the target path has no file name",
        ))
    })?;
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let (tmp_path, file) = create_temp(&dir, file_name).map_err(io_err)?;

    let result = write_and_sync(file, write).and_then(|()| fs::rename(&tmp_path, path));
    match result {
        Ok(()) => {
            sync_dir(&dir);
            Ok(())
        }
        Err(e) => {
            // Best effort: the temporary file must not survive a failed write.
            let _ = fs::remove_file(&tmp_path);
            Err(unwrap_io_error(e, path))
        }
    }
}

/// Creates a new, uniquely named temporary file in `dir`. Long target names are shortened in
/// the temporary name so that it stays within file-name length limits.
fn create_temp(dir: &Path, file_name: &std::ffi::OsStr) -> io::Result<(PathBuf, File)> {
    let lossy = file_name.to_string_lossy();
    let stem: String = lossy.chars().take(64).collect();
    let pid = std::process::id();
    let mut last_err = None;
    for _ in 0..64 {
        let count = COUNTER.fetch_add(1, Ordering::Relaxed);
        let nanos = SystemTime::now()
            .duration_since(UNIX_EPOCH)
            .map(|d| d.subsec_nanos())
            .unwrap_or(0);
        let tmp = dir.join(format!(".{stem}.tmp-{pid}-{count}-{nanos:08x}"));
        match OpenOptions::new().write(true).create_new(true).open(&tmp) {
            Ok(f) => return Ok((tmp, f)),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => last_err = Some(e),
            Err(e) => return Err(e),
        }
    }
    Err(last_err.unwrap_or_else(|| io::Error::other("could not create a temporary file")))
}

fn write_and_sync<F>(file: File, write: F) -> io::Result<()>
where
    F: FnOnce(&mut dyn Write) -> io::Result<()>,
{
    let mut w = BufWriter::with_capacity(1 << 16, file);
    write(&mut w)?;
    w.flush()?;
    let file = w.into_inner().map_err(|e| e.into_error())?;
    file.sync_all()?;
    Ok(())
}

/// Makes the rename durable (Unix); errors are ignored because the data is already in place.
fn sync_dir(dir: &Path) {
    #[cfg(unix)]
    {
        if let Ok(d) = File::open(dir) {
            let _ = d.sync_all();
        }
    }
    #[cfg(not(unix))]
    {
        let _ = dir;
    }
}

/// Recovers an [`IoError`] smuggled through `io::Error::other`, or wraps a plain I/O error.
fn unwrap_io_error(e: io::Error, path: &Path) -> IoError {
    if e.get_ref().is_some_and(|inner| inner.is::<IoError>()) {
        if let Some(inner) = e.into_inner() {
            if let Ok(typed) = inner.downcast::<IoError>() {
                return *typed;
            }
        }
        // Unreachable in practice: the check above guarantees the downcast succeeds.
        return IoError::Io {
            path: path.to_path_buf(),
            source: io::Error::other("writer failed"),
        };
    }
    IoError::Io {
        path: path.to_path_buf(),
        source: e,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch_dir(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!(
            "unamalla-io-atomic-{tag}-{}-{}",
            std::process::id(),
            COUNTER.fetch_add(1, Ordering::Relaxed)
        ));
        let _ = fs::remove_dir_all(&d);
        fs::create_dir_all(&d).unwrap();
        d
    }

    fn entries(d: &Path) -> Vec<String> {
        let mut v: Vec<String> = fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn successful_write_creates_only_the_target() {
        let d = scratch_dir("ok");
        let target = d.join("out.txt");
        atomic_write(&target, |w| w.write_all(b"hello\n")).unwrap();
        assert_eq!(fs::read_to_string(&target).unwrap(), "hello\n");
        assert_eq!(entries(&d), vec!["out.txt".to_string()]);
        // Replacing an existing file.
        atomic_write(&target, |w| w.write_all(b"second")).unwrap();
        assert_eq!(fs::read_to_string(&target).unwrap(), "second");
        assert_eq!(entries(&d), vec!["out.txt".to_string()]);
        fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn failing_writer_leaves_no_target_and_no_temp_file() {
        let d = scratch_dir("fail");
        let target = d.join("mesh.vtk");
        let err = atomic_write(&target, |w| {
            // Enough data to force the buffer to reach the temporary file on disk.
            for _ in 0..10_000 {
                w.write_all(b"0.123456789 0.987654321 0\n")?;
            }
            Err(io::Error::other("disk full (simulated)"))
        })
        .unwrap_err();
        match err {
            IoError::Io { path, source } => {
                assert_eq!(path, target);
                assert!(source.to_string().contains("simulated"));
            }
            other => panic!("unexpected error {other:?}"),
        }
        assert!(!target.exists());
        assert!(entries(&d).is_empty(), "left over: {:?}", entries(&d));
        fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn failing_writer_keeps_previous_content_and_typed_error_passes_through() {
        let d = scratch_dir("keep");
        let target = d.join("keep.vtk");
        fs::write(&target, "old content").unwrap();
        let err = atomic_write(&target, |w| {
            w.write_all(b"new partial content")?;
            Err(io::Error::other(IoError::Malformed {
                path: PathBuf::from("x"),
                line: 7,
                message: "typed".into(),
            }))
        })
        .unwrap_err();
        assert!(matches!(err, IoError::Malformed { line: 7, .. }), "{err:?}");
        assert_eq!(fs::read_to_string(&target).unwrap(), "old content");
        assert_eq!(entries(&d), vec!["keep.vtk".to_string()]);
        fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn long_target_name_is_fine() {
        let d = scratch_dir("long");
        let name = format!("{}.vtk", "n".repeat(240));
        let target = d.join(&name);
        atomic_write(&target, |w| w.write_all(b"x")).unwrap();
        assert_eq!(entries(&d), vec![name]);
        fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn missing_directory_is_an_io_error() {
        let d = scratch_dir("nodir");
        let target = d.join("no").join("such").join("dir.vtk");
        let err = atomic_write(&target, |w| w.write_all(b"x")).unwrap_err();
        assert!(matches!(err, IoError::Io { ref path, .. } if *path == target));
        fs::remove_dir_all(&d).unwrap();
    }
}
