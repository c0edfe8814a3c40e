//! Writing a file so that readers see the old version or the new one, never half of one: a
//! temporary file next to the target, then a rename over it.
//!
//! - A symbolic link is written through: the new file replaces the link's target (the temporary
//!   file lives in the target's folder, so the rename stays on one file system) and the link
//!   stays a link.
//! - A file that exists keeps its permission bits (a 0600 image stays 0600); a new one gets
//!   0644 less the umask, as any program's new file.
//! - When the encoder fails because the disk did (full, gone), the error is the I/O error
//!   itself, not the encoder's wrapping of it (the image crate calls every EXR failure
//!   "decoding").
//! - On any failure the temporary file is removed.

use crate::image::output_check::resolve_output_target;
use anyhow::{anyhow, Context, Result};
use std::fs::File;
use std::io::{self, BufWriter, Seek, SeekFrom, Write};
use std::path::Path;

/// A writer that remembers the first I/O error it passed on.
pub struct ErrorRecorder<W> {
    inner: W,
    first_error: Option<io::Error>,
}

impl<W> ErrorRecorder<W> {
    pub fn new(inner: W) -> ErrorRecorder<W> {
        ErrorRecorder {
            inner,
            first_error: None,
        }
    }

    /// The first error the inner writer returned, if any.
    pub fn take_error(&mut self) -> Option<io::Error> {
        self.first_error.take()
    }

    fn record<T>(&mut self, result: io::Result<T>) -> io::Result<T> {
        if let Err(e) = &result {
            if self.first_error.is_none() {
                self.first_error = Some(io::Error::new(e.kind(), e.to_string()));
            }
        }
        result
    }
}

impl<W: Write> Write for ErrorRecorder<W> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let result = self.inner.write(buf);
        self.record(result)
    }

    fn flush(&mut self) -> io::Result<()> {
        let result = self.inner.flush();
        self.record(result)
    }
}

impl<W: Seek> Seek for ErrorRecorder<W> {
    fn seek(&mut self, pos: SeekFrom) -> io::Result<u64> {
        let result = self.inner.seek(pos);
        self.record(result)
    }
}

/// The writer an encoder gets.
pub type EncodeWriter<'a> = BufWriter<ErrorRecorder<&'a File>>;

/// Runs `encode` on a buffered writer over `sink` and flushes it. An I/O error of the sink wins
/// over the encoder's own message; other encoder failures are "cannot encode".
pub fn encode_into<E: std::fmt::Display>(
    sink: &File,
    path: &Path,
    encode: impl FnOnce(&mut EncodeWriter<'_>) -> Result<(), E>,
) -> Result<()> {
    let mut writer = BufWriter::new(ErrorRecorder::new(sink));
    let encoded = encode(&mut writer);
    let flushed = writer.flush();
    let io_error = writer
        .into_inner()
        .map_err(|e| e.into_error())
        .map(|mut recorder| recorder.take_error());
    let io_error = match io_error {
        Ok(recorded) => recorded,
        Err(e) => Some(e),
    };
    if let Some(e) = io_error {
        return Err(anyhow!("cannot write {}: {e}", path.display()));
    }
    match (encoded, flushed) {
        (Err(e), _) => Err(anyhow!("cannot encode {}: {e}", path.display())),
        (Ok(()), Err(e)) => Err(anyhow!("cannot write {}: {e}", path.display())),
        (Ok(()), Ok(())) => Ok(()),
    }
}

/// Writes `path` atomically with what `encode` writes; see the module documentation.
pub fn write_atomically<E: std::fmt::Display>(
    path: &Path,
    encode: impl FnOnce(&mut EncodeWriter<'_>) -> Result<(), E>,
) -> Result<()> {
    write_atomically_with(path, |tmp, _| encode_into(tmp, path, encode))
}

/// The same for an encoder that writes a file by its path: it gets the temporary file's path
/// and must write that file in place (open, truncate, write). Its errors are reported as it
/// words them.
pub fn write_atomically_via_path(
    path: &Path,
    encode: impl FnOnce(&Path) -> Result<()>,
) -> Result<()> {
    write_atomically_with(path, |_, tmp_path| encode(tmp_path))
}

fn write_atomically_with(
    path: &Path,
    encode: impl FnOnce(&File, &Path) -> Result<()>,
) -> Result<()> {
    let target = resolve_output_target(path).map_err(anyhow::Error::msg)?;
    let folder = target.parent().unwrap_or(Path::new("/"));
    let existing_permissions = std::fs::metadata(&target)
        .ok()
        .filter(|m| m.is_file())
        .map(|m| m.permissions());
    let mut builder = tempfile::Builder::new();
    builder.prefix(".glint-").suffix(".tmp");
    // tempfile's default is 0600; a new image is an ordinary file (the umask still applies).
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o644));
    let tmp = builder
        .tempfile_in(folder)
        .with_context(|| format!("cannot create a temporary file in {}", folder.display()))?;
    encode(tmp.as_file(), tmp.path())?;
    if let Some(permissions) = existing_permissions {
        tmp.as_file()
            .set_permissions(permissions)
            .with_context(|| format!("cannot set the permissions of {}", path.display()))?;
    }
    tmp.as_file()
        .sync_all()
        .with_context(|| format!("cannot write {}", path.display()))?;
    tmp.persist(&target)
        .with_context(|| format!("cannot write {}", path.display()))?;
    Ok(())
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;
    use std::os::unix::fs::PermissionsExt;

    #[test]
    fn a_path_encoder_keeps_the_mode_and_leaves_no_temporary_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.bin");
        std::fs::write(&path, b"old").unwrap();
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o600)).unwrap();
        write_atomically_via_path(&path, |tmp| Ok(std::fs::write(tmp, b"new")?)).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
        let mode = std::fs::metadata(&path).unwrap().permissions().mode();
        assert_eq!(mode & 0o777, 0o600);
        let failed = write_atomically_via_path(&path, |_| Err(anyhow!("encoder failed")));
        assert!(failed.is_err());
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}
