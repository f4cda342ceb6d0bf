//! The library's one outlet for lines meant for a person: results a program shows, progress of a long run, and
//! warnings. Library modules call [`emit`] instead of printing, so that whoever embeds the library (a program, a
//! test, a GUI) decides where those lines go with [`set_sink`]; by default they go where they always went: stdout
//! for [`Channel::Out`], stderr for the others, with the text unchanged.
//!
//! The sink is process-global: the lines come from deep inside runs and searches, and threading a writer through
//! every call would touch every signature on the way for the sake of a few messages.

use std::sync::{PoisonError, RwLock};

/// Where a line is meant to go; the sink decides what that means.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Channel {
    /// A result a program shows its user (the default sink writes it to stdout).
    Out,
    /// A progress line of a long computation (the default sink writes it to stderr).
    Progress,
    /// A warning, whose text already carries any `warning: ` prefix: the sink adds none (the default sink writes it
    /// to stderr).
    Warning,
}

/// A receiver of the library's lines: the channel and the line, without its trailing newline.
pub type Sink = Box<dyn Fn(Channel, &str) + Send + Sync>;

/// The sink set by [`set_sink`]; `None` means [`default_sink`].
static SINK: RwLock<Option<Sink>> = RwLock::new(None);

/// Hands one line to the sink: [`default_sink`] unless [`set_sink`] chose another. `line` has no trailing newline.
///
/// A sink must not call `emit` itself (it would wait on the lock it is called under when a [`set_sink`] is pending).
pub fn emit(channel: Channel, line: &str) {
    // A sink that panicked leaves the lock poisoned; the lines after it still deserve an outlet.
    let sink = SINK.read().unwrap_or_else(PoisonError::into_inner);
    match sink.as_ref() {
        Some(sink) => sink(channel, line),
        None => default_sink(channel, line),
    }
}

/// Routes every later [`emit`] to `sink`, replacing the one before.
pub fn set_sink(sink: impl Fn(Channel, &str) + Send + Sync + 'static) {
    *SINK.write().unwrap_or_else(PoisonError::into_inner) = Some(Box::new(sink));
}

/// Goes back to [`default_sink`].
pub fn reset_sink() {
    *SINK.write().unwrap_or_else(PoisonError::into_inner) = None;
}

/// The sink in place until [`set_sink`]: [`Channel::Out`] to stdout, the others to stderr, each line followed by a
/// newline. A custom sink may forward the lines it does not want to this one.
///
/// This is the only place in the library that writes to stdout or stderr: it is the outlet, not a module printing
/// on its own account.
pub fn default_sink(channel: Channel, line: &str) {
    match channel {
        Channel::Out => println!("{line}"),
        Channel::Progress | Channel::Warning => eprintln!("{line}"),
    }
}

/// A simulated time (s) for a line a person reads (progress, `done:`): six significant digits, so that an adaptive
/// step's time (`48234.652155108546`) prints as `48234.7` and a time made of steps (`3 × 1.1` = 3.3000000000000003)
/// as `3.3`; a whole time prints whole, without decimals (`120`, `1234567`). The files keep every digit.
pub fn fmt_time(t: f64) -> String {
    if !t.is_finite() {
        return format!("{t}");
    }
    let whole = t.round();
    if (t - whole).abs() <= 1e-9 * whole.abs().max(1.0) {
        return format!("{}", whole + 0.0);
    }
    let r: f64 = format!("{t:.5e}").parse().unwrap_or(t);
    format!("{}", r + 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::RefCell;

    thread_local! {
        static SEEN: RefCell<Vec<(Channel, String)>> = const { RefCell::new(Vec::new()) };
    }

    /// A custom sink receives each emitted line with its channel, and the default comes back after
    /// [`reset_sink`]. The sink is process-global and other tests may emit meanwhile from their own threads: it
    /// records only this thread's lines carrying a marker and forwards everything else to the default.
    #[test]
    fn a_custom_sink_receives_channel_and_line() {
        const MARK: &str = "messages-sink-test-7f3a";
        set_sink(|channel, line| {
            if line.contains(MARK) {
                SEEN.with(|s| s.borrow_mut().push((channel, line.to_string())));
            } else {
                default_sink(channel, line);
            }
        });
        emit(Channel::Out, &format!("{MARK} result"));
        emit(Channel::Progress, &format!("{MARK} 50%"));
        emit(Channel::Warning, &format!("warning: {MARK}"));
        let from_another_thread = std::thread::spawn(|| {
            emit(Channel::Out, &format!("{MARK} elsewhere"));
            SEEN.with(|s| s.borrow().len())
        })
        .join()
        .unwrap();
        reset_sink();
        // After the reset the line goes to stderr, not to the recorder.
        emit(Channel::Progress, &format!("{MARK} after reset"));
        let seen = SEEN.with(|s| s.borrow().clone());
        assert_eq!(
            seen,
            vec![
                (Channel::Out, format!("{MARK} result")),
                (Channel::Progress, format!("{MARK} 50%")),
                (Channel::Warning, format!("warning: {MARK}")),
            ]
        );
        // The sink ran in the emitting thread, which recorded the line there.
        assert_eq!(from_another_thread, 1);
    }
}
