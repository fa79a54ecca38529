//! Whole output sets or none (see `docs/reliability.md`).
//!
//! A run that writes several files must never leave a mixture behind: files of an older run
//! that the new one does not write (stale `block-K.vts`), the first half of a set after a
//! failure late in the run (disk full, a bad `--svg` path), or files of two concurrent runs
//! into the same directory.
//!
//! * [`OutputDir`] — a run's **directory** of files. Everything is written into a fresh staging
//!   directory *beside* the target (`<parent>/.<name>.unamalla-tmp-<pid>-<n>-<nanos>`, same file
//!   system, so renames are atomic), and [`OutputDir::commit`] renames the staging directory
//!   onto the target at the very end. An existing target is moved aside first (to
//!   `.<name>.unamalla-old-…`) and removed after the new set is in place. Dropping an
//!   uncommitted `OutputDir` (an error, a panic) removes the staging directory, so a failed run
//!   leaves the target exactly as it was. Two concurrent runs each have their own staging
//!   directory; their final renames are serialized by an exclusive lock on the parent
//!   directory ([`std::fs::File::lock`]), so whichever commits last wins, and the target
//!   always holds exactly one run's files. After `kill -9` the target is intact too (old set
//!   or new set); the orphaned staging directory of a dead process is removed by the next run
//!   into the same target.
//!   An existing target directory is only replaced when it is empty or holds a previous
//!   output (the marker file [`MARKER`] written by every commit); a directory with other
//!   files (`-o .`, `-o ~`) is refused with [`OutputError::Foreign`], never deleted.
//! * [`OutputFiles`] — a run's set of **individual files** (`-o out.geojson --svg pic.svg`):
//!   each file is written to a temporary name beside its target ([`OutputFiles::stage`]) and
//!   all are renamed into place by [`OutputFiles::commit`] once every one of them has been
//!   written; dropping the set uncommitted removes the temporaries. (Renames of separate files
//!   are atomic one by one, not as a set; they are the last, cheap step of a run.)

use std::fs;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{SystemTime, UNIX_EPOCH};

/// Name of the marker file every committed [`OutputDir`] holds; it lists the set's files.
pub const MARKER: &str = ".unamalla-output";

/// Infix of staging names (directories and files) beside a target.
const TMP_INFIX: &str = ".unamalla-tmp-";
/// Infix of a replaced target while the new set moves in.
const OLD_INFIX: &str = ".unamalla-old-";

static COUNTER: AtomicU64 = AtomicU64::new(0);

/// Errors of [`OutputDir`] and [`OutputFiles`]. Every variant names the path.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum OutputError {
    /// A file-system operation failed.
    #[error("{path}: {action}: {source}")]
    Io {
        /// The path the operation was about.
        path: PathBuf,
        /// What was being done ("creating the staging directory", …).
        action: &'static str,
        /// The operating system's error.
        #[source]
        source: io::Error,
    },
    /// The target path names no directory entry (`.`, `..`, `/`).
    #[error("{0}: the output must be a named file or directory (not '.', '..' or '/')")]
    NoName(PathBuf),
    /// The target exists but is not a directory.
    #[error("{0}: exists and is not a directory")]
    NotADirectory(PathBuf),
    /// The target directory holds files that no unamalla run wrote.
    #[error(
        "{path}: the directory exists and holds files not written by unamalla (e.g. '{example}'); \
         it is replaced as a whole, so give a new or empty directory"
    )]
    Foreign {
        /// The target directory.
        path: PathBuf,
        /// One of the foreign entries.
        example: String,
    },
}

fn io_err<'a>(path: &'a Path, action: &'static str) -> impl FnOnce(io::Error) -> OutputError + 'a {
    move |source| OutputError::Io {
        path: path.to_path_buf(),
        action,
        source,
    }
}

/// A unique suffix `<pid>-<counter>-<nanos>`.
fn unique() -> String {
    let nanos = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.subsec_nanos())
        .unwrap_or(0);
    format!(
        "{}-{}-{nanos:08x}",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    )
}

