//! A spinner for one long command (`fair`, `analyze` on 10⁶ points and more): drawn on stderr
//! only when stderr is a terminal and only once the work has taken [`SHOW_AFTER`], so that
//! quick runs and pipes see nothing.

use std::io::IsTerminal as _;
use std::sync::mpsc::{self, RecvTimeoutError, Sender};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// How long the work runs before the spinner appears.
pub const SHOW_AFTER: Duration = Duration::from_secs(1);
/// Redraw interval of a visible spinner.
const TICK: Duration = Duration::from_millis(120);

/// What the spinner's thread is told.
enum Signal {
    /// Show this message from now on.
    Message(String),
    /// The work is done: clear the spinner.
    Done,
}

/// A running spinner; dropping it (or [`Spinner::finish`]) clears it.
#[derive(Debug)]
pub struct Spinner {
    signals: Option<Sender<Signal>>,
    thread: Option<JoinHandle<()>>,
}

impl Spinner {
    /// Start the clock for a spinner showing `message` (nothing at all off a terminal).
    pub fn start(message: String) -> Spinner {
        if !std::io::stderr().is_terminal() {
            return Spinner {
                signals: None,
                thread: None,
            };
        }
        let (signals, wait) = mpsc::channel::<Signal>();
        let thread = std::thread::spawn(move || {
            let show_at = Instant::now() + SHOW_AFTER;
            let mut message = message;
            loop {
                match wait.recv_timeout(show_at.saturating_duration_since(Instant::now())) {
                    Ok(Signal::Message(m)) => message = m,
                    Err(RecvTimeoutError::Timeout) => break,
                    // Finished (or dropped) in time.
                    Ok(Signal::Done) | Err(RecvTimeoutError::Disconnected) => return,
                }
            }
            let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
            if let Ok(style) = ProgressStyle::with_template("{spinner} {msg} [{elapsed}]") {
                bar.set_style(style);
            }
            bar.set_message(message);
            bar.enable_steady_tick(TICK);
            while let Ok(Signal::Message(m)) = wait.recv() {
                bar.set_message(m);
            }
            bar.finish_and_clear();
        });
        Spinner {
            signals: Some(signals),
            thread: Some(thread),
        }
    }

    /// Show `message` from now on (the clock keeps running: a long read followed by a long
    /// computation shows one spinner after [`SHOW_AFTER`], not one per step).
    pub fn set_message(&self, message: String) {
        if let Some(signals) = &self.signals {
            let _ = signals.send(Signal::Message(message));
        }
    }

    /// Clear the spinner (waits for it to be erased, so that later lines start clean).
    pub fn finish(self) {}
}

impl Drop for Spinner {
    fn drop(&mut self) {
        if let Some(signals) = self.signals.take() {
            let _ = signals.send(Signal::Done);
        }
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}
