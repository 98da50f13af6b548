//! Output files that are never left half-written: every file curvetet writes goes to a
//! temporary file in the target's directory, is flushed and synced, then renamed over the
//! target in one step. A failed write (full disk, file size limit, a write error) removes
//! the temporary and leaves the target as it was; a killed process leaves at most a
//! hidden `.NAME.XXXXXX.tmp` beside it, never a truncated file under the final name; two
//! concurrent writers of one path each rename a complete file, so the last one wins whole.
//!
//! Also the checks a command runs on its outputs before any work: the directory exists
//! and takes new files ([`check_output_dir`]), and an output is not the input or another
//! output ([`same_file`]).

use std::fs;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use crate::error::{Error, Result};

/// The temporary files being written now, for [`remove_unfinished_temporaries`].
static UNFINISHED: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Keeps a temporary file's path in [`UNFINISHED`] while it is written.
struct Unfinished(PathBuf);

impl Unfinished {
    /// Creates a temporary file with `make` and registers it, holding the registry's lock
    /// throughout: a signal taken meanwhile waits, then finds the file registered.
    fn create(
        make: impl FnOnce() -> io::Result<tempfile::NamedTempFile>,
    ) -> io::Result<(tempfile::NamedTempFile, Unfinished)> {
        let mut list = UNFINISHED.lock().unwrap_or_else(|e| e.into_inner());
        let tmp = make()?;
        list.push(tmp.path().to_path_buf());
        let path = tmp.path().to_path_buf();
        Ok((tmp, Unfinished(path)))
    }
}

impl Drop for Unfinished {
    fn drop(&mut self) {
        let mut list = UNFINISHED.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(i) = list.iter().position(|p| *p == self.0) {
            list.swap_remove(i);
        }
    }
}

/// Remove the temporary files of the writes in progress, for a program about to end on a
/// signal (Ctrl-C, SIGTERM) while writing: its targets stay as they were, and nothing is
/// left beside them. Call it from a thread that waits for the signals (not from a signal
/// handler: it takes a lock), then end the process; the interrupted writes fail.
pub fn remove_unfinished_temporaries() {
    let list = UNFINISHED.lock().unwrap_or_else(|e| e.into_inner());
    for p in list.iter() {
        let _ = fs::remove_file(p);
    }
}

/// The directory a file named `path` lives in (`.` for a bare file name).
fn dir_of(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// Where writing `path` should land: through a symbolic link to the file it names (so a
/// link keeps pointing to the new contents), else `path` itself.
fn target_of(path: &Path) -> PathBuf {
    match fs::symlink_metadata(path) {
        Ok(m) if m.file_type().is_symlink() => fs::canonicalize(path).unwrap_or(path.into()),
        _ => path.to_path_buf(),
    }
}

/// A temporary file beside `target`, created with the permissions a new file gets
/// (0666 less the umask) or those of the file it replaces.
fn temporary_beside(target: &Path) -> io::Result<tempfile::NamedTempFile> {
    let name = target
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let prefix = format!(".{name}.");
    let mut b = tempfile::Builder::new();
    b.prefix(&prefix).suffix(".tmp");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        b.permissions(fs::Permissions::from_mode(0o666));
    }
    let tmp = b.tempfile_in(dir_of(target))?;
    if let Ok(old) = fs::metadata(target) {
        if old.is_file() {
            fs::set_permissions(tmp.path(), old.permissions())?;
        }
    }
    Ok(tmp)
}

/// Write `path` atomically: `write` fills a buffered temporary file beside it, which is
/// synced and renamed over `path`. On any error the temporary is removed and `path` is
/// untouched; the error names `path`.
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<&mut fs::File>) -> io::Result<()>,
) -> Result<()> {
    let target = target_of(path);
    let err = |e| Error::io(path, e);
    let (mut tmp, _unfinished) = Unfinished::create(|| temporary_beside(&target)).map_err(err)?;
    {
        let mut w = BufWriter::with_capacity(1 << 20, tmp.as_file_mut());
        write(&mut w).map_err(err)?;
        w.flush().map_err(err)?;
    }
    tmp.as_file().sync_all().map_err(err)?;
    // On failure the returned error owns the temporary, which is removed when dropped.
    tmp.persist(&target).map_err(|e| err(e.error))?;
    sync_dir(dir_of(&target));
    Ok(())
}

/// Make the rename durable (best effort: some file systems cannot sync a directory).
fn sync_dir(dir: &Path) {
    #[cfg(unix)]
    if let Ok(d) = fs::File::open(dir) {
        let _ = d.sync_all();
    }
    #[cfg(not(unix))]
    let _ = dir;
}

