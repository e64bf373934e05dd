//! Operators one sample at a time: each family's streaming form
//! ([`StreamingOperator`](crate::model::operators::streaming::StreamingOperator), supplied in
//! the family's own model file), dispatched from [`OperatorModel`] by the registry's
//! `operator_families!` list.

use super::{Compensator, CompensatorStep, Guarded, GuardedInverse, InverseKernel, Kernel};
use crate::model::operators::initial_state::History;
use crate::model::operators::streaming::StreamingOperator;
use crate::model::operators::{Inversion, OperatorModel};
use crate::Result;

/// Γ of one family, streamed.
#[derive(Clone, Debug)]
pub(super) struct OperatorStream<F: StreamingOperator> {
    operator: F,
    initial: F::Forward,
    state: F::Forward,
}

impl<F: StreamingOperator> OperatorStream<F> {
    /// The operator at its initial state.
    pub(super) fn new(operator: F) -> Result<Self> {
        let initial = operator.forward_stream()?;
        Ok(Self {
            operator,
            state: initial.clone(),
            initial,
        })
    }

    /// Γ\[u\]ₖ; the state moves on.
    pub(super) fn next(&mut self, k: usize, u: f64) -> Result<f64> {
        self.operator.forward_sample(&mut self.state, k, u)
    }

    /// Back to the initial state.
    pub(super) fn restart(&mut self) {
        self.state.clone_from(&self.initial);
    }
}

impl<F: StreamingOperator + Send + std::fmt::Debug> Kernel for OperatorStream<F> {
    fn reset(&mut self) {
        self.restart();
    }
    fn step(&mut self, k: usize, u: &[f64], y: &mut [f64]) -> Result<()> {
        y[0] = self.next(k, u[0])?;
        Ok(())
    }
}

/// Γ⁻¹ of one family, streamed.
#[derive(Clone, Debug)]
pub(super) struct OperatorInverse<F: StreamingOperator> {
    operator: F,
    initial: F::Inverse,
    state: F::Inverse,
}

impl<F: StreamingOperator> OperatorInverse<F> {
    /// The inverse at its initial state.
    pub(super) fn new(operator: F) -> Result<Self> {
        let initial = operator.inverse_stream()?;
        Ok(Self::at(operator, initial))
    }

    /// The inverse at the initial state `initial` (its reset goes back there).
    fn at(operator: F, initial: F::Inverse) -> Self {
        Self {
            operator,
            state: initial.clone(),
            initial,
        }
    }
}

impl<F: StreamingOperator + Send + std::fmt::Debug> InverseKernel for OperatorInverse<F> {
    fn reset(&mut self) {
        self.state.clone_from(&self.initial);
    }
    fn step(&mut self, k: usize, r: f64) -> Result<CompensatorStep> {
        self.operator.inverse_sample(&mut self.state, k, r)
    }
}

/// An operator stream that runs a declared history at its first (good) sample u₀: the inputs
/// u₀ and u_turn go through the stream, their outputs dropped, then u₀ gives the first output
/// ([`History::turn_at`]: the path a batch simulation of the saved model runs, so the same
/// bits).
#[derive(Debug)]
struct AfterHistory {
    inner: AnyOperatorStream,
    /// The operator's memory reach ([`History::reach`]).
    reach: f64,
    history: History,
    primed: bool,
}

impl Kernel for AfterHistory {
    fn reset(&mut self) {
        self.inner.reset();
        self.primed = false;
    }
    fn step(&mut self, k: usize, u: &[f64], y: &mut [f64]) -> Result<()> {
        if !self.primed {
            let turn = self.history.turn_at(self.reach, u[0]);
            let mut dropped = [0.0];
            let run = self
                .inner
                .step(k, u, &mut dropped)
                .and_then(|()| self.inner.step(k, &[turn], &mut dropped));
            if let Err(e) = run {
                self.inner.reset();
                return Err(e);
            }
            self.primed = true;
        }
        self.inner.step(k, u, y)
    }
}

/// An operator's inverse primed by a declared history: at construction and at every reset it
/// takes the reference r_turn, the operator's output at the history's turn from its own
/// initial state, its command dropped ([`OperatorModel::compensator_from`]).
#[derive(Debug)]
struct PrimedInverse {
    inner: AnyOperatorInverse,
    reference: f64,
}

impl PrimedInverse {
    fn new(mut inner: AnyOperatorInverse, reference: f64) -> Result<Self> {
        inner.step(0, reference)?;
        Ok(Self { inner, reference })
    }
}

