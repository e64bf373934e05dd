//! The streaming form of every operator family: Γ and Γ⁻¹ one sample at a time from the
//! family's documented initial state, with a state that is fixed in size once built.
//!
//! Each family supplies its step in its own model file: the linear-in-weights families
//! (PI, generalised PI, Maxwell-slip, backlash, Preisach, KP) through their core operator G
//! ([`Core`](super::elementary::Core): `forward_step`, `backward_step`), turned into Γ = ±G or
//! ±G⁻¹ by their orientation here; the differential families (Jiles–Atherton, Bouc–Wen,
//! Duhem, Dahl) through [`super::differential::Stream`] and [`super::differential::InverseStream`], one
//! `differential_streaming!` line each. The registry (`operator_families!`) generates the
//! dispatch of [`crate::model::OperatorModel`] onto them (`crate::model::stream`).
//!
//! The batch simulations and inversions of the linear-in-weights families, and the batch
//! inversion of the differential ones, are loops over these same steps.

use super::elementary::{
    oriented_state, oriented_step, outside_domain, Core, OrientedInverse, OrientedState,
};
use super::initial_state::History;
use crate::{Error, Result};

/// One sample of an operator's inverse: the command, what the operator makes of it, and
/// whether the reference lay beyond its reach (clipped).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CompensatorStep {
    /// The command uₖ.
    pub u: f64,
    /// Γ\[u\]ₖ (equal to the reference where it is reachable).
    pub predicted: f64,
    /// True when the reference was clipped to the reachable range.
    pub clipped: bool,
}

/// An operator family's streaming form (see the module doc). `k` is the sample's index,
/// counted from the initial state, for the errors.
pub(crate) trait StreamingOperator {
    /// Γ's state.
    type Forward: Clone + std::fmt::Debug + Send;
    /// Γ⁻¹'s state.
    type Inverse: Clone + std::fmt::Debug + Send;
    /// True when a monotone excursion of the operator's memory reach leaves a state that
    /// depends on nothing before it (the wiping-out property, Mayergoyz 2003): the
    /// linear-in-weights families. A differential family's state only fades.
    const WIPES_OUT: bool;

    /// Γ's initial state (an operator whose values cannot be simulated is refused here).
    fn forward_stream(&self) -> Result<Self::Forward>;
    /// Γ\[u\]ₖ for uₖ = `u`; the state moves on to k + 1.
    fn forward_sample(&self, state: &mut Self::Forward, k: usize, u: f64) -> Result<f64>;
    /// Γ⁻¹'s initial state.
    fn inverse_stream(&self) -> Result<Self::Inverse>;
    /// The command for the reference rₖ = `r`; the state moves on to k + 1.
    fn inverse_sample(
        &self,
        state: &mut Self::Inverse,
        k: usize,
        r: f64,
    ) -> Result<CompensatorStep>;
    /// Γ⁻¹'s initial state when its first command starts after the declared `history` (with
    /// its saved turn) by running it: a differential family, whose state after the history
    /// depends on the first command ([`super::differential::HistoryRun`]). None for the
    /// families whose memory wipes out, whose inverse is primed by one reference instead
    /// (`OperatorModel::priming_reference`).
    fn inverse_stream_after(&self, _history: History) -> Result<Option<Self::Inverse>> {
        Ok(None)
    }
}

/// The error of a stream whose Preisach memory outgrew its fixed capacity at sample `k`.
fn memory_full(k: usize) -> Error {
    Error::Unsupported(format!(
        "at sample {k} the input nests more minor loops than the streaming Preisach state holds \
         ({} corners); simulate the record in one batch, or reset the stepper",
        super::preisach::STREAM_MEMORY
    ))
}

/// The linear-in-weights families: Γ = ±G or ±G⁻¹ from the core's steps.
impl<C: Core + Clone + std::fmt::Debug> StreamingOperator for C {
    type Forward = OrientedState<C>;
    type Inverse = OrientedInverse<C>;
    const WIPES_OUT: bool = true;

    fn forward_stream(&self) -> Result<Self::Forward> {
        Ok(oriented_state(self, self.orientation(), None))
    }

    /// An input outside the domain of a clockwise Γ = ±G⁻¹ is an error, as in the batch.
    fn forward_sample(&self, state: &mut Self::Forward, k: usize, u: f64) -> Result<f64> {
        let (y, outside) = oriented_step(self, self.orientation(), state, u);
        let overflowed = match state {
            OrientedState::Direct(forward) => self.overflowed(Some(forward), None),
            OrientedState::Inverse(backward) => self.overflowed(None, Some(backward)),
        };
        match (outside, overflowed) {
            (_, true) => Err(memory_full(k)),
            (true, false) => Err(outside_domain(k, u)),
            (false, false) => Ok(y),
        }
    }

    fn inverse_stream(&self) -> Result<Self::Inverse> {
        Ok(OrientedInverse::new(self, None))
    }

    fn inverse_sample(
        &self,
        state: &mut Self::Inverse,
        k: usize,
        r: f64,
    ) -> Result<CompensatorStep> {
        let (u, predicted, clipped) = state.step(self, r);
        if state.overflowed(self) {
            return Err(memory_full(k));
        }
        Ok(CompensatorStep {
            u,
            predicted,
            clipped,
        })
    }
}

/// Implements [`StreamingOperator`] for a differential family (an
/// [`super::differential::InputOde`] with a `validate` method) through
/// [`super::differential::Stream`] and [`super::differential::InverseStream`].
macro_rules! differential_streaming {
    ($ty:ty) => {
        impl $crate::model::operators::streaming::StreamingOperator for $ty {
            type Forward = $crate::model::operators::differential::Stream;
            type Inverse = $crate::model::operators::differential::InverseStream;
            const WIPES_OUT: bool = false;

            fn forward_stream(&self) -> $crate::Result<Self::Forward> {
                self.validate()?;
                Ok(Self::Forward::default())
            }
            fn forward_sample(
                &self,
                state: &mut Self::Forward,
                k: usize,
                u: f64,
            ) -> $crate::Result<f64> {
                state.step(self, k, u)
            }
            fn inverse_stream(&self) -> $crate::Result<Self::Inverse> {
                self.validate()?;
                Ok(Self::Inverse::default())
            }
            fn inverse_sample(
                &self,
                state: &mut Self::Inverse,
                k: usize,
                r: f64,
            ) -> $crate::Result<$crate::model::operators::streaming::CompensatorStep> {
                state.step(self, k, r)
            }
            fn inverse_stream_after(
                &self,
                history: $crate::model::operators::initial_state::History,
            ) -> $crate::Result<Option<Self::Inverse>> {
                use $crate::model::operators::differential::HistoryRun;
                use $crate::model::operators::initial_state::History;
                self.validate()?;
                let reach = History::reach(self);
                Ok(Some(Self::Inverse::after(HistoryRun { history, reach })))
            }
        }
    };
}
pub(crate) use differential_streaming;
