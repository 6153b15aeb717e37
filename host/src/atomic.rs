//! Atomic file output: write a temporary file in the target's directory,
//! then move it into place, so a failure never leaves a half-written file.

use crate::error::{Error, Result};
use std::io::Write as _;
use std::path::Path;

/// Write `bytes` to `path` atomically (a [`tempfile::NamedTempFile`] in the
/// same directory, synced, then persisted over `path`). The directory must
/// exist. On failure the temporary file is removed.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let io = |action: &'static str| {
        move |source: std::io::Error| Error::Io {
            action,
            path: path.to_path_buf(),
            source,
        }
    };
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
    let mut tmp =
        tempfile::NamedTempFile::new_in(dir).map_err(io("cannot create the temporary file"))?;
    tmp.write_all(bytes)
        .and_then(|()| tmp.as_file().sync_all())
        .map_err(io("cannot write the temporary file"))?;
    tmp.persist(path)
        .map_err(|e| io("cannot move the temporary file into place")(e.error))?;
    Ok(())
}