impl InverseKernel for PrimedInverse {
    fn reset(&mut self) {
        self.inner.reset();
        // It succeeded at construction, from the same state.
        let _ = self.inner.step(0, self.reference);
    }
    fn step(&mut self, k: usize, r: f64) -> Result<CompensatorStep> {
        self.inner.step(k, r)
    }
}

/// An operator of any family streamed, the family's type erased: what a cascade holds.
pub(super) type AnyOperatorStream = Box<dyn Kernel>;
/// An operator's inverse of any family streamed, the family's type erased.
pub(super) type AnyOperatorInverse = Box<dyn InverseKernel>;

/// `OperatorModel::stream` and `OperatorModel::inverse_stream`, one arm per family of the
/// registry.
macro_rules! dispatch {
    ($($variant:ident: $ty:ty),* $(,)?) => {
        impl OperatorModel {
            /// The operator one sample at a time, from its documented initial state (the
            /// kernel a cascade's stream holds).
            pub(super) fn stream(&self) -> Result<AnyOperatorStream> {
                Ok(match self {
                    $(OperatorModel::$variant(m) => Box::new(OperatorStream::new(m.clone())?),)*
                })
            }

            /// The operator's inverse one sample at a time.
            pub(super) fn inverse_stream(&self) -> Result<AnyOperatorInverse> {
                Ok(match self {
                    $(OperatorModel::$variant(m) => Box::new(OperatorInverse::new(m.clone())?),)*
                })
            }

            /// The inverse whose first command runs the declared `history`
            /// ([`StreamingOperator::inverse_stream_after`]); None for the families that
            /// prime it instead.
            fn inverse_stream_after(&self, history: History) -> Result<Option<AnyOperatorInverse>> {
                Ok(match self {
                    $(OperatorModel::$variant(m) => m.inverse_stream_after(history)?.map(|initial| {
                        Box::new(OperatorInverse::at(m.clone(), initial)) as AnyOperatorInverse
                    }),)*
                })
            }

            /// The family's [`StreamingOperator::WIPES_OUT`].
            fn wipes_out(&self) -> bool {
                match self {
                    $(OperatorModel::$variant(_) => <$ty as StreamingOperator>::WIPES_OUT,)*
                }
            }
        }
    };
}
crate::model::operators::operator_families!(dispatch);

impl OperatorModel {
    /// The operator as a [`Stepper`](super::Stepper): Γ\[u\]ₖ for each uₖ, from the family's
    /// documented initial state; equal to the batch [`simulate`] to the bit.
    ///
    /// [`simulate`]: crate::model::operators::HysteresisOperator::simulate
    pub fn stepper(&self) -> Result<Box<dyn super::Stepper>> {
        Ok(Box::new(Guarded::new(self.stream()?, 1, 1)))
    }

    /// [`OperatorModel::stepper`] after the declared `history` (None: from the documented
    /// initial state): the history runs at the first good sample, as
    /// [`initial_state::simulate_from`] runs it before a record; equal to it to the bit when
    /// the history has its saved turn (without one, a file of an earlier version, the batch
    /// places the turn from the record's range and the stream at u₀ ± reach).
    ///
    /// [`initial_state::simulate_from`]: crate::model::operators::initial_state::simulate_from
    pub fn stepper_from(&self, history: Option<History>) -> Result<Box<dyn super::Stepper>> {
        let Some(history) = history else {
            return self.stepper();
        };
        let primed = AfterHistory {
            inner: self.stream()?,
            reach: History::reach(self.as_operator()),
            history,
            primed: false,
        };
        Ok(Box::new(Guarded::new(
            Box::new(primed) as AnyOperatorStream,
            1,
            1,
        )))
    }

    /// The operator's inverse as a [`Compensator`]: the command uₖ with Γ\[u\]ₖ = rₖ, clipped
    /// where the batch [`invert`] clips; equal to it to the bit.
    ///
    /// [`invert`]: crate::model::operators::HysteresisOperator::invert
    pub fn compensator(&self) -> Result<Box<dyn Compensator>> {
        Ok(Box::new(GuardedInverse::new(self.inverse_stream()?)))
    }

