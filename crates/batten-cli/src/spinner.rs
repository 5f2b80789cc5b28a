//! A spinner for one long command (`fair`, `analyze` on 10⁶ points and more): drawn on stderr
//! only when stderr is a terminal and only once the work has taken [`SHOW_AFTER`], so that
//! quick runs and pipes see nothing.

use std::io::IsTerminal as _;
use std::sync::mpsc::{self, RecvTimeoutError, Sender};
use std::thread::JoinHandle;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// How long the work runs before the spinner appears.
pub const SHOW_AFTER: Duration = Duration::from_secs(1);
/// Redraw interval of a visible spinner.
const TICK: Duration = Duration::from_millis(120);

/// A running spinner; dropping it (or [`Spinner::finish`]) clears it.
#[derive(Debug)]
pub struct Spinner {
    done: Option<Sender<()>>,
    thread: Option<JoinHandle<()>>,
}

impl Spinner {
    /// Start the clock for a spinner showing `message` (nothing at all off a terminal).
    pub fn start(message: String) -> Spinner {
        if !std::io::stderr().is_terminal() {
            return Spinner {
                done: None,
                thread: None,
            };
        }
        let (done, wait) = mpsc::channel::<()>();
        let thread = std::thread::spawn(move || {
            if wait.recv_timeout(SHOW_AFTER) != Err(RecvTimeoutError::Timeout) {
                return; // finished (or dropped) in time
            }
            let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
            if let Ok(style) = ProgressStyle::with_template("{spinner} {msg} [{elapsed}]") {
                bar.set_style(style);
            }
            bar.set_message(message);
            bar.enable_steady_tick(TICK);
            let _ = wait.recv();
            bar.finish_and_clear();
        });
        Spinner {
            done: Some(done),
            thread: Some(thread),
        }
    }

    /// Clear the spinner (waits for it to be erased, so that later lines start clean).
    pub fn finish(self) {}
}

impl Drop for Spinner {
    fn drop(&mut self) {
        if let Some(done) = self.done.take() {
            let _ = done.send(());
        }
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}
