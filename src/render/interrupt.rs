//! SIGINT and SIGTERM during a render: the first one asks the render to stop at the next batch
//! boundary and write what it has (a resumable file where the output can hold one); a second
//! one ends the process at once, as users expect of a second Ctrl-C.
//!
//! signal-hook's flag handlers do only async-signal-safe work (atomic stores); everything else
//! happens on the render thread, which polls [`requested`] between batches.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, OnceLock};

#[cfg(unix)]
const SIGNALS: [i32; 2] = [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM];

struct Flags {
    /// Set by the first signal.
    requested: Arc<AtomicBool>,
    /// Which signal it was.
    signal: Arc<AtomicUsize>,
}

static FLAGS: OnceLock<Flags> = OnceLock::new();

fn flags() -> &'static Flags {
    FLAGS.get_or_init(|| Flags {
        requested: Arc::new(AtomicBool::new(false)),
        signal: Arc::new(AtomicUsize::new(0)),
    })
}

/// Installs the handlers (once; later calls do nothing) and returns the flag the render loop
/// polls ([`crate::render::StopRules::interrupted`]).
pub fn install() -> std::io::Result<&'static AtomicBool> {
    static INSTALLED: OnceLock<()> = OnceLock::new();
    let flags = flags();
    if INSTALLED.get().is_none() {
        #[cfg(unix)]
        for signal in SIGNALS {
            // The conditional shutdown is registered first, so it sees the flag as it was
            // before this delivery: only a second signal ends the process.
            signal_hook::flag::register_conditional_shutdown(
                signal,
                128 + signal,
                Arc::clone(&flags.requested),
            )?;
            signal_hook::flag::register_usize(signal, Arc::clone(&flags.signal), signal as usize)?;
            signal_hook::flag::register(signal, Arc::clone(&flags.requested))?;
        }
        let _ = INSTALLED.set(());
    }
    Ok(&flags.requested)
}

/// The signal received, if any: its number.
pub fn requested() -> Option<i32> {
    let flags = flags();
    flags
        .requested
        .load(Ordering::SeqCst)
        .then(|| flags.signal.load(Ordering::SeqCst) as i32)
}

/// "SIGINT", "SIGTERM" or "signal N", for messages.
pub fn name(signal: i32) -> String {
    match signal {
        2 => "SIGINT".into(),
        15 => "SIGTERM".into(),
        n => format!("signal {n}"),
    }
}

/// The conventional exit status after a signal: 128 + its number (130 for SIGINT, 143 for
/// SIGTERM).
pub fn exit_code(signal: i32) -> u8 {
    (128 + signal).clamp(0, 255) as u8
}

/// A render stopped by a signal, after writing what it had: the command line turns it into
/// exit code [`exit_code`].
#[derive(Debug, thiserror::Error)]
#[error("{message}")]
pub struct Interrupted {
    pub signal: i32,
    pub message: String,
}