    /// The reference that primes the inverse for a declared `history` saved with its turn
    /// u_turn: Γ's first output at u_turn from the documented initial state. None without a
    /// history or a saved turn, and for a family whose memory does not wipe out (a
    /// differential one, whose first command runs the history instead:
    /// [`OperatorModel::history_reaches_the_inverse`]).
    ///
    /// After it the inverse's state is the operator's after the input u_turn, and the first
    /// command u₀ descends (ascends) from there: exactly the state after the history
    /// u₀ → u_turn → u₀ that `simulate` runs for a u₀ on the record's side of the saved turn
    /// (the fit placed it at least the memory reach beyond the record, and a compensator's
    /// limits keep its commands within the record's range), since the excursion to u_turn
    /// wipes out what preceded it. A command beyond the saved turn (no limits, a reference
    /// far beyond the record) starts from this state, where `simulate` would turn beyond u₀.
    pub fn priming_reference(&self, history: Option<History>) -> Result<Option<f64>> {
        let Some(turn) = history.and_then(|h| h.turn).filter(|_| self.wipes_out()) else {
            return Ok(None);
        };
        let mut forward = self.stream()?;
        let mut y = [0.0];
        forward.step(0, &[turn], &mut y)?;
        Ok(Some(y[0]))
    }

    /// True when the compensator and the batch compensation start after a declared history:
    /// one saved with its turn. The families whose memory wipes out prime their inverse with
    /// one reference ([`OperatorModel::priming_reference`]); a differential family's first
    /// command runs the history's path itself
    /// ([`crate::model::operators::differential::HistoryRun`]). A file of an earlier version
    /// (no saved turn) starts the inverse from the family's documented initial state.
    pub fn history_reaches_the_inverse(&self, history: Option<History>) -> bool {
        history.is_some_and(|h| h.turn.is_some())
    }

    /// The inverse stream after the declared `history` (as
    /// [`OperatorModel::history_reaches_the_inverse`] says): primed, run by its first
    /// command, or from the documented initial state.
    fn inverse_stream_from(&self, history: Option<History>) -> Result<AnyOperatorInverse> {
        if let Some(r) = self.priming_reference(history)? {
            return Ok(Box::new(PrimedInverse::new(self.inverse_stream()?, r)?));
        }
        if let Some(h) = history.filter(|_| self.history_reaches_the_inverse(history)) {
            if let Some(inverse) = self.inverse_stream_after(h)? {
                return Ok(inverse);
            }
        }
        self.inverse_stream()
    }

    /// [`OperatorModel::compensator`] after the declared `history`
    /// ([`OperatorModel::history_reaches_the_inverse`]); equal to
    /// [`OperatorModel::invert_from`] to the bit.
    pub fn compensator_from(&self, history: Option<History>) -> Result<Box<dyn Compensator>> {
        Ok(Box::new(GuardedInverse::new(
            self.inverse_stream_from(history)?,
        )))
    }

    /// The batch inversion of `reference` after the declared `history`, the state
    /// [`OperatorModel::compensator_from`] starts in: the operator's [`invert`] of the priming
    /// reference and then `reference` (the families whose memory wipes out), the differential
    /// family's inverse steps from the state its history leaves (its [`invert`] is the loop
    /// of the same steps), or its [`invert`] as it is.
    ///
    /// [`invert`]: crate::model::operators::HysteresisOperator::invert
    pub fn invert_from(&self, history: Option<History>, reference: &[f64]) -> Result<Inversion> {
        if let Some(r) = self.priming_reference(history)? {
            let primed: Vec<f64> = std::iter::once(r)
                .chain(reference.iter().copied())
                .collect();
            let mut inv = self.as_operator().invert(&primed)?;
            return Ok(Inversion {
                u: inv.u.split_off(1),
                predicted: inv.predicted.split_off(1),
                clipped: inv
                    .clipped
                    .iter()
                    .filter(|&&k| k >= 1)
                    .map(|k| k - 1)
                    .collect(),
            });
        }
        if !self.history_reaches_the_inverse(history) {
            return self.as_operator().invert(reference);
        }
        let mut inverse = self.inverse_stream_from(history)?;
        crate::model::operators::differential::check_signal("reference", reference)?;
        let n = reference.len();
        let mut out = Inversion {
            u: Vec::with_capacity(n),
            predicted: Vec::with_capacity(n),
            clipped: Vec::new(),
        };
        for (k, &r) in reference.iter().enumerate() {
            let step = inverse.step(k, r)?;
            out.u.push(step.u);
            out.predicted.push(step.predicted);
            if step.clipped {
                out.clipped.push(k);
            }
        }
        Ok(out)
    }
}