/// Parent directory and file name of `target` (the parent `.` when there is none).
fn split(target: &Path) -> Result<(PathBuf, String), OutputError> {
    let name = match target.file_name() {
        Some(n) => n.to_string_lossy().into_owned(),
        None => return Err(OutputError::NoName(target.to_path_buf())),
    };
    let parent = match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    Ok((parent, name))
}

/// Short form of a name for temporary names (file-name length limits).
fn short(name: &str) -> String {
    name.chars().take(64).collect()
}

/// Whether process `pid` is alive (Linux: `/proc/<pid>`; elsewhere assumed alive).
fn process_alive(pid: u32) -> bool {
    if cfg!(target_os = "linux") {
        Path::new("/proc").join(pid.to_string()).exists()
    } else {
        true
    }
}

/// Removes staging and set-aside entries of `name` in `parent` left by dead processes
/// (`kill -9` during a run). Best effort.
fn remove_orphans(parent: &Path, name: &str) {
    let Ok(entries) = fs::read_dir(parent) else {
        return;
    };
    let short = short(name);
    for e in entries.flatten() {
        let file = e.file_name().to_string_lossy().into_owned();
        for infix in [TMP_INFIX, OLD_INFIX] {
            let prefix = format!(".{short}{infix}");
            let Some(rest) = file.strip_prefix(&prefix) else {
                continue;
            };
            let pid = rest.split('-').next().and_then(|p| p.parse::<u32>().ok());
            if let Some(pid) = pid {
                if pid != std::process::id() && !process_alive(pid) {
                    let p = e.path();
                    let _ = if p.is_dir() {
                        fs::remove_dir_all(&p)
                    } else {
                        fs::remove_file(&p)
                    };
                }
            }
        }
    }
}

/// A run's output directory, written into a staging directory and renamed into place by
/// [`OutputDir::commit`] (see the module documentation).
#[derive(Debug)]
pub struct OutputDir {
    target: PathBuf,
    parent: PathBuf,
    name: String,
    staging: PathBuf,
    committed: bool,
}

impl OutputDir {
    /// Creates the staging directory for `target` (creating the target's parent directories if
    /// needed). Fails early — before any work is wasted — when the target cannot be replaced:
    /// it is a file, or a directory holding foreign files, or the parent is not writable.
    pub fn create(target: impl AsRef<Path>) -> Result<Self, OutputError> {
        let target = target.as_ref().to_path_buf();
        let (parent, name) = split(&target)?;
        check_replaceable(&target)?;
        fs::create_dir_all(&parent).map_err(io_err(&parent, "creating the parent directory"))?;
        remove_orphans(&parent, &name);
        let staging = parent.join(format!(".{}{TMP_INFIX}{}", short(&name), unique()));
        fs::create_dir(&staging).map_err(io_err(&staging, "creating the staging directory"))?;
        Ok(Self {
            target,
            parent,
            name,
            staging,
            committed: false,
        })
    }

    /// The staging directory: write the run's files here.
    pub fn path(&self) -> &Path {
        &self.staging
    }

    /// `self.path().join(file)`.
    pub fn join(&self, file: impl AsRef<Path>) -> PathBuf {
        self.staging.join(file)
    }

