//! Lines for the user on stdout and stderr, written without panicking.
//!
//! `println!` and `eprintln!` panic when the write fails (stdout on a full device, stderr
//! into a file on a full disk), which ends a command with a backtrace and, in a simulation,
//! loses the run's summary. Here a failed write is remembered instead: the stream and the
//! cause ([`failure`]), later lines to that stream are dropped, and the command ends with
//! an error naming both and a non-zero exit. A run in progress stops at its next step when
//! it sees a failure (with a checkpoint, as on Ctrl-C).
//!
//! A closed pipe (`sphrepro list | head`) is not a failure here: SIGPIPE, at its default
//! action (set in `main`), ends the process quietly at the first write into it.

use std::fmt;
use std::io::Write;
use std::sync::Mutex;

/// The first write that failed: "stdout: No space left on device (os error 28)".
static FAILURE: Mutex<Option<String>> = Mutex::new(None);

/// The two streams.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stream {
    /// Standard output: what a command reports (`list`, `status`, `run`, `check`).
    Stdout,
    /// Standard error: errors, warnings and a run's progress.
    Stderr,
}

impl Stream {
    fn name(self) -> &'static str {
        match self {
            Stream::Stdout => "stdout",
            Stream::Stderr => "stderr",
        }
    }
}

/// Writes `args` to `stream`, then a newline if `newline`, unless a write to it failed
/// before; a failure is remembered (see [`failure`]), never a panic.
pub fn write(stream: Stream, args: fmt::Arguments, newline: bool) {
    let mut failed = FAILURE.lock().unwrap_or_else(|e| e.into_inner());
    if failed.as_deref().is_some_and(|f| f.starts_with(stream.name())) {
        return;
    }
    let end = if newline { "\n" } else { "" };
    let written = match stream {
        Stream::Stdout => {
            let mut out = std::io::stdout().lock();
            write!(out, "{args}{end}").and_then(|()| out.flush())
        }
        Stream::Stderr => write!(std::io::stderr().lock(), "{args}{end}"),
    };
    if let Err(e) = written {
        failed.get_or_insert_with(|| format!("{}: {e}", stream.name()));
    }
}

/// The first write to stdout or stderr that failed, naming the stream and the cause.
pub fn failure() -> Option<String> {
    FAILURE.lock().unwrap_or_else(|e| e.into_inner()).clone()
}

/// Like `println!`, without a panic when stdout cannot be written ([`console`](crate::console)).
#[macro_export]
macro_rules! outln {
    ($($arg:tt)*) => {
        $crate::console::write($crate::console::Stream::Stdout, format_args!($($arg)*), true)
    };
}

/// Like `eprintln!`, without a panic when stderr cannot be written ([`console`](crate::console)).
#[macro_export]
macro_rules! errln {
    ($($arg:tt)*) => {
        $crate::console::write($crate::console::Stream::Stderr, format_args!($($arg)*), true)
    };
}

/// Like `eprint!`, without a panic when stderr cannot be written ([`console`](crate::console)).
#[macro_export]
macro_rules! err {
    ($($arg:tt)*) => {
        $crate::console::write($crate::console::Stream::Stderr, format_args!($($arg)*), false)
    };
}
