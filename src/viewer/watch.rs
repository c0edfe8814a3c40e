//! Notices edits of the scene file by polling its modification time and length: one `stat`
//! a frame at most, no watcher thread and no new dependency.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant, SystemTime};

/// How often the file is looked at; frequent enough to feel instant after a save.
const POLL_INTERVAL: Duration = Duration::from_millis(100);

/// What identifies one version of the file; `None` while it cannot be read (mid-save).
type Stamp = Option<(SystemTime, u64)>;

pub struct FileWatch {
    path: PathBuf,
    seen: Stamp,
    last_poll: Instant,
}

fn stamp(path: &Path) -> Stamp {
    let meta = std::fs::metadata(path).ok()?;
    Some((meta.modified().ok()?, meta.len()))
}

impl FileWatch {
    /// Watches `path`, taking its current version as seen.
    pub fn new(path: &Path) -> FileWatch {
        FileWatch {
            path: path.to_owned(),
            seen: stamp(path),
            last_poll: Instant::now(),
        }
    }

    /// Whether the file changed since the last call that said so; polls at most every
    /// [`POLL_INTERVAL`] unless `now` is set.
    pub fn changed(&mut self, now: bool) -> bool {
        if !now && self.last_poll.elapsed() < POLL_INTERVAL {
            return false;
        }
        self.last_poll = Instant::now();
        let current = stamp(&self.path);
        // A file that vanished (an editor's rename dance) is reported when it is back.
        if current.is_none() || current == self.seen {
            return false;
        }
        self.seen = current;
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reports_each_edit_once() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.toml");
        std::fs::write(&path, "a").unwrap();
        let mut w = FileWatch::new(&path);
        assert!(!w.changed(true));
        std::fs::write(&path, "bb").unwrap();
        assert!(w.changed(true));
        assert!(!w.changed(true));
        std::fs::remove_file(&path).unwrap();
        assert!(!w.changed(true));
        std::fs::write(&path, "ccc").unwrap();
        assert!(w.changed(true));
    }
}
