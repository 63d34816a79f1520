//! The atomic writer every output goes through ([`write_atomically`]): a temporary file beside the
//! target, renamed onto it, so that a failed write leaves the earlier file whole.

use std::fs::{File, Metadata, OpenOptions};
use std::io::{self, Write};
use std::path::{Path, PathBuf};

use super::StoreError;

/// Symbolic links followed before giving up (Linux's own limit for one path).
const MAX_LINKS: usize = 40;

/// Temporary names tried before giving up when every one is taken (a stale temporary of a
/// crashed process with the same id).
const MAX_TEMPORARIES: usize = 64;

/// `EROFS` (read-only file system) on Linux, macOS and the BSDs; `std` names it only from
/// Rust 1.83 on (`ErrorKind::ReadOnlyFilesystem`), above this crate's minimum.
#[cfg(unix)]
const EROFS: i32 = 30;

/// Why a write was refused before anything was written, carried inside the [`io::Error`] of
/// [`StoreError::Io`] (which keeps the system error's kind), so that every caller that reports
/// the I/O error shows it.
#[derive(Debug, thiserror::Error)]
enum Refusal {
    /// The target exists and cannot be opened for writing (a read-only file for a non-root user).
    #[error("it exists and cannot be opened for writing ({0}); nothing was written")]
    NotWritable(io::Error),
    /// No temporary file can be created in the target's directory, and there is no writable
    /// file to write in place.
    #[error("cannot create a temporary file in {}: {source}", dir.display())]
    NoTemporary {
        /// The target's directory.
        dir: PathBuf,
        /// The system error.
        source: io::Error,
    },
}

impl Refusal {
    fn into_io(self) -> io::Error {
        let kind = match &self {
            Refusal::NotWritable(e) | Refusal::NoTemporary { source: e, .. } => e.kind(),
        };
        io::Error::new(kind, self)
    }
}

/// Writes `bytes` to the file `path` names, atomically whenever the directory allows it.
///
/// The contract, in order:
/// - **Symbolic links are followed**: a `path` that is a link (or a chain of at most 40 links,
///   possibly dangling) writes the file it points to, and the link stays a link.
/// - **An existing regular file must be writable**: it is opened for writing (not truncated)
///   first; if the system refuses (a read-only file for a non-root user, a read-only file
///   system), the write is refused with an error naming `path`, and nothing is written.
/// - **Atomic replacement**: the bytes go to a temporary file `.topomech.tmp-PID-SERIAL` (at most
///   45 bytes, whatever the target's name; unique per process and call) in the target's
///   directory, which is written, given the old file's permissions and (best effort) its owner
///   and group, fsynced and renamed onto the target; then the directory is fsynced (best
///   effort). On any error the temporary is removed and the old file is left whole. Other
///   hard links to the old file keep the old content; ACLs and extended attributes are not
///   copied. A new file gets the default mode (0666 less the umask).
/// - **In-place fallback**: when the directory refuses the temporary (permission denied, a
///   read-only file system) but the target is an existing writable regular file, the target is
///   truncated and written in place, then fsynced — as a plain `File::create` would; a failure
///   then (a full disk) can leave it partial. With no such file the write is refused with an
///   error naming the directory ("cannot create a temporary file in DIR: …").
///
/// A `path` that exists and is a directory is refused by the rename (nothing replaced); a
/// device or a pipe is replaced by a regular file (callers that mean to write into one, like
/// `vtk`'s frame writer for `/dev/null`, write it themselves). O(size).
///
/// # Errors
/// [`StoreError::Io`] naming `path`, with the system error (or the refusals above, which keep
/// its kind).
///
/// # Examples
///
/// ```
/// let path = std::env::temp_dir().join(format!("topomech-doc-{}-atomic.bin", std::process::id()));
/// topomech::store::write_atomically(&path, b"first").unwrap();
/// topomech::store::write_atomically(&path, b"second").unwrap();
/// assert_eq!(std::fs::read(&path).unwrap(), b"second");
/// let missing = path.with_extension("d").join("no/such/dir.bin");
/// let err = topomech::store::write_atomically(&missing, b"x").unwrap_err();
/// assert!(matches!(&err, topomech::store::StoreError::Io { path, .. } if *path == missing), "{err}");
/// # std::fs::remove_file(&path).unwrap();
/// ```
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), StoreError> {
    write_resolved(path, bytes).map_err(|source| StoreError::Io { path: path.to_path_buf(), source })
}

/// [`write_atomically`] with the plain I/O error. O(size).
fn write_resolved(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let target = follow_links(path)?;
    let old = writable_file(&target)?;
    let dir = directory_of(&target);
    match create_temporary(&dir, old.is_some()) {
        Ok((tmp, file)) => replace(file, &tmp, &target, old.as_ref(), bytes).inspect_err(|_| {
            // The rename failed or never ran: the temporary is the only thing to undo.
            let _ = std::fs::remove_file(&tmp);
        })?,
        Err(e) if refused_by_directory(&e) && old.is_some() => return write_in_place(&target, bytes),
        Err(source) if refused_by_directory(&source) => return Err(Refusal::NoTemporary { dir, source }.into_io()),
        Err(e) => return Err(e),
    }
    // Persist the rename itself; not every platform lets a directory be opened and synced.
    if let Ok(d) = File::open(&dir) {
        let _ = d.sync_all();
    }
    Ok(())
}

