//! The progress bar of long commands: drawn on stderr only when stderr is a terminal, so pipes,
//! files and CI logs never see it.

use std::io::IsTerminal;
use std::sync::Mutex;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use crate::progress::Progress;

/// A bar per phase (cases, each study's rungs) with the item in progress and the time elapsed
/// since the command started.
pub struct Bar {
    enabled: bool,
    started: Instant,
    current: Mutex<Option<ProgressBar>>,
}

impl Bar {
    pub fn new() -> Self {
        Bar {
            enabled: std::io::stderr().is_terminal(),
            started: Instant::now(),
            current: Mutex::new(None),
        }
    }

    fn with_bar(&self, f: impl FnOnce(&ProgressBar)) {
        if let Some(b) = self.current.lock().expect("progress lock").as_ref() {
            f(b);
        }
    }

    /// Removes the bar from the terminal (before results are printed).
    pub fn clear(&self) {
        if let Some(b) = self.current.lock().expect("progress lock").take() {
            b.finish_and_clear();
        }
    }
}

impl Progress for Bar {
    fn begin(&self, total: usize, unit: &str) {
        if !self.enabled {
            return;
        }
        self.clear();
        let style = ProgressStyle::with_template(
            "{elapsed_precise} {bar:30} {pos}/{len} {prefix} {wide_msg}",
        )
        .expect("static template");
        let bar = ProgressBar::with_draw_target(Some(total as u64), ProgressDrawTarget::stderr())
            .with_style(style)
            .with_prefix(unit.to_string())
            .with_elapsed(self.started.elapsed());
        // Ticks keep the elapsed time moving while one long case or rung runs.
        bar.enable_steady_tick(Duration::from_millis(250));
        *self.current.lock().expect("progress lock") = Some(bar);
    }

    fn start(&self, item: &str) {
        self.with_bar(|b| b.set_message(item.to_string()));
    }

    fn advance(&self) {
        self.with_bar(|b| b.inc(1));
    }

    fn finish(&self) {
        self.clear();
    }
}

impl Drop for Bar {
    fn drop(&mut self) {
        self.clear();
    }
}