/// Fails unless a file can be written at `path`: its directory exists, is a directory and
/// takes a new file (tried by creating and removing a temporary file there, which also
/// answers for read-only file systems and access control lists), and `path` is not a
/// directory. For commands to call on every output before reading their input.
pub fn check_output_dir(path: &Path) -> Result<()> {
    let target = target_of(path);
    let dir = dir_of(&target);
    match fs::metadata(dir) {
        Ok(m) if m.is_dir() => {}
        Ok(_) => {
            return Err(Error::io(
                path,
                io::Error::new(
                    io::ErrorKind::InvalidInput,
                    format!("{} is not a directory", dir.display()),
                ),
            ))
        }
        Err(e) => {
            return Err(Error::io(
                path,
                io::Error::new(e.kind(), format!("output directory {}: {e}", dir.display())),
            ))
        }
    }
    if fs::metadata(&target).is_ok_and(|m| m.is_dir()) {
        return Err(Error::io(
            path,
            io::Error::new(io::ErrorKind::InvalidInput, "is a directory"),
        ));
    }
    Unfinished::create(|| {
        tempfile::Builder::new()
            .prefix(".curvetet-probe.")
            .tempfile_in(dir)
    })
    .map(drop)
    .map_err(|e| {
        Error::io(
            path,
            io::Error::new(e.kind(), format!("cannot write in {}: {e}", dir.display())),
        )
    })
}

/// `path` with symbolic links and `..` resolved; for a file that does not exist yet, its
/// resolved directory joined with its name.
fn resolved(path: &Path) -> PathBuf {
    if let Ok(p) = fs::canonicalize(path) {
        return p;
    }
    match (fs::canonicalize(dir_of(path)), path.file_name()) {
        (Ok(d), Some(n)) => d.join(n),
        _ => path.to_path_buf(),
    }
}

/// Do `a` and `b` name the same file: the same path once links are resolved, or (both
/// existing) the same device and inode, which also catches hard links?
pub fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if let (Ok(ma), Ok(mb)) = (fs::metadata(a), fs::metadata(b)) {
            return ma.dev() == mb.dev() && ma.ino() == mb.ino();
        }
    }
    resolved(a) == resolved(b)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("curvetet-atomic-{}-{name}", std::process::id()));
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
    fn a_failed_write_leaves_the_old_file_and_no_temporary() {
        let d = scratch("fail");
        let p = d.join("out.msh");
        fs::write(&p, b"old contents").unwrap();
        let r = write_atomic(&p, |w| {
            w.write_all(&[b'x'; 3 << 20])?;
            Err(io::Error::other("disk full"))
        });
        let e = r.unwrap_err().to_string();
        assert!(e.contains("out.msh") && e.contains("disk full"), "{e}");
        assert_eq!(fs::read(&p).unwrap(), b"old contents");
        assert_eq!(entries(&d), ["out.msh"]);
        write_atomic(&p, |w| w.write_all(b"new")).unwrap();
        assert_eq!(fs::read(&p).unwrap(), b"new");
        assert_eq!(entries(&d), ["out.msh"]);
    }

    #[cfg(unix)]
    #[test]
    fn a_link_is_written_through_and_permissions_are_kept() {
        use std::os::unix::fs::PermissionsExt;
        let d = scratch("link");
        let real = d.join("real.vtu");
        fs::write(&real, b"old").unwrap();
        fs::set_permissions(&real, fs::Permissions::from_mode(0o640)).unwrap();
        let link = d.join("link.vtu");
        std::os::unix::fs::symlink(&real, &link).unwrap();
        assert!(same_file(&link, &real));
        write_atomic(&link, |w| w.write_all(b"new")).unwrap();
        assert!(fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(fs::read(&real).unwrap(), b"new");
        let mode = fs::metadata(&real).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o640);
    }

    #[test]
    fn outputs_are_checked_and_compared() {
        let d = scratch("check");
        assert!(check_output_dir(&d.join("a.msh")).is_ok());
        let e = check_output_dir(&d.join("missing/a.msh")).unwrap_err();
        assert!(e.to_string().contains("missing"), "{e}");
        fs::write(d.join("file"), b"").unwrap();
        assert!(check_output_dir(&d.join("file/a.msh")).is_err());
        assert!(check_output_dir(&d).is_err());
        fs::create_dir(d.join("sub")).unwrap();
        assert!(same_file(&d.join("x.msh"), &d.join("sub/../x.msh")));
        assert!(same_file(&d.join("x.msh"), &d.join(".").join("x.msh")));
        assert!(!same_file(&d.join("x.msh"), &d.join("y.msh")));
        // Nothing left behind by the checks.
        assert_eq!(entries(&d), ["file", "sub"]);
    }
}
