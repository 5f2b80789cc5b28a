//! Ending on SIGINT, SIGTERM or SIGHUP without leaving anything half-written.
//!
//! Every output is written atomically through a hidden temporary file beside its target
//! (`batten::io::write_atomic`). When a signal arrives the handler (on a thread of its own,
//! from `ctrlc`) removes those temporaries, refuses new ones, runs the command's last word
//! (a batch writes the summary of the files that finished, marked incomplete), prints one
//! line and ends the process with `128 + 2`, the shell's code for an interrupt. A target is
//! never left partial: it is the old file or the new one. A closed pipe needs no handler:
//! Rust ignores SIGPIPE, and a write to a closed stdout is an error the command handles.

use std::sync::Mutex;

use crate::output;

/// The exit code after a signal (128 + SIGINT).
pub const EXIT_INTERRUPTED: i32 = 130;

/// What a command still writes when it is interrupted; returns a note for the user.
type LastWord = Box<dyn FnOnce() -> Option<String> + Send>;

static LAST_WORD: Mutex<Option<LastWord>> = Mutex::new(None);

/// Install the handler. Without one (the platform refused) the signal ends the process as
/// before; that is reported as a failure to install nothing, so it is ignored.
pub fn install() {
    let _ = ctrlc::set_handler(on_signal);
}

/// Set what an interrupted command still writes (replacing any earlier one).
pub fn set_last_word(f: impl FnOnce() -> Option<String> + Send + 'static) {
    *LAST_WORD.lock().unwrap_or_else(|e| e.into_inner()) = Some(Box::new(f));
}

/// Clear the last word once the command has written everything itself.
pub fn clear_last_word() {
    *LAST_WORD.lock().unwrap_or_else(|e| e.into_inner()) = None;
}

fn on_signal() {
    let removed = batten::io::remove_temporaries();
    let last = LAST_WORD.lock().unwrap_or_else(|e| e.into_inner()).take();
    let note = last.and_then(|f| f());
    let mut line = String::from("interrupted");
    if removed > 0 {
        line.push_str(&format!(
            "; removed {} of unfinished writes",
            output::count(removed, "temporary file")
        ));
    }
    if let Some(n) = note {
        line.push_str("; ");
        line.push_str(&n);
    }
    output::error_line(&line);
    std::process::exit(EXIT_INTERRUPTED);
}
