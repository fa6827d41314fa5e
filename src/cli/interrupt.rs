//! Ctrl-C and SIGTERM: the first one asks the run to stop once the files in flight are finished
//! (each output is renamed into place whole, or not at all, so none is left half-written); a
//! second one exits at once.
//!
//! It uses the `ctrlc` crate, whose handler runs on its own thread, so the handler may take a
//! lock and wake the watcher's channel; a raw signal handler could do neither.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

/// Set by the first signal.
static STOP: AtomicBool = AtomicBool::new(false);

type Waker = Box<dyn Fn() + Send>;

/// Called by the first signal, to wake a thread blocked on something other than `STOP`.
static WAKER: Mutex<Option<Waker>> = Mutex::new(None);

/// Exit status after a second signal, as shells report death by SIGINT.
const EXIT_INTERRUPTED: i32 = 130;

/// Installs the handler (once per process); failing to is not fatal, Ctrl-C then just kills.
pub fn install() {
    let _ = ctrlc::set_handler(|| {
        if STOP.swap(true, Ordering::SeqCst) {
            std::process::exit(EXIT_INTERRUPTED);
        }
        if let Some(wake) = WAKER.lock().ok().as_deref().and_then(Option::as_ref) {
            wake();
        }
    });
}

/// The flag the workers poll.
pub fn flag() -> &'static AtomicBool {
    &STOP
}

/// Whether a stop was asked for.
pub fn requested() -> bool {
    STOP.load(Ordering::SeqCst)
}

/// Runs `wake` when a stop is asked for (replacing any earlier one).
pub fn on_stop(wake: impl Fn() + Send + 'static) {
    if let Ok(mut w) = WAKER.lock() {
        *w = Some(Box::new(wake));
    }
}
