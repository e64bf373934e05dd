//! Cascades one sample at a time: a hysteresis (an operator of any family, or the
//! Coleman–Hodgdon hysteresis) followed by the linear block, and the operator cascade's
//! inverse (the linear block's, then the operator's, as
//! [`OperatorCascade::compensate`](crate::model::OperatorCascade::compensate) computes it).

use super::coleman_hodgdon::HysteresisStream;
use super::linear::{LinearInverse, LinearStream};
use super::operator::{AnyOperatorInverse, AnyOperatorStream};
use super::{InverseKernel, Kernel};
use crate::model::operators::CompensatorStep;
use crate::model::{HysteresisCascade, OperatorCascade};
use crate::{Error, Result};

/// The operator cascade's batch error for a linear block whose output is not finite.
fn unstable(k: usize) -> Error {
    Error::Diverged {
        index: k,
        reason: "the linear block's output is not finite; it is unstable for this input".into(),
    }
}

/// An operator followed by the linear block: v_k = Γ\[u\]_k, y_k = the block's output.
#[derive(Debug)]
pub(super) struct OperatorCascadeStream {
    operator: AnyOperatorStream,
    linear: LinearStream,
}

impl OperatorCascadeStream {
    pub(super) fn new(model: &OperatorCascade) -> Result<Self> {
        Ok(Self {
            operator: model.operator.stream()?,
            linear: LinearStream::new(model.linear.clone()),
        })
    }

    /// y_k for u_k = `u`.
    fn next(&mut self, k: usize, u: f64) -> Result<f64> {
        let mut v = [0.0];
        self.operator.step(k, &[u], &mut v)?;
        let y = self.linear.step(v[0]);
        if y.is_finite() {
            Ok(y)
        } else {
            Err(unstable(k))
        }
    }
}

impl Kernel for OperatorCascadeStream {
    fn reset(&mut self) {
        self.operator.reset();
        self.linear.reset();
    }
    fn step(&mut self, k: usize, u: &[f64], y: &mut [f64]) -> Result<()> {
        y[0] = self.next(k, u[0])?;
        Ok(())
    }
}

/// The Coleman–Hodgdon cascade: v from the hysteresis started at 0, then the linear block.
#[derive(Clone, Debug)]
pub(super) struct ChCascadeStream {
    hysteresis: HysteresisStream,
    linear: LinearStream,
}

impl ChCascadeStream {
    pub(super) fn new(model: &HysteresisCascade) -> Self {
        Self {
            hysteresis: HysteresisStream::new(model.hysteresis.clone(), 0.0),
            linear: LinearStream::new(model.linear.clone()),
        }
    }
}

impl Kernel for ChCascadeStream {
    fn reset(&mut self) {
        self.hysteresis.restart();
        self.linear.reset();
    }
    fn step(&mut self, k: usize, u: &[f64], y: &mut [f64]) -> Result<()> {
        let v = self.hysteresis.next(k, u[0])?;
        y[0] = self.linear.step(v);
        Ok(())
    }
}

/// The operator cascade's compensator: for ρ_s = r_{s+k} (the reference the linear block's
/// delay k samples ahead), v_s from the block's inverse, u_s = Γ⁻¹\[v\]_s, and the cascade's
/// output y_s for the commands so far.
#[derive(Debug)]
pub(super) struct OperatorCascadeInverse {
    linear: LinearInverse,
    operator: AnyOperatorInverse,
    forward: OperatorCascadeStream,
    delay: usize,
}

impl OperatorCascadeInverse {
    /// Refused, as the batch refuses it, when B is not minimum phase.
    pub(super) fn new(model: &OperatorCascade) -> Result<Self> {
        model.check_minimum_phase()?;
        Ok(Self {
            linear: LinearInverse::new(model.linear.clone()),
            operator: model.operator.inverse_stream()?,
            forward: OperatorCascadeStream::new(model)?,
            delay: model.linear.delay(),
        })
    }
}

impl InverseKernel for OperatorCascadeInverse {
    fn reset(&mut self) {
        self.linear.reset();
        self.operator.reset();
        self.forward.reset();
    }
    fn preview(&self) -> usize {
        self.delay
    }
    fn step(&mut self, s: usize, rho: f64) -> Result<CompensatorStep> {
        let v = self.linear.step(rho);
        let inverse = self.operator.step(s, v)?;
        let predicted = self.forward.next(s, inverse.u)?;
        Ok(CompensatorStep {
            predicted,
            ..inverse
        })
    }
}
