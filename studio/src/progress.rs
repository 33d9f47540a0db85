//! Progress bars for the steps that take more than a second. indicatif
//! draws them on stderr only when it is a terminal, so tests and pipes
//! stay quiet.

use indicatif::{ProgressBar, ProgressStyle};

/// A bar counting `what` (lines, passes, pixels…).
pub fn bar(message: &str, len: u64) -> ProgressBar {
    let style = ProgressStyle::with_template("{msg:>12} [{bar:32}] {pos}/{len} {elapsed}")
        .expect("a valid template")
        .progress_chars("=> ");
    ProgressBar::new(len)
        .with_style(style)
        .with_message(message.to_string())
}

/// No bar at all (tests, library callers).
pub fn quiet() -> ProgressBar {
    ProgressBar::hidden()
}

/// A step that cannot count: a spinner with its name.
pub fn spinner(message: &str) -> ProgressBar {
    let p = ProgressBar::new_spinner().with_message(message.to_string());
    p.enable_steady_tick(std::time::Duration::from_millis(120));
    p
}