/// The path `path` ends at after following symbolic links (each relative link read from its
/// own directory); `path` itself when it is no link or does not exist. O(links).
fn follow_links(path: &Path) -> io::Result<PathBuf> {
    let mut p = path.to_path_buf();
    for _ in 0..=MAX_LINKS {
        if !std::fs::symlink_metadata(&p).is_ok_and(|m| m.file_type().is_symlink()) {
            return Ok(p);
        }
        let link = std::fs::read_link(&p)?;
        p = match p.parent() {
            Some(dir) => dir.join(link),
            None => link,
        };
    }
    Err(io::Error::other(format!("more than {MAX_LINKS} symbolic links to follow")))
}

/// The metadata of `target` when it is an existing regular file, which must then open for
/// writing (without truncation); `None` when it does not exist or is no regular file.
fn writable_file(target: &Path) -> io::Result<Option<Metadata>> {
    match std::fs::metadata(target) {
        Ok(m) if m.is_file() => match OpenOptions::new().write(true).open(target) {
            Ok(_) => Ok(Some(m)),
            Err(e) => Err(Refusal::NotWritable(e).into_io()),
        },
        _ => Ok(None),
    }
}

/// The directory holding `target` (`.` for a bare file name).
fn directory_of(target: &Path) -> PathBuf {
    match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// The serial of the next temporary name of this process.
static TEMPORARY_SERIAL: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// The temporary name of serial `serial` in `dir`.
fn temporary_name(dir: &Path, serial: u64) -> PathBuf {
    dir.join(format!(".topomech.tmp-{}-{serial}", std::process::id()))
}

/// A new temporary file in `dir`, named `.topomech.tmp-PID-SERIAL` (unique per process and
/// call; a name left by a crashed process is skipped). Created `private` (0600 on Unix) when it
/// will replace a file whose permissions it takes later, with the default mode otherwise.
fn create_temporary(dir: &Path, private: bool) -> io::Result<(PathBuf, File)> {
    let mut last = None;
    for _ in 0..MAX_TEMPORARIES {
        let serial = TEMPORARY_SERIAL.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let tmp = temporary_name(dir, serial);
        let mut options = OpenOptions::new();
        options.write(true).create_new(true);
        #[cfg(unix)]
        if private {
            std::os::unix::fs::OpenOptionsExt::mode(&mut options, 0o600);
        }
        #[cfg(not(unix))]
        let _ = private;
        match options.open(&tmp) {
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => last = Some(e),
            result => return result.map(|file| (tmp, file)),
        }
    }
    Err(last.unwrap_or_else(|| io::Error::other("no temporary name left")))
}

/// Whether creating a file in a directory failed because the directory refuses it (permission
/// denied, operation not permitted, read-only file system) rather than for want of it or space.
fn refused_by_directory(e: &io::Error) -> bool {
    #[cfg(unix)]
    let read_only = e.raw_os_error() == Some(EROFS);
    #[cfg(not(unix))]
    let read_only = false;
    e.kind() == io::ErrorKind::PermissionDenied || read_only
}

/// Writes the temporary `file` (at `tmp`), gives it the old file's permissions and owner, syncs
/// it and renames it onto `target`.
fn replace(mut file: File, tmp: &Path, target: &Path, old: Option<&Metadata>, bytes: &[u8]) -> io::Result<()> {
    file.write_all(bytes)?;
    file.flush()?;
    if let Some(m) = old {
        keep_owner_and_mode(&file, m)?;
    }
    file.sync_all()?;
    drop(file);
    std::fs::rename(tmp, target)
}

/// Gives `file` the owner and group of `old` (best effort: only root may give a file away)
/// and then its permissions (after the owner, whose change may clear set-id bits).
fn keep_owner_and_mode(file: &File, old: &Metadata) -> io::Result<()> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        let (uid, gid) = (old.uid(), old.gid());
        if std::os::unix::fs::fchown(file, Some(uid), Some(gid)).is_err() {
            let _ = std::os::unix::fs::fchown(file, None, Some(gid));
        }
    }
    file.set_permissions(old.permissions())
}

/// Writes `bytes` over the existing file `target` in place (truncating it), then syncs it: the
/// fallback when its directory takes no temporary file.
fn write_in_place(target: &Path, bytes: &[u8]) -> io::Result<()> {
    let mut file = OpenOptions::new().write(true).truncate(true).open(target)?;
    file.write_all(bytes)?;
    file.flush()?;
    file.sync_all()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Names left by another writer (or a crashed run of a process with the same id) are
    /// skipped: the next free serial is taken, and the files already there are left untouched.
    #[test]
    fn temporary_names_already_taken_are_skipped() {
        let dir = std::env::temp_dir().join(format!("topomech-write-unit-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let next = TEMPORARY_SERIAL.load(std::sync::atomic::Ordering::Relaxed);
        let taken: Vec<PathBuf> = (next..next + 8).map(|s| temporary_name(&dir, s)).collect();
        for t in &taken {
            std::fs::write(t, b"left by someone else").unwrap();
        }
        let (tmp, file) = create_temporary(&dir, true).expect("a free name past the taken ones");
        drop(file);
        assert!(!taken.contains(&tmp), "{} was already taken", tmp.display());
        for t in &taken {
            assert_eq!(std::fs::read(t).unwrap(), b"left by someone else", "{} was overwritten", t.display());
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