    /// The final directory.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// Writes the marker, then renames the staging directory onto the target (an existing
    /// target, empty or a previous output, is moved aside and removed afterwards). Returns the
    /// target path.
    pub fn commit(mut self) -> Result<PathBuf, OutputError> {
        let mut files = list_files(&self.staging, Path::new(""))
            .map_err(io_err(&self.staging, "listing the staged files"))?;
        files.sort();
        let marker = self.staging.join(MARKER);
        let text: String = files.iter().map(|f| format!("{f}\n")).collect();
        fs::write(&marker, text).map_err(io_err(&marker, "writing the marker"))?;
        sync_tree(&self.staging);
        // commits into one parent directory are serialized by an exclusive lock on it, held
        // until this function returns (see `lock_dir`)
        let _lock = lock_dir(&self.parent);
        // without the lock (a platform or file system without directory locks), concurrent
        // commits can re-create the target between moving it aside and moving the staging
        // directory in; retry a few times (each round moves one run's set aside)
        let mut last: Option<io::Error> = None;
        for _ in 0..16 {
            check_replaceable(&self.target)?;
            let old = self
                .parent
                .join(format!(".{}{OLD_INFIX}{}", short(&self.name), unique()));
            let moved_aside = match fs::rename(&self.target, &old) {
                Ok(()) => true,
                Err(e) if e.kind() == io::ErrorKind::NotFound => false,
                Err(e) => return Err(io_err(&self.target, "moving the old output aside")(e)),
            };
            match fs::rename(&self.staging, &self.target) {
                Ok(()) => {
                    self.committed = true;
                    if moved_aside {
                        let _ = fs::remove_dir_all(&old);
                    }
                    sync_dir(&self.parent);
                    return Ok(self.target.clone());
                }
                Err(e) => {
                    // another run's set took the place: it is whole, try again; any other
                    // error: put the old set back
                    if moved_aside && fs::rename(&old, &self.target).is_err() {
                        let _ = fs::remove_dir_all(&old);
                    }
                    if !self.target.exists() {
                        return Err(io_err(&self.target, "moving the new output into place")(e));
                    }
                    last = Some(e);
                }
            }
        }
        Err(io_err(&self.target, "moving the new output into place")(
            last.unwrap_or_else(|| io::Error::other("too many concurrent runs")),
        ))
    }
}

impl Drop for OutputDir {
    fn drop(&mut self) {
        if !self.committed {
            let _ = fs::remove_dir_all(&self.staging);
        }
    }
}

/// An exclusive advisory lock on directory `dir` (`flock` on Linux, through
/// [`std::fs::File::lock`]), released when the returned file is dropped — also when the
/// process dies, so a `kill -9` leaves no stale lock. Two commits into one directory then
/// cannot interleave their "move the old set aside, move the new set in" steps: each finds the
/// target as the previous commit left it. Locking the directory itself leaves no lock file
/// behind. `None` where a directory cannot be opened or locked (e.g. Windows); the commit then
/// falls back to its retry loop.
fn lock_dir(dir: &Path) -> Option<fs::File> {
    let f = fs::File::open(dir).ok()?;
    f.lock().ok()?;
    Some(f)
}

/// The target may be replaced: absent, or an empty directory, or a directory with the marker.
fn check_replaceable(target: &Path) -> Result<(), OutputError> {
    let meta = match fs::symlink_metadata(target) {
        Ok(m) => m,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(io_err(target, "reading the output directory")(e)),
    };
    if !meta.is_dir() {
        return Err(OutputError::NotADirectory(target.to_path_buf()));
    }
    if target.join(MARKER).is_file() {
        return Ok(());
    }
    let mut entries = match fs::read_dir(target) {
        Ok(entries) => entries,
        // moved aside by a concurrent run's commit since the metadata above (that run's set,
        // which had the marker): the target is absent now
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(io_err(target, "reading the output directory")(e)),
    };
    match entries.next() {
        None => Ok(()),
        // a concurrent run's set (with its marker) moved in since the marker test above
        Some(_) if target.join(MARKER).is_file() => Ok(()),
        Some(e) => Err(OutputError::Foreign {
            path: target.to_path_buf(),
            example: e
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .unwrap_or_default(),
        }),
    }
}

/// Relative paths of the files below `dir` (`/`-separated).
fn list_files(dir: &Path, rel: &Path) -> io::Result<Vec<String>> {
    let mut out = Vec::new();
    for e in fs::read_dir(dir.join(rel))? {
        let e = e?;
        let r = rel.join(e.file_name());
        if e.file_type()?.is_dir() {
            out.extend(list_files(dir, &r)?);
        } else {
            out.push(r.to_string_lossy().replace('\\', "/"));
        }
    }
    Ok(out)
}

/// `fsync` of the files and directories below `dir` (best effort; the writers already sync
/// their files, this covers the directory entries).
fn sync_tree(dir: &Path) {
    if let Ok(entries) = fs::read_dir(dir) {
        for e in entries.flatten() {
            if e.file_type().is_ok_and(|t| t.is_dir()) {
                sync_tree(&e.path());
            }
        }
    }
    sync_dir(dir);
}

