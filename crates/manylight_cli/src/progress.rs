//! Progress of a long command: a bar on a terminal (indicatif), one plain line per step
//! otherwise (a log file or CI shows what ran and how long it took).

use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal as _;
use std::time::Instant;

/// Counts the steps of a command and shows them on stderr.
pub struct Progress {
    bar: Option<ProgressBar>,
    total: u64,
    done: u64,
    started: Instant,
    what: &'static str,
}

impl Progress {
    /// `total` steps of `what` (a plural noun: "frames", "configurations").
    pub fn new(total: u64, what: &'static str) -> Progress {
        let bar = std::io::stderr().is_terminal().then(|| {
            let bar = ProgressBar::new(total);
            bar.set_style(
                ProgressStyle::with_template(&format!(
                    "{{bar:40}} {{pos}}/{{len}} {what}, {{elapsed}} [{{msg}}]"
                ))
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
            );
            bar
        });
        Progress { bar, total, done: 0, started: Instant::now(), what }
    }

    /// What is being worked on now (shown beside the bar; plain output prints it with the
    /// next finished step).
    pub fn set_message(&self, message: impl Into<String>) {
        if let Some(bar) = &self.bar {
            bar.set_message(message.into());
        }
    }

    /// One step done; `line` says what it was (printed as a plain line without a terminal).
    pub fn step(&mut self, line: impl FnOnce() -> String) {
        self.done += 1;
        match &self.bar {
            Some(bar) => bar.inc(1),
            None => eprintln!(
                "[{}/{} {}, {:.0} s] {}",
                self.done,
                self.total,
                self.what,
                self.started.elapsed().as_secs_f64(),
                line()
            ),
        }
    }

    /// Removes the bar.
    pub fn finish(self) {
        if let Some(bar) = self.bar {
            bar.finish_and_clear();
        }
    }
}
