//! Reading a file the user names (a scene, and later meshes and images) without trusting it to
//! be one: only a regular file is read, and only up to a size limit, so a FIFO cannot block
//! (the viewer's reload would freeze its window), and `/dev/zero` or a runaway file cannot
//! fill the memory.
//!
//! The file is opened non-blocking (opening a FIFO with no writer would otherwise wait
//! forever), then the opened file itself is checked, so a file swapped between a check and
//! the open cannot slip through.

use std::cell::RefCell;
use std::fs::File;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::time::SystemTime;

/// One version of a file: its modification time and length; `None` where it could not be
/// opened (missing, or mid-save).
pub type FileStamp = Option<(SystemTime, u64)>;

/// A file a load asked for, and the version it found.
pub type FileRead = (PathBuf, FileStamp);

thread_local! {
    /// The files [`read_regular_file`] was asked for on this thread since
    /// [`recording_reads`] began, when it is running.
    static RECORDED_READS: RefCell<Option<Vec<FileRead>>> = const { RefCell::new(None) };
}

/// Runs `load` and returns, with its result, every file [`read_regular_file`] was asked for
/// on this thread meanwhile (the scene file, meshes, `.mtl` and `.bin` files, images), each
/// once, with the version it found: the viewer watches them all for edits.
pub fn recording_reads<T>(load: impl FnOnce() -> T) -> (T, Vec<FileRead>) {
    let outer = RECORDED_READS.with(|r| r.replace(Some(Vec::new())));
    let result = load();
    let reads = RECORDED_READS
        .with(|r| r.replace(outer))
        .unwrap_or_default();
    (result, reads)
}

fn record_read(path: &Path, stamp: FileStamp) {
    RECORDED_READS.with(|r| {
        if let Some(reads) = r.borrow_mut().as_mut() {
            match reads.iter_mut().find(|(p, _)| p == path) {
                Some(read) => read.1 = stamp,
                None => reads.push((path.to_owned(), stamp)),
            }
        }
    });
}

/// The version of `path` on disk now.
pub fn file_stamp(path: &Path) -> FileStamp {
    let meta = std::fs::metadata(path).ok()?;
    Some((meta.modified().ok()?, meta.len()))
}

/// Largest scene file glint reads: far above any hand-written scene (the 700-quad test scene
/// is 60 KiB; 64 MiB is about 600,000 quads), small enough to parse in seconds.
pub const SCENE_FILE_LIMIT: u64 = 64 << 20;

/// Largest image file (`glint compare`'s EXR inputs): an uncompressed float RGBA EXR of the
/// largest image glint renders (2²³ pixels) is 128 MiB.
pub const IMAGE_FILE_LIMIT: u64 = 256 << 20;

/// Largest mesh file (OBJ, PLY, glTF; also an OBJ's .mtl): about 20 million triangles as a
/// binary PLY, far more than one GPU storage binding of 128 MiB holds (2.8 million), and it
/// still fits in memory beside the scene built from it.
pub const MESH_FILE_LIMIT: u64 = 1 << 30;

/// `bytes` as a short human figure ("64 MiB").
pub fn format_size(bytes: u64) -> String {
    const UNITS: [&str; 4] = ["bytes", "KiB", "MiB", "GiB"];
    let mut value = bytes;
    let mut unit = 0;
    while unit + 1 < UNITS.len() && value >= 1024 && value.is_multiple_of(1024) {
        value /= 1024;
        unit += 1;
    }
    format!("{value} {}", UNITS[unit])
}

#[cfg(unix)]
fn open_without_blocking(path: &Path) -> std::io::Result<File> {
    use std::os::unix::fs::OpenOptionsExt;
    std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK)
        .open(path)
}

#[cfg(not(unix))]
fn open_without_blocking(path: &Path) -> std::io::Result<File> {
    File::open(path)
}

/// The bytes of `path` if it is a regular file of at most `limit` bytes. The error is a
/// sentence without the path (callers put the path and line in front): "cannot read the
/// file: …", "not a regular file (a FIFO)", "the file is 80 MiB; the limit is 64 MiB".
/// `what` names the kind of file in messages ("scene file").
pub fn read_regular_file(path: &Path, limit: u64, what: &str) -> Result<Vec<u8>, String> {
    let file = open_without_blocking(path).map_err(|e| {
        record_read(path, None);
        format!("cannot read the {what}: {e}")
    })?;
    let meta = file.metadata().map_err(|e| {
        record_read(path, None);
        format!("cannot read the {what}: {e}")
    })?;
    // The version of the file opened, not of one swapped in later.
    record_read(path, meta.modified().ok().map(|m| (m, meta.len())));
    if !meta.is_file() {
        return Err(format!(
            "cannot read the {what}: it is {}, not a regular file",
            describe_file_type(&meta)
        ));
    }
    let too_big = || {
        format!(
            "the {what} is larger than glint's limit of {} for it",
            format_size(limit)
        )
    };
    if meta.len() > limit {
        return Err(too_big());
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    // The file may grow while it is read: never read more than one byte past the limit.
    file.take(limit + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("cannot read the {what}: {e}"))?;
    if bytes.len() as u64 > limit {
        return Err(too_big());
    }
    Ok(bytes)
}

fn describe_file_type(meta: &std::fs::Metadata) -> &'static str {
    if meta.is_dir() {
        return "a folder";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let t = meta.file_type();
        if t.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    "a special file"
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_read_as_people_write_them() {
        assert_eq!(format_size(SCENE_FILE_LIMIT), "64 MiB");
        assert_eq!(format_size(1000), "1000 bytes");
        assert_eq!(format_size(2048), "2 KiB");
    }

    #[test]
    fn reads_a_regular_file_within_the_limit_only() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.toml");
        std::fs::write(&path, b"12345").unwrap();
        assert_eq!(read_regular_file(&path, 5, "scene file").unwrap(), b"12345");
        let e = read_regular_file(&path, 4, "scene file").unwrap_err();
        assert!(e.contains("limit of 4 bytes"), "{e}");
        let e = read_regular_file(dir.path(), 100, "scene file").unwrap_err();
        assert!(e.contains("a folder"), "{e}");
    }

    #[cfg(unix)]
    #[test]
    fn refuses_devices_at_once() {
        let e = read_regular_file(Path::new("/dev/zero"), 100, "scene file").unwrap_err();
        assert!(e.contains("character device"), "{e}");
    }
}