fn sync_dir(dir: &Path) {
    #[cfg(unix)]
    {
        if let Ok(d) = fs::File::open(dir) {
            let _ = d.sync_all();
        }
    }
    #[cfg(not(unix))]
    {
        let _ = dir;
    }
}

/// A run's set of individual output files, staged beside their targets and renamed into place
/// together by [`OutputFiles::commit`] (see the module documentation).
#[derive(Debug, Default)]
pub struct OutputFiles {
    staged: Vec<(PathBuf, PathBuf)>,
    committed: bool,
}

impl OutputFiles {
    /// An empty set.
    pub fn new() -> Self {
        Self::default()
    }

    /// A temporary path beside `target` (same directory, same extension, so writers that
    /// choose the format by extension still do) for the caller to write; it replaces `target`
    /// at [`OutputFiles::commit`]. Fails when the target's directory does not exist or is not
    /// writable (checked by creating the temporary file), or the target is a directory.
    pub fn stage(&mut self, target: impl AsRef<Path>) -> Result<PathBuf, OutputError> {
        let target = target.as_ref().to_path_buf();
        let (parent, name) = split(&target)?;
        if target.is_dir() {
            return Err(OutputError::Io {
                path: target,
                action: "writing the output file",
                source: io::Error::other("a directory of that name exists"),
            });
        }
        remove_orphans(&parent, &name);
        let ext = target
            .extension()
            .map(|e| format!(".{}", e.to_string_lossy()))
            .unwrap_or_default();
        let tmp = parent.join(format!(".{}{TMP_INFIX}{}{ext}", short(&name), unique()));
        fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)
            .map_err(io_err(&target, "creating the output file"))?;
        self.staged.push((tmp.clone(), target));
        Ok(tmp)
    }

    /// Stages `target` and writes `bytes` to it.
    pub fn write(&mut self, target: impl AsRef<Path>, bytes: &[u8]) -> Result<(), OutputError> {
        let target = target.as_ref();
        let tmp = self.stage(target)?;
        write_synced(&tmp, bytes).map_err(io_err(target, "writing the output file"))
    }

    /// Renames every staged file onto its target.
    pub fn commit(mut self) -> Result<(), OutputError> {
        for (tmp, target) in &self.staged {
            fs::rename(tmp, target).map_err(io_err(target, "moving the output file into place"))?;
        }
        self.committed = true;
        Ok(())
    }
}

impl Drop for OutputFiles {
    fn drop(&mut self) {
        if !self.committed {
            for (tmp, _) in &self.staged {
                let _ = fs::remove_file(tmp);
            }
        }
    }
}

