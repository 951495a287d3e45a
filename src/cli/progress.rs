//! A progress bar over the bytes of one file being read (`verify`, `export`): drawn on stderr only when
//! stderr is a terminal, and only once the read has taken longer than [`DELAY`], so short runs and pipes
//! show nothing.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::time::{Duration, Instant};

/// Reads shorter than this show no bar.
pub const DELAY: Duration = Duration::from_secs(1);

/// The bar of one file.
pub struct FileProgress {
    bar: ProgressBar,
    started: Instant,
    terminal: bool,
}

impl FileProgress {
    /// A hidden bar for a file of `len` bytes, labelled `name`.
    pub fn new(name: &str, len: u64) -> Self {
        let bar = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::hidden());
        if let Ok(style) = ProgressStyle::with_template(
            "{msg} {bar:40} {percent:>3}% {binary_bytes}/{binary_total_bytes} (eta {eta})",
        ) {
            bar.set_style(style);
        }
        bar.set_message(name.to_string());
        Self {
            bar,
            started: Instant::now(),
            terminal: std::io::stderr().is_terminal(),
        }
    }

    /// `bytes` of the file have been read (called from the reading thread).
    pub fn update(&self, bytes: u64) {
        if self.terminal && self.bar.is_hidden() && self.started.elapsed() > DELAY {
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
        }
        self.bar.set_position(bytes);
    }

    /// Removes the bar.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}
