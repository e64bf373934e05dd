//! Progress of long runs on stderr, and the `--time-limit` of the searches.
//!
//! Every phase that may take over a second shows its name and count: "fitting: iteration 7
//! cost 1.2e-3", "identifying cascade: bootstrap replicate 12/30". On a terminal that is a
//! live spinner line; when stderr is a pipe or a file it is a plain line at most every
//! [`PLAIN_EVERY`] (so that a CI log shows a long run is alive without filling up); with
//! `--quiet` nothing is shown.
//!
//! `--time-limit S` makes the fit callbacks and the phase observers answer
//! [`Control::Stop`] once S seconds have passed since the start of the run: the searches stop
//! with the best result so far, [`time_limit_hit`] tells the command so, and the report's
//! `search.termination` is set to the code `time_limit` ([`mark_report`]). The run still
//! succeeds (exit 0) with one warning line on stderr.

use hysid::numerics::{Control, IterationRecord, Observer, Progress};
use hysid::report::Report;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, OnceLock};
use std::time::{Duration, Instant};

/// The shortest interval between two plain progress lines.
pub const PLAIN_EVERY: Duration = Duration::from_secs(3);

/// How the run shows progress and when it must stop.
struct RunSettings {
    quiet: bool,
    limit: Option<Duration>,
    start: Instant,
    hit: AtomicBool,
}

static RUN: OnceLock<RunSettings> = OnceLock::new();

/// Records `--quiet` and `--time-limit` for the run (called once by `main`).
pub fn init(quiet: bool, time_limit_s: Option<f64>) {
    let _ = RUN.set(RunSettings {
        quiet,
        limit: time_limit_s.and_then(|s| Duration::try_from_secs_f64(s).ok()),
        start: Instant::now(),
        hit: AtomicBool::new(false),
    });
}

/// Prints one line about what the run is doing on stderr, unless `--quiet`.
pub fn note(message: &str) {
    if !RUN.get().is_some_and(|run| run.quiet) {
        tell!("{message}");
    }
}

/// True once the time limit is reached (and remembered as hit).
fn over_time() -> bool {
    let Some(run) = RUN.get() else {
        return false;
    };
    match run.limit {
        Some(limit) if run.start.elapsed() >= limit => {
            run.hit.store(true, Ordering::Relaxed);
            true
        }
        _ => false,
    }
}

/// The answer to a search asking whether to go on.
fn control() -> Control {
    if over_time() {
        Control::Stop
    } else {
        Control::Continue
    }
}

/// True when the time limit stopped a search of this run.
pub fn time_limit_hit() -> bool {
    RUN.get().is_some_and(|r| r.hit.load(Ordering::Relaxed))
}

/// The time limit in seconds, when one is set.
fn limit_s() -> Option<f64> {
    RUN.get().and_then(|r| r.limit).map(|d| d.as_secs_f64())
}

/// The one warning line of a run stopped by the time limit, when it was.
pub fn time_limit_warning() -> Option<String> {
    let limit = limit_s()?;
    time_limit_hit().then(|| {
        format!(
            "warning: the time limit of {limit} s stopped the search; the results are the best \
             found so far, and the report says so (search.termination = time_limit)"
        )
    })
}

/// `report` with `search.termination` set to `time_limit` when the time limit stopped a search.
pub fn mark_report(report: &Report) -> Report {
    let mut report = report.clone();
    // The work the command performed, in the unit of the work budget, where the library did
    // not count it itself.
    if let Some(search) = &mut report.search {
        search
            .model_steps
            .get_or_insert_with(hysid::identify::budget::counted);
        search.estimated_model_steps = crate::budget::estimated();
    }
    match (time_limit_hit(), limit_s()) {
        (true, Some(limit)) => report.stopped_by_time_limit(limit),
        _ => report,
    }
}

/// Where progress goes: a live bar, throttled plain lines, or nowhere.
#[derive(Clone)]
struct Sink {
    stage: String,
    bar: Option<ProgressBar>,
    plain: Option<Arc<Mutex<Instant>>>,
}

impl Sink {
    fn new(stage: &str) -> Self {
        let quiet = RUN.get().is_some_and(|r| r.quiet);
        let mut sink = Sink {
            stage: stage.to_string(),
            bar: None,
            plain: None,
        };
        if quiet {
            return sink;
        }
        if std::io::stderr().is_terminal() {
            let bar = ProgressBar::new_spinner();
            bar.set_style(
                ProgressStyle::with_template("{spinner} {prefix}: {msg} [{elapsed}]")
                    .unwrap_or_else(|_| ProgressStyle::default_spinner()),
            );
            bar.set_prefix(stage.to_string());
            bar.enable_steady_tick(Duration::from_millis(120));
            sink.bar = Some(bar);
        } else {
            // The first plain line comes after PLAIN_EVERY: short runs print nothing.
            sink.plain = Some(Arc::new(Mutex::new(Instant::now())));
        }
        sink
    }

    fn show(&self, message: String) {
        if let Some(bar) = &self.bar {
            bar.set_message(message);
        } else if let Some(last) = &self.plain {
            let Ok(mut last) = last.lock() else { return };
            if last.elapsed() >= PLAIN_EVERY {
                *last = Instant::now();
                tell!("{}: {message}", self.stage);
            }
        }
    }
}

/// The progress of one stage of a command: its fit iterations and its phases.
pub struct FitProgress {
    sink: Sink,
}

impl FitProgress {
    /// Starts showing the progress of the stage `stage`.
    pub fn new(stage: &str) -> Self {
        Self {
            sink: Sink::new(stage),
        }
    }

    /// The callback to hand to an estimator: shows the iteration and its cost, and stops the
    /// search at the time limit.
    pub fn callback(&self) -> impl FnMut(&IterationRecord) -> Control + '_ {
        move |r| {
            self.sink
                .show(format!("iteration {} cost {:.6e}", r.iteration, r.cost));
            control()
        }
    }

    /// Shows what the stage is doing now (a step of a recipe without counts, e.g. "step 2:
    /// steady-state loops").
    pub fn show(&self, what: &str) {
        self.sink.show(what.to_string());
    }

    /// The observer to put in a recipe's settings: shows "phase k/N", and stops the phase at
    /// the time limit.
    pub fn observer(&self) -> Observer {
        let sink = self.sink.clone();
        Observer::new(move |p: &Progress<'_>| {
            if p.total > 0 {
                sink.show(format!("{} {}/{}", p.phase, p.done, p.total));
            }
            control()
        })
    }
}

impl Drop for FitProgress {
    fn drop(&mut self) {
        if let Some(bar) = &self.sink.bar {
            bar.finish_and_clear();
        }
    }
}