fn write_synced(path: &Path, bytes: &[u8]) -> io::Result<()> {
    use std::io::Write;
    let mut f = fs::File::create(path)?;
    f.write_all(bytes)?;
    f.sync_all()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("unamalla-output-{tag}-{}", std::process::id()));
        let _ = fs::remove_dir_all(&d);
        fs::create_dir_all(&d).unwrap();
        d
    }

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn a_second_run_replaces_the_whole_set() {
        let root = scratch("replace");
        let target = root.join("out");
        let d = OutputDir::create(&target).unwrap();
        for f in ["a.txt", "b.txt", "stale.txt"] {
            fs::write(d.join(f), f).unwrap();
        }
        d.commit().unwrap();
        let d = OutputDir::create(&target).unwrap();
        fs::write(d.join("a.txt"), "new").unwrap();
        d.commit().unwrap();
        assert_eq!(names(&target), vec![MARKER, "a.txt"]);
        assert_eq!(fs::read_to_string(target.join("a.txt")).unwrap(), "new");
        assert_eq!(fs::read_to_string(target.join(MARKER)).unwrap(), "a.txt\n");
        // nothing left beside the target
        assert_eq!(names(&root), vec!["out"]);
    }

    #[test]
    fn a_failed_run_leaves_the_target_as_it_was() {
        let root = scratch("failed");
        let target = root.join("out");
        let d = OutputDir::create(&target).unwrap();
        fs::write(d.join("a.txt"), "old").unwrap();
        d.commit().unwrap();
        {
            let d = OutputDir::create(&target).unwrap();
            fs::write(d.join("a.txt"), "half").unwrap();
            // dropped without commit: the run failed
        }
        assert_eq!(fs::read_to_string(target.join("a.txt")).unwrap(), "old");
        assert_eq!(names(&root), vec!["out"]);
        // a fresh target that failed is not created at all
        {
            let _d = OutputDir::create(root.join("never")).unwrap();
        }
        assert_eq!(names(&root), vec!["out"]);
    }

    #[test]
    fn a_directory_with_foreign_files_is_refused_and_kept() {
        let root = scratch("foreign");
        fs::write(root.join("thesis.tex"), "precious").unwrap();
        let e = OutputDir::create(&root).unwrap_err();
        assert!(matches!(e, OutputError::Foreign { .. }), "{e}");
        assert!(e.to_string().contains("thesis.tex"), "{e}");
        assert!(root.join("thesis.tex").exists());
        assert!(matches!(
            OutputDir::create(root.join("thesis.tex")).unwrap_err(),
            OutputError::NotADirectory(_)
        ));
        assert!(matches!(
            OutputDir::create(".").unwrap_err(),
            OutputError::NoName(_)
        ));
        // an empty existing directory is fine
        let empty = root.join("empty");
        fs::create_dir(&empty).unwrap();
        let d = OutputDir::create(&empty).unwrap();
        fs::write(d.join("x"), "1").unwrap();
        d.commit().unwrap();
        assert_eq!(names(&empty), vec![MARKER, "x"]);
    }

    #[test]
    fn concurrent_commits_leave_one_whole_set() {
        let root = scratch("concurrent");
        let target = root.join("out");
        let handles: Vec<_> = (0..8)
            .map(|k| {
                let target = target.clone();
                std::thread::spawn(move || {
                    let d = OutputDir::create(&target).unwrap();
                    for f in 0..=k {
                        fs::write(d.join(format!("f{f}")), format!("{k}")).unwrap();
                    }
                    d.commit().unwrap();
                })
            })
            .collect();
        for h in handles {
            h.join().unwrap();
        }
        // one run's set: files f0..=fk all holding k, nothing else
        let files: Vec<String> = names(&target).into_iter().filter(|n| n != MARKER).collect();
        let k = files.len() - 1;
        for f in &files {
            assert_eq!(fs::read_to_string(target.join(f)).unwrap(), k.to_string());
        }
        assert_eq!(names(&root), vec!["out"]);
    }

    #[test]
    fn orphans_of_dead_processes_are_removed() {
        let root = scratch("orphans");
        // pid 2^31 - 2 does not exist (above Linux's pid_max)
        let orphan = root.join(format!(".out{TMP_INFIX}2147483646-0-0"));
        fs::create_dir(&orphan).unwrap();
        fs::write(orphan.join("half.vtu"), "x").unwrap();
        let d = OutputDir::create(root.join("out")).unwrap();
        if cfg!(target_os = "linux") {
            assert!(!orphan.exists());
        }
        d.commit().unwrap();
    }

    #[test]
    fn file_sets_are_staged_and_committed_together() {
        let root = scratch("files");
        fs::write(root.join("a.geojson"), "old").unwrap();
        {
            let mut set = OutputFiles::new();
            set.write(root.join("a.geojson"), b"new").unwrap();
            // the second target's directory does not exist: the whole set fails
            assert!(set.write(root.join("missing/b.svg"), b"svg").is_err());
        }
        assert_eq!(names(&root), vec!["a.geojson"]);
        assert_eq!(fs::read_to_string(root.join("a.geojson")).unwrap(), "old");
        let mut set = OutputFiles::new();
        let tmp = set.stage(root.join("b.svg")).unwrap();
        assert_eq!(tmp.extension().unwrap(), "svg");
        fs::write(&tmp, "svg").unwrap();
        set.write(root.join("a.geojson"), b"new").unwrap();
        set.commit().unwrap();
        assert_eq!(names(&root), vec!["a.geojson", "b.svg"]);
        assert_eq!(fs::read_to_string(root.join("a.geojson")).unwrap(), "new");
    }
}
