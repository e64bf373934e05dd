//! A long call watched from the calling Python thread: Ctrl-C stops it, a time limit bounds
//! it, a progress callable hears from it.
//!
//! Python handles signals on its main thread, between bytecodes: a Rust call that holds
//! the thread for a minute delays `KeyboardInterrupt` by that minute. So a long call
//! ([`run_watched`]) runs the library recipe on a worker thread of its own while the calling
//! thread waits with the GIL released and, every [`POLL`], takes the GIL back and
//!
//! * asks Python whether a signal came (`Python::check_signals`, which runs Python's
//!   handlers). When one raises — Ctrl-C's `KeyboardInterrupt`, or the exception of a
//!   handler the program installed — the call returns that exception at once and the worker
//!   is told to stop ([`Watch::stop`]): the recipe's fit callbacks and phase observers answer
//!   [`Control::Stop`] (the way the command line's `--time-limit` stops a search), the
//!   recipe winds down at its next iteration or phase step, and its result is dropped
//!   unread. A recipe writes no file, so nothing partial is left behind;
//! * calls the progress callable, if one was given, with the latest phase and iteration the
//!   recipe reported (at the start, every [`PROGRESS_EVERY`] and at the end): the callable
//!   runs on the calling thread, as Python code expects, never on a worker. An exception it
//!   raises stops the call like a signal.
//!
//! The time limit is the worker's own: once it has passed, the callbacks and observers
//! answer [`Control::Stop`], the searches end with the best result so far, and
//! [`Watch::finish`] marks the report (`search.termination.code = "time_limit"`), as the
//! command line does.
//!
//! The library installs no signal handler (signals belong to the program: Python keeps its
//! own), so after any call — an export among them — Ctrl-C raises `KeyboardInterrupt` as in
//! any Python program.

use hysid::numerics::{Control, IterationRecord, Observer};
use hysid::report::Report;
use pyo3::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Arc, Mutex};
use std::time::{Duration, Instant};

/// How often the waiting thread asks Python for signals: twenty times within the 1 s a
/// user waits for Ctrl-C to act, and rare enough to cost nothing (a wake-up of microseconds).
pub const POLL: Duration = Duration::from_millis(50);

/// How often the progress callable is called while a call runs (besides its start and end).
pub const PROGRESS_EVERY: Duration = Duration::from_millis(500);

/// What a call is asked to respect: a time limit in seconds and a progress callable taking
/// (stage, done, total, iteration, cost, elapsed_s).
#[derive(Default)]
pub struct Watching {
    /// Seconds after which the searches stop with the best result so far.
    pub time_limit: Option<f64>,
    /// Called on the calling thread with the latest progress (see the module docs).
    pub progress: Option<Py<PyAny>>,
}

/// The latest progress a recipe reported.
#[derive(Clone, Debug, Default)]
struct Snapshot {
    /// The phase ("iteration" for a fit's iterations), empty before the first report.
    stage: String,
    done: usize,
    total: usize,
    iteration: Option<usize>,
    cost: Option<f64>,
}

/// The state shared by the caller and the worker.
#[derive(Debug)]
struct Shared {
    stopped: AtomicBool,
    start: Instant,
    limit: Option<(f64, Instant)>,
    limit_hit: AtomicBool,
    latest: Mutex<Snapshot>,
}

/// What a watched call's recipe is told from the calling thread (cheap to clone).
#[derive(Clone, Debug)]
pub struct Watch {
    shared: Arc<Shared>,
}

impl Default for Watch {
    fn default() -> Self {
        Self::new(None)
    }
}

impl Watch {
    /// A watch whose searches stop `time_limit` seconds from now (None: no limit).
    fn new(time_limit: Option<f64>) -> Self {
        let start = Instant::now();
        let limit = time_limit.map(|s| {
            let deadline = Duration::try_from_secs_f64(s)
                .ok()
                .and_then(|d| start.checked_add(d));
            // A limit too far to represent never comes.
            (
                s,
                deadline.unwrap_or(start + Duration::from_secs(u32::MAX.into())),
            )
        });
        Self {
            shared: Arc::new(Shared {
                stopped: AtomicBool::new(false),
                start,
                limit,
                limit_hit: AtomicBool::new(false),
                latest: Mutex::new(Snapshot::default()),
            }),
        }
    }

    /// Asks the recipe to stop at its next check.
    pub fn stop(&self) {
        self.shared.stopped.store(true, Ordering::Relaxed);
    }

    /// True once [`Watch::stop`] was called.
    pub fn stopped(&self) -> bool {
        self.shared.stopped.load(Ordering::Relaxed)
    }

    /// True once the time limit stopped a search.
    pub fn time_limit_hit(&self) -> bool {
        self.shared.limit_hit.load(Ordering::Relaxed)
    }

    /// The answer to a search asking whether to go on.
    fn control(&self) -> Control {
        if self.stopped() {
            return Control::Stop;
        }
        match self.shared.limit {
            Some((_, deadline)) if Instant::now() >= deadline => {
                self.shared.limit_hit.store(true, Ordering::Relaxed);
                Control::Stop
            }
            _ => Control::Continue,
        }
    }

    /// Records what the recipe reports.
    fn record(&self, update: impl FnOnce(&mut Snapshot)) {
        if let Ok(mut latest) = self.shared.latest.lock() {
            update(&mut latest);
        }
    }

