//! The viewer's denoised image (the D key): Open Image Denoise (src/image/denoise.rs) run on a
//! background thread over a snapshot of the accumulation, so the window stays responsive and
//! the progressive render goes on meanwhile. [`RefreshSchedule`] decides when to start one and
//! whether a finished one may be shown; it is pure, so it is tested without a window or OIDN.

use crate::image::aov::Aovs;
use crate::image::denoise::{self, Oidn};
use crate::image::output::Image;
use crate::render::Renderer;
use anyhow::Result;
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// The denoised image is refreshed at most this often (OIDN takes a good part of a second on a
/// 512² image on 2 cores, and the renderer needs those cores too).
pub const REFRESH_INTERVAL: Duration = Duration::from_millis(500);

/// A 1-spp preview is replaced next frame, or the next time the camera moves while it is
/// dragged: denoising one would be wasted work.
const MIN_SPP: u32 = 2;

/// Which accumulation an image shows: `generation` counts the restarts (camera moves, resets,
/// reloads, resizes), `spp` the samples since the last one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Snapshot {
    pub generation: u64,
    pub spp: u32,
}

/// When to denoise: only when the accumulation changed since the last denoise, at most every
/// `interval`, one at a time; a result for an older generation (another camera) is stale.
#[derive(Debug)]
pub struct RefreshSchedule {
    interval: Duration,
    last_start: Option<Instant>,
    last_snapshot: Option<Snapshot>,
    in_flight: bool,
}

impl RefreshSchedule {
    pub fn new(interval: Duration) -> RefreshSchedule {
        RefreshSchedule {
            interval,
            last_start: None,
            last_snapshot: None,
            in_flight: false,
        }
    }

    /// Whether a denoise of `current` should start at `now`.
    pub fn due(&self, now: Instant, current: Snapshot) -> bool {
        !self.in_flight
            && current.spp >= MIN_SPP
            && self.last_snapshot != Some(current)
            && self
                .last_start
                .is_none_or(|t| now.saturating_duration_since(t) >= self.interval)
    }

    /// A denoise of `snapshot` started at `now`.
    pub fn started(&mut self, now: Instant, snapshot: Snapshot) {
        self.in_flight = true;
        self.last_start = Some(now);
        self.last_snapshot = Some(snapshot);
    }

    /// The denoise of `done` finished: whether it may be shown, i.e. is of the accumulation
    /// of `current_generation` (anything older shows a camera or scene that is gone).
    pub fn finished(&mut self, done: Snapshot, current_generation: u64) -> bool {
        self.in_flight = false;
        done.generation == current_generation
    }
}

/// A finished denoise.
pub struct Denoised {
    pub snapshot: Snapshot,
    pub image: Image,
    pub seconds: f64,
}

/// What a frame learns from [`DenoisedView::update`].
pub enum Update {
    Nothing,
    /// A fresh denoised image of the current accumulation, to show from now on.
    Show(Denoised),
    /// A finished denoise of an older accumulation (or after D turned it off), thrown away.
    Stale(Snapshot),
    /// OIDN failed: denoising is off again, the raw image shown.
    Failed(anyhow::Error),
}

type Message = (Snapshot, Result<Denoised>);

/// The D key's state: on or off, the schedule, and the background denoises.
pub struct DenoisedView {
    on: bool,
    schedule: RefreshSchedule,
    results: (mpsc::Sender<Message>, mpsc::Receiver<Message>),
    /// The accumulation the shown denoised image is of; `None`: the raw image is shown.
    shown: Option<Snapshot>,
}

/// Denoises `color` with its AOVs, timed.
fn run(oidn: &Oidn, snapshot: Snapshot, color: &Image, aovs: &Aovs) -> Result<Denoised> {
    let started = Instant::now();
    let image = oidn.denoise(color, aovs)?;
    Ok(Denoised {
        snapshot,
        image,
        seconds: started.elapsed().as_secs_f64(),
    })
}

impl Default for DenoisedView {
    fn default() -> DenoisedView {
        DenoisedView {
            on: false,
            schedule: RefreshSchedule::new(REFRESH_INTERVAL),
            results: mpsc::channel(),
            shown: None,
        }
    }
}

impl DenoisedView {
    pub fn is_on(&self) -> bool {
        self.on
    }

    /// The accumulation the shown denoised image is of, while one is shown.
    pub fn shown(&self) -> Option<Snapshot> {
        self.shown
    }

