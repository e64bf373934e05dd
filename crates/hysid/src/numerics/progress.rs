//! Progress of the phases of a recipe, reported to an observer the caller supplies.
//!
//! A recipe with phases that take long (a grid of k/N points, k/N starts of a multi-start,
//! k/N bootstrap replicates) calls [`Observer::report`] after each step. The library prints
//! nothing: a front end turns the reports into a progress bar or log lines. The observer's
//! answer is a [`Control`]: [`Control::Stop`] asks the recipe to skip the remaining steps of
//! the phase and go on with the best result so far (how a time limit is implemented).

use super::Control;
use std::fmt;
use std::sync::Arc;

/// One step of a phase: `done` of `total` steps of `phase` are finished.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Progress<'a> {
    /// The phase, in words ("grid", "start", "bootstrap replicate").
    pub phase: &'a str,
    /// Steps finished.
    pub done: usize,
    /// Steps in the phase.
    pub total: usize,
}

/// The function an observer calls.
type ObserverFn = dyn Fn(&Progress<'_>) -> Control + Send + Sync;

/// An optional progress observer, shared by the parallel steps of a phase (cheap to clone).
#[derive(Clone, Default)]
pub struct Observer(Option<Arc<ObserverFn>>);

impl fmt::Debug for Observer {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(if self.0.is_some() {
            "Observer(set)"
        } else {
            "Observer(none)"
        })
    }
}

/// Two observers are equal when both are absent or both are the same function (one `Arc`):
/// settings that carry an observer stay comparable.
impl PartialEq for Observer {
    fn eq(&self, other: &Self) -> bool {
        match (&self.0, &other.0) {
            (None, None) => true,
            (Some(a), Some(b)) => Arc::ptr_eq(a, b),
            _ => false,
        }
    }
}

impl Observer {
    /// An observer calling `f` on every step.
    pub fn new(f: impl Fn(&Progress<'_>) -> Control + Send + Sync + 'static) -> Self {
        Self(Some(Arc::new(f)))
    }

    /// No observer: every report answers [`Control::Continue`].
    pub fn none() -> Self {
        Self(None)
    }

    /// Reports that `done` of `total` steps of `phase` are finished; the observer's answer.
    pub fn report(&self, phase: &str, done: usize, total: usize) -> Control {
        match &self.0 {
            Some(f) => f(&Progress { phase, done, total }),
            None => Control::Continue,
        }
    }

    /// True when the observer asks to stop (asked without a new step: `done` = `total` = 0).
    pub fn should_stop(&self, phase: &str) -> bool {
        self.report(phase, 0, 0) == Control::Stop
    }
}
