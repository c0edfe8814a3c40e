//! Notices edits of the scene file by polling its modification time and length: one `stat`
//! a frame at most, no watcher thread and no new dependency. [`BackgroundLoad`] then reads
//! the edited file on a worker thread, so the event loop never waits for a file: whatever the
//! file turns into (a FIFO, a link to `/dev/zero`, a huge file, a stalled network mount), the
//! window keeps drawing.

use crate::scene::model::{load_scene_or_model, ModelOptions};
use crate::scene::{Scene, SceneError};
use std::path::{Path, PathBuf};
use std::sync::mpsc::{self, Receiver, TryRecvError};
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

/// Loads the scene file on a worker thread, one load at a time.
pub struct BackgroundLoad {
    path: PathBuf,
    /// How a model file becomes a scene (a scene file ignores it).
    model: ModelOptions,
    in_flight: Option<Receiver<Result<Scene, SceneError>>>,
    /// Another edit came while a load was in flight: load again when it is done.
    wanted: bool,
}

impl BackgroundLoad {
    pub fn new(path: &Path) -> BackgroundLoad {
        BackgroundLoad {
            path: path.to_owned(),
            model: ModelOptions::default(),
            in_flight: None,
            wanted: false,
        }
    }

    /// Loads a model file with these options.
    pub fn with_model(mut self, model: ModelOptions) -> BackgroundLoad {
        self.model = model;
        self
    }

    /// Asks for a load of the file as it is now.
    pub fn request(&mut self) {
        self.wanted = true;
        self.start_if_idle();
    }

    fn start_if_idle(&mut self) {
        if self.in_flight.is_some() || !self.wanted {
            return;
        }
        self.wanted = false;
        let (send, receive) = mpsc::channel();
        let path = self.path.clone();
        let model = self.model.clone();
        std::thread::spawn(move || {
            // The viewer may have moved on (or quit) by the time the load ends.
            let _ = send.send(load_scene_or_model(&path, &model));
        });
        self.in_flight = Some(receive);
    }

    /// The result of the load in flight, once it is done; never waits.
    pub fn poll(&mut self) -> Option<Result<Scene, SceneError>> {
        let receiver = self.in_flight.as_ref()?;
        let result = match receiver.try_recv() {
            Ok(result) => result,
            Err(TryRecvError::Empty) => return None,
            Err(TryRecvError::Disconnected) => Err(SceneError {
                path: self.path.clone(),
                position: None,
                field: None,
                message: "the scene loader stopped unexpectedly".into(),
            }),
        };
        self.in_flight = None;
        self.start_if_idle();
        Some(result)
    }

    /// Whether a load is running or asked for.
    pub fn busy(&self) -> bool {
        self.in_flight.is_some() || self.wanted
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

    /// A FIFO with no writer would block a plain open() for ever; the load must fail at once.
    #[cfg(unix)]
    #[test]
    fn a_fifo_in_place_of_the_scene_is_refused_without_blocking() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.toml");
        let c_path = std::ffi::CString::new(path.to_str().unwrap()).unwrap();
        assert_eq!(unsafe { libc::mkfifo(c_path.as_ptr(), 0o600) }, 0);
        let mut load = BackgroundLoad::new(&path);
        load.request();
        let deadline = Instant::now() + Duration::from_secs(10);
        let result = loop {
            if let Some(result) = load.poll() {
                break result;
            }
            assert!(Instant::now() < deadline, "the load of a FIFO did not end");
            std::thread::sleep(Duration::from_millis(5));
        };
        let e = result.unwrap_err().to_string();
        assert!(e.contains("FIFO"), "{e}");
        assert!(!load.busy());
    }
}