    /// Turns denoising on (when OIDN loads; the error says why not) or off.
    pub fn toggle(&mut self) -> Result<bool> {
        if !self.on {
            denoise::oidn()?;
        }
        self.on = !self.on;
        // Results of a denoise started before are still received, and dropped as stale or
        // unwanted; a fresh schedule starts the first denoise at once.
        let in_flight = self.schedule.in_flight;
        self.schedule = RefreshSchedule::new(REFRESH_INTERVAL);
        self.schedule.in_flight = in_flight;
        self.shown = None;
        Ok(self.on)
    }

    /// Called each frame after the batch: takes a finished denoise, and starts the next one
    /// when it is due (reading the mean and AOVs back from `renderer`).
    pub fn update(&mut self, renderer: &mut dyn Renderer, current: Snapshot) -> Result<Update> {
        let update = match self.results.1.try_recv() {
            Ok(message) => self.receive(message, current),
            Err(_) => Update::Nothing,
        };
        if self
            .shown
            .is_some_and(|s| s.generation != current.generation)
        {
            self.shown = None;
        }
        let now = Instant::now();
        if self.on && self.schedule.due(now, current) {
            let oidn = denoise::oidn()?;
            let color = renderer.read_mean()?;
            let aovs = renderer.read_aovs()?;
            self.schedule.started(now, current);
            let sender = self.results.0.clone();
            std::thread::spawn(move || {
                let _ = sender.send((current, run(oidn, current, &color, &aovs)));
            });
        }
        Ok(update)
    }

    fn receive(&mut self, (snapshot, result): Message, current: Snapshot) -> Update {
        let fresh = self.schedule.finished(snapshot, current.generation);
        match result {
            // A failure is OIDN's (memory, an unsupported CPU): the raw image stays.
            Err(e) => {
                let was_on = std::mem::replace(&mut self.on, false);
                self.shown = None;
                if was_on {
                    Update::Failed(e)
                } else {
                    Update::Nothing
                }
            }
            Ok(denoised) if fresh && self.on => {
                self.shown = Some(snapshot);
                Update::Show(denoised)
            }
            Ok(_) => Update::Stale(snapshot),
        }
    }

    /// Waits (at most `limit`) for the running denoise, if any, and takes it as `update` does.
    /// Tests use it to see a background denoise land at a known frame.
    pub fn wait(&mut self, current: Snapshot, limit: Duration) -> Update {
        if !self.schedule.in_flight {
            return Update::Nothing;
        }
        match self.results.1.recv_timeout(limit) {
            Ok(message) => self.receive(message, current),
            Err(_) => Update::Nothing,
        }
    }

    /// A denoise of the current accumulation now, on this thread (saving what is shown).
    pub fn denoise_now(&self, renderer: &mut dyn Renderer, current: Snapshot) -> Result<Image> {
        let color = renderer.read_mean()?;
        let aovs = renderer.read_aovs()?;
        Ok(run(denoise::oidn()?, current, &color, &aovs)?.image)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: Duration = Duration::from_millis(1);

    fn snap(generation: u64, spp: u32) -> Snapshot {
        Snapshot { generation, spp }
    }

    #[test]
    fn refreshes_only_changed_accumulations_at_most_every_interval() {
        let t0 = Instant::now();
        let mut s = RefreshSchedule::new(500 * MS);
        assert!(!s.due(t0, snap(1, 1)), "a 1-spp preview is not denoised");
        assert!(s.due(t0, snap(1, 2)), "the first denoise starts at once");
        s.started(t0, snap(1, 2));
        assert!(!s.due(t0 + 600 * MS, snap(1, 8)), "one at a time");
        assert!(s.finished(snap(1, 2), 1));
        assert!(!s.due(t0 + 100 * MS, snap(1, 8)), "at most every 0.5 s");
        assert!(!s.due(t0 + 499 * MS, snap(1, 8)));
        assert!(s.due(t0 + 500 * MS, snap(1, 8)));
        s.started(t0 + 500 * MS, snap(1, 8));
        assert!(s.finished(snap(1, 8), 1));
        // Nothing new (the sample limit reached): no denoise, however long.
        assert!(!s.due(t0 + 10_000 * MS, snap(1, 8)));
        assert!(s.due(t0 + 10_000 * MS, snap(1, 9)));
    }

    #[test]
    fn a_result_for_an_older_camera_is_stale() {
        let t0 = Instant::now();
        let mut s = RefreshSchedule::new(500 * MS);
        s.started(t0, snap(3, 40));
        // The camera moved while OIDN ran: generation 4 now.
        assert!(!s.finished(snap(3, 40), 4));
        // Same spp count in the new generation is a new accumulation.
        assert!(s.due(t0 + 500 * MS, snap(4, 40)));
        assert!(!s.due(t0 + 499 * MS, snap(4, 40)));
    }
}
