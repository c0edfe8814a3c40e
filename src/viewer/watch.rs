//! Notices edits of the scene file, and of every file its last load read (meshes, `.mtl` and
//! `.bin` files, textures, the environment map: `input_file::recording_reads`), by polling
//! their modification times and lengths: one `stat` per file every [`POLL_INTERVAL`] at most,
//! no watcher thread and no new dependency. [`BackgroundLoad`] then reads the edited files on
//! a worker thread, so the event loop never waits for a file: whatever the
//! file turns into (a FIFO, a link to `/dev/zero`, a huge file, a stalled network mount), the
//! window keeps drawing.

use crate::input_file::{file_stamp, recording_reads, FileRead, FileStamp};
use crate::scene::model::{load_scene_or_model, ModelOptions};
use crate::scene::{Scene, SceneError};
use std::path::{Path, PathBuf};
use std::sync::mpsc::{self, Receiver, TryRecvError};
use std::time::{Duration, Instant};

/// How often the file is looked at; frequent enough to feel instant after a save.
const POLL_INTERVAL: Duration = Duration::from_millis(100);

/// A load's result and the files it read.
pub type Loaded = (Result<Scene, SceneError>, Vec<FileRead>);

/// Loads the scene (or model) file as the viewer does, recording the files the load read.
pub fn load_watched(path: &Path, model: &ModelOptions) -> Loaded {
    recording_reads(|| load_scene_or_model(path, model))
}

pub struct FileWatch {
    /// The scene file first, then what its last load read, each with the version last seen.
    files: Vec<(PathBuf, FileStamp)>,
    last_poll: Instant,
}

impl FileWatch {
    /// Watches the scene file `path`, taking its current version as seen.
    pub fn new(path: &Path) -> FileWatch {
        FileWatch {
            files: vec![(path.to_owned(), file_stamp(path))],
            last_poll: Instant::now(),
        }
    }

    /// Watches what a load read, at the versions it read. After a good load these are the
    /// files; after a failed one they join the files watched (the last good scene's stay, and
    /// the file that broke the load is watched for its fix).
    pub fn adopt(&mut self, reads: Vec<FileRead>, load_succeeded: bool) {
        if load_succeeded {
            self.files.truncate(1);
        }
        for (path, stamp) in reads {
            match self.files.iter_mut().find(|(p, _)| *p == path) {
                Some(file) => file.1 = stamp,
                None => self.files.push((path, stamp)),
            }
        }
    }

    /// Whether a watched file changed since the last call that said so; polls at most every
    /// [`POLL_INTERVAL`] unless `now` is set.
    pub fn changed(&mut self, now: bool) -> bool {
        if !now && self.last_poll.elapsed() < POLL_INTERVAL {
            return false;
        }
        self.last_poll = Instant::now();
        let mut changed = false;
        for (path, seen) in &mut self.files {
            let current = file_stamp(path);
            // A file that vanished (an editor's rename dance) is reported when it is back.
            if current.is_some() && current != *seen {
                *seen = current;
                changed = true;
            }
        }
        changed
    }

    /// How many files are watched (the scene file included).
    pub fn file_count(&self) -> usize {
        self.files.len()
    }
}

/// Loads the scene file on a worker thread, one load at a time.
pub struct BackgroundLoad {
    path: PathBuf,
    /// How a model file becomes a scene (a scene file ignores it).
    model: ModelOptions,
    in_flight: Option<Receiver<Loaded>>,
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
            let _ = send.send(load_watched(&path, &model));
        });
        self.in_flight = Some(receive);
    }

    /// The result of the load in flight, once it is done; never waits.
    pub fn poll(&mut self) -> Option<Loaded> {
        let receiver = self.in_flight.as_ref()?;
        let result = match receiver.try_recv() {
            Ok(result) => result,
            Err(TryRecvError::Empty) => return None,
            Err(TryRecvError::Disconnected) => (
                Err(SceneError {
                    path: self.path.clone(),
                    position: None,
                    field: None,
                    message: "the scene loader stopped unexpectedly".into(),
                }),
                Vec::new(),
            ),
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

    /// The files a load read are watched with the scene file: an edited texture is an edit,
    /// also after a load that failed on it.
    #[test]
    fn an_edited_texture_is_an_edit_of_the_scene() {
        let dir = tempfile::tempdir().unwrap();
        let scene = dir.path().join("s.toml");
        let texture = dir.path().join("t.png");
        std::fs::write(
            &scene,
            "[camera]\neye = [0, 0, -5]\ntarget = [0, 0, 0]\nup = [0, 1, 0]\nvfov = 40\n\
             [render]\nwidth = 4\nheight = 4\nspp = 1\nmax_bounces = 1\n\
             [materials.m]\ntype = \"diffuse\"\ncolor = { texture = \"t.png\" }\n\
             [[spheres]]\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n",
        )
        .unwrap();
        let write_png = |grey: u8| {
            image::GrayImage::from_pixel(2, 2, image::Luma([grey]))
                .save(&texture)
                .unwrap()
        };
        write_png(100);
        let mut w = FileWatch::new(&scene);
        let (result, reads) = load_watched(&scene, &ModelOptions::default());
        result.unwrap();
        assert_eq!(reads.len(), 2, "{reads:?}");
        w.adopt(reads, true);
        assert_eq!(w.file_count(), 2);
        assert!(!w.changed(true));
        // File times can be coarse: a new length is a new version whatever the clock says.
        std::fs::write(&texture, b"not an image").unwrap();
        assert!(w.changed(true));
        assert!(!w.changed(true));
        // The broken texture fails the load; its fix is an edit too.
        let (result, reads) = load_watched(&scene, &ModelOptions::default());
        assert!(result.is_err());
        w.adopt(reads, false);
        write_png(200);
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
        let e = result.0.unwrap_err().to_string();
        assert!(e.contains("FIFO"), "{e}");
        assert!(!load.busy());
    }
}
