//! Atomic file output: write a temporary file in the target's directory,
//! then move it into place, so a failure never leaves a half-written file.

use crate::error::{Error, Result};
use std::io::Write as _;
use std::path::Path;

/// What to do when the target file exists already.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Existing {
    /// Replace it (atomically: readers see the old or the new file).
    Replace,
    /// Leave it and fail with [`std::io::ErrorKind::AlreadyExists`].
    Keep,
}

/// The steps [`persist_bytes`] names when one fails.
pub const CREATE: &str = "create the temporary file";
/// See [`CREATE`].
pub const WRITE: &str = "write the temporary file";
/// See [`CREATE`].
pub const MOVE: &str = "move the temporary file into place";

/// Write `bytes` to a temporary file in `dir` (synced), then move it to
/// `path`: the one atomic writer of the host. The error names the step that
/// failed ("create the temporary file", "write the temporary file", "move
/// the temporary file into place") with its I/O cause.
pub fn persist_bytes(
    dir: &Path,
    path: &Path,
    bytes: &[u8],
    existing: Existing,
) -> std::result::Result<(), (&'static str, std::io::Error)> {
    let mut tmp = tempfile::NamedTempFile::new_in(dir).map_err(|e| (CREATE, e))?;
    tmp.write_all(bytes)
        .and_then(|()| tmp.as_file().sync_all())
        .map_err(|e| (WRITE, e))?;
    match existing {
        Existing::Replace => tmp.persist(path).map(|_| ()),
        Existing::Keep => tmp.persist_noclobber(path).map(|_| ()),
    }
    .map_err(|e| (MOVE, e.error))
}

/// Write `bytes` to `path` atomically, replacing any file there: a
/// temporary file in the same directory, synced, then renamed.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    if path.file_name().is_none() {
        return Err(Error::InvalidArgument(format!(
            "{}: the path has no file name",
            path.display()
        )));
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    persist_bytes(dir, path, bytes, Existing::Replace).map_err(|(action, source)| Error::Io {
        action: match action {
            CREATE => "cannot create the temporary file",
            WRITE => "cannot write the temporary file",
            _ => "cannot move the temporary file into place",
        },
        path: path.to_path_buf(),
        source,
    })
}
