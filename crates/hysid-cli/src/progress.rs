//! Progress of long fits on stderr (hidden when stderr is not a terminal).

use hysid::numerics::{Control, IterationRecord};
use indicatif::{ProgressBar, ProgressStyle};
use std::time::Duration;

/// A spinner that shows the iteration and the criterion of an iterative fit.
pub struct FitProgress {
    bar: ProgressBar,
}

impl FitProgress {
    /// Starts a spinner with a stage label.
    pub fn new(stage: &str) -> Self {
        let bar = ProgressBar::new_spinner();
        bar.set_style(
            ProgressStyle::with_template("{spinner} {prefix} {msg} [{elapsed}]")
                .unwrap_or_else(|_| ProgressStyle::default_spinner()),
        );
        bar.set_prefix(stage.to_string());
        bar.enable_steady_tick(Duration::from_millis(120));
        Self { bar }
    }

    /// The callback to hand to an estimator.
    pub fn callback(&self) -> impl FnMut(&IterationRecord) -> Control + '_ {
        move |r| {
            self.bar
                .set_message(format!("iteration {} cost {:.6e}", r.iteration, r.cost));
            Control::Continue
        }
    }
}

impl Drop for FitProgress {
    fn drop(&mut self) {
        self.bar.finish_and_clear();
    }
}