    /// The fit callback to hand to an estimator: records the iteration and its cost, and
    /// stops the search once stopped or past the time limit.
    pub fn callback(&self) -> impl FnMut(&IterationRecord) -> Control + '_ {
        move |r| {
            self.record(|s| {
                s.iteration = Some(r.iteration);
                s.cost = Some(r.cost);
                if s.stage.is_empty() {
                    s.stage = "iteration".into();
                }
            });
            self.control()
        }
    }

    /// The phase observer to put in a recipe's settings: records the phase and its count,
    /// and stops the phase once stopped or past the time limit.
    pub fn observer(&self) -> Observer {
        let watch = self.clone();
        Observer::new(move |p| {
            if p.total > 0 {
                watch.record(|s| {
                    s.stage = p.phase.to_string();
                    s.done = p.done;
                    s.total = p.total;
                });
            }
            watch.control()
        })
    }

    /// `report`, its `search.termination` set to `time_limit` when the time limit stopped a
    /// search of the call (as the command line marks its reports).
    pub fn finish(&self, report: Report) -> Report {
        match self.shared.limit {
            Some((limit, _)) if self.time_limit_hit() => report.stopped_by_time_limit(limit),
            _ => report,
        }
    }

    /// Calls `progress` with the latest snapshot, `stage` replacing its stage when given.
    fn tell(&self, py: Python<'_>, progress: &Py<PyAny>, stage: Option<&str>) -> PyResult<()> {
        let s = self
            .shared
            .latest
            .lock()
            .map(|s| s.clone())
            .unwrap_or_default();
        let stage = match stage {
            Some(stage) => stage.to_string(),
            None if s.stage.is_empty() => "start".to_string(),
            None => s.stage,
        };
        let elapsed = self.shared.start.elapsed().as_secs_f64();
        progress.call1(py, (stage, s.done, s.total, s.iteration, s.cost, elapsed))?;
        Ok(())
    }
}

type Caught<T> = std::thread::Result<hysid::Result<T>>;

/// Runs `f` on a worker thread, the calling thread checking Python's signals every
/// [`POLL`] and calling the progress callable with the GIL released in between (see the
/// module docs). A signal handler's (or the progress callable's) exception is returned as
/// soon as it is raised; otherwise `f`'s outcome, a panic caught.
pub fn run_watched<T: Send + 'static>(
    py: Python<'_>,
    watching: Watching,
    f: impl FnOnce(&Watch) -> hysid::Result<T> + Send + 'static,
) -> PyResult<Caught<T>> {
    let watch = Watch::new(watching.time_limit);
    let (sender, receiver) = mpsc::sync_channel::<Caught<T>>(1);
    let worker_watch = watch.clone();
    let stop_on = |e: PyErr| {
        watch.stop();
        e
    };
    if let Some(progress) = &watching.progress {
        watch.tell(py, progress, Some("start"))?;
    }
    std::thread::Builder::new()
        .name("hysid-call".into())
        .spawn(move || {
            let outcome = catch_unwind(AssertUnwindSafe(|| f(&worker_watch)));
            // The caller may have gone (interrupted): then the outcome is dropped unread.
            let _ = sender.send(outcome);
        })
        .map_err(|e| {
            crate::errors::InternalError::new_err(format!("cannot start a worker thread: {e}"))
        })?;
    let mut receiver = receiver;
    let mut told = Instant::now();
    loop {
        // The receiver is not `Sync`: it goes to the detached wait and comes back.
        let (back, received) = py.detach(move || {
            let received = receiver.recv_timeout(POLL);
            (receiver, received)
        });
        receiver = back;
        match received {
            Ok(outcome) => {
                if let Some(progress) = &watching.progress {
                    watch.tell(py, progress, Some("done"))?;
                }
                return Ok(outcome);
            }
            Err(mpsc::RecvTimeoutError::Timeout) => {
                py.check_signals().map_err(stop_on)?;
                if let Some(progress) = &watching.progress {
                    if told.elapsed() >= PROGRESS_EVERY {
                        told = Instant::now();
                        watch.tell(py, progress, None).map_err(stop_on)?;
                    }
                }
            }
            Err(mpsc::RecvTimeoutError::Disconnected) => {
                return Err(crate::errors::InternalError::new_err(
                    "internal error in hysid (the worker thread ended without a result); \
                     please report it with the input that caused it",
                ))
            }
        }
    }
}

/// The [`Watching`] of a call's `time_limit=` and `progress=` arguments, checked: a time
/// limit is a positive number of seconds (`ConfigError`), progress a callable (`TypeError`).
pub fn watching(
    py: Python<'_>,
    time_limit: Option<f64>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Watching> {
    if let Some(s) = time_limit {
        if !(s.is_finite() && s > 0.0) {
            return Err(crate::errors::named(
                py,
                "ConfigError",
                format!("time_limit={s}: give a positive number of seconds, or None for no limit"),
            ));
        }
    }
    if let Some(p) = &progress {
        if !p.bind(py).is_callable() {
            return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                "progress: expected a callable taking one hysid.Progress, got {}",
                p.bind(py).get_type().name()?
            )));
        }
    }
    Ok(Watching {
        time_limit,
        progress,
    })
}
