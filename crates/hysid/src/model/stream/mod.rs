//! Streaming models: one sample in, one sample out, from the model's saved initial state —
//! the form a controller runs, and the reference the exported C and Rust code
//! (`crate::export`) transliterates.
//!
//! # Step semantics
//!
//! [`Stepper::step`] with the input u_k writes y_k — exactly the sample
//! [`FittedModel::simulate`] gives at k for the same inputs, `ts` and `y0` — and then
//! advances the state to k + 1. [`Compensator::step`] with the reference r gives the command u
//! that makes the model follow it, with what the model makes of it and whether r was out of
//! reach (clipped to the reachable range, as [`compensate`](crate::model::compensate::compensate)
//! clips, and counted). A fresh or [`reset`](Stepper::reset) stepper is at the model's
//! initial state; after an error (a divergence, a budget or capacity overflow: latched) a
//! stepper's state is undefined until it is reset. A non-finite sample is not an error: it
//! is skipped, and a compensator's command is limited, by the one rule of
//! [`crate::model::limits`] (the library's, the exported code's and Python's).
//!
//! For a cascade with delay k ≥ 1 the command u_s first moves the output at s + k, so its
//! compensator takes the reference [`preview`](Compensator::preview) = k samples ahead:
//! step s is given r_{s+k} and returns u_s with the predicted output y_s (the batch pads the
//! record's end with its last reference; [`compensate_stream`] does the same and equals the
//! batch).
//!
//! # Equality with the batch
//!
//! Every kind's stream equals the batch to the bit: the operator families, the
//! Coleman–Hodgdon hysteresis and the operator cascade's compensator step through the very
//! code the batch loops over (the families' `Core` and differential streams, the
//! Coleman–Hodgdon inverse); the linear block, the differential operators' forward simulation
//! and the grey-box models perform the batch's operations in the batch's order (each
//! submodule says how). The exceptions are documented where they arise: a grey-box model
//! saved with `band_limited` interpolation ([`FittedModel::streaming_differs`]), the
//! divergence guard of a differential operator (100 000 sub-steps per sample interval rather
//! than per record), and the fixed capacity of the Preisach memory (below).
//!
//! # Input between samples (grey-box and equation models)
//!
//! A stream integrates interval [t_{k−1}, t_k] when u_k arrives (one interval late, which
//! the output never sees: y_k depends on x(t_k) and u_k only). So zero-order hold (u_{k−1}
//! held over the interval) and linear interpolation (u_{k−1} to u_k) are the batch's, bit for
//! bit. Band-limited interpolation reads the whole record's spectrum, which no stream has: it
//! is streamed with linear interpolation, and [`FittedModel::streaming_differs`] says so (an
//! export refuses or warns on it).
//!
//! # Fixed-size state
//!
//! Every state is allocated when the stepper is built and never grows: play, kernel and
//! relay states; the differential operators' state and previous input; the linear block's
//! windows of n past outputs and k + m past inputs; a grey-box model's state vector and the
//! two-sample input track. The Preisach plane's memory is its staircase of alternating
//! extrema, whose depth the input sets (every nested minor loop adds two corners): a stream
//! holds [`STREAM_MEMORY`](crate::model::operators::preisach::STREAM_MEMORY) corners and
//! errors when an input nests deeper, where the batch, which holds them all, goes on.
//!
//! # What does not stream
//!
//! * A model fitted to **pre-filtered** records ([`FittedModel::Prefiltered`]): its filter
//!   removes the record's mean and runs forward and backward over the whole record (zero
//!   phase), which no causal step can do, and the inner model was fitted to the filtered
//!   signals only. Refused, one line.
//! * An **inverse-dynamics** rigid body ([`FittedModel::InverseDynamics`]): it predicts the
//!   drive signal from a zero-phase filtered, differentiated and decimated position — the
//!   same non-causal filter. Refused; its rigid body (the inner model) streams forward.
//! * Compensators exist where [`compensate`](crate::model::compensate::compensate) inverts:
//!   operators, the Coleman–Hodgdon hysteresis alone, operator cascades with a minimum-phase
//!   linear block. A Coleman–Hodgdon cascade and the grey-box models have none (the batch's
//!   error, [`Error::NotInvertible`]); a cascade whose B is not minimum phase is refused with
//!   the batch's one-line error.

mod cascade;
mod coleman_hodgdon;
mod greybox;
mod linear;
mod operator;

pub use crate::model::operators::CompensatorStep;

use crate::model::coleman_hodgdon::InitialOutput;
use crate::model::compensate::Compensation;
use crate::model::limits::{is_bad, Limits};
use crate::model::saved::FittedModel;
use crate::model::{ColemanHodgdon, HysteresisCascade, OperatorCascade};
use crate::{Error, Result};

/// One sample in, one sample out, from the model's saved initial state.
pub trait Stepper: Send + std::fmt::Debug {
    /// The number of input channels `step` takes.
    fn n_inputs(&self) -> usize;
    /// The number of output channels `step` writes.
    fn n_outputs(&self) -> usize;
    /// Back to the model's initial state (and the fault count to 0).
    fn reset(&mut self);
    /// y_k for the input u_k (exactly the sample `FittedModel::simulate` gives at k), then the
    /// state advances to k + 1. `u` holds one value per input, `y` one per output. An input
    /// with a non-finite value is a bad sample ([`crate::model::limits`]): the state stays,
    /// `y` gets the last good outputs (0 before any) and the step counts a fault.
    fn step(&mut self, u: &[f64], y: &mut [f64]) -> Result<()>;
    /// True when the last sample was bad (non-finite); cleared by the next good one.
    fn error(&self) -> bool;
    /// How many bad (non-finite) samples since the last reset.
    fn faults(&self) -> usize;
}

/// The command that makes a model follow a reference, one sample at a time.
pub trait Compensator: Send + std::fmt::Debug {
    /// Back to the model's initial state (and the clipped and fault counts to 0).
    fn reset(&mut self);
    /// How many samples ahead the reference is given: the linear block's delay k for an
    /// operator cascade (step s takes r_{s+k}), 0 otherwise.
    fn preview(&self) -> usize;
    /// The command u_k that makes the model follow the reference (clipped to the reachable
    /// range as batch compensation does, then to the [`limits`](Compensator::limits), and
    /// counted). A non-finite reference is a bad sample ([`crate::model::limits`]): the state
    /// stays, the step repeats the last good command (the limits' midpoint, or 0, before
    /// any) and counts a fault.
    fn step(&mut self, reference: f64) -> Result<CompensatorStep>;
    /// How many references were clipped since the last reset.
    fn clipped(&self) -> usize;
    /// The limits of the command (none: unlimited; the default of a new compensator).
    fn limits(&self) -> Option<Limits>;
    /// Sets the limits of the command and resets the compensator.
    fn set_limits(&mut self, limits: Option<Limits>);
    /// True when the last reference was bad (non-finite); cleared by the next good one.
    fn error(&self) -> bool;
    /// How many bad (non-finite) references since the last reset.
    fn faults(&self) -> usize;
}

/// A kind's step, given the sample's index (the checks and the count are [`Guarded`]'s).
trait Kernel: Send + std::fmt::Debug {
    fn reset(&mut self);
    fn step(&mut self, k: usize, u: &[f64], y: &mut [f64]) -> Result<()>;
}

impl<K: Kernel + ?Sized> Kernel for Box<K> {
    fn reset(&mut self) {
        (**self).reset()
    }
    fn step(&mut self, k: usize, u: &[f64], y: &mut [f64]) -> Result<()> {
        (**self).step(k, u, y)
    }
}

/// A kind's inverse step, given the command's index.
trait InverseKernel: Send + std::fmt::Debug {
    fn reset(&mut self);
    fn preview(&self) -> usize {
        0
    }
    fn step(&mut self, k: usize, reference: f64) -> Result<CompensatorStep>;
}

impl<K: InverseKernel + ?Sized> InverseKernel for Box<K> {
    fn reset(&mut self) {
        (**self).reset()
    }
    fn preview(&self) -> usize {
        (**self).preview()
    }
    fn step(&mut self, k: usize, reference: f64) -> Result<CompensatorStep> {
        (**self).step(k, reference)
    }
}

/// A kernel with the checks every stepper makes: the channel counts, bad (non-finite) inputs
/// skipped ([`crate::model::limits`]), and finite outputs (as [`FittedModel::simulate`]
/// refuses a non-finite output), and the count k of good samples.
#[derive(Debug)]
struct Guarded<K> {
    kernel: K,
    k: usize,
    n_inputs: usize,
    n_outputs: usize,
    /// The last good outputs (0 before any).
    held: Vec<f64>,
    bad: bool,
    faults: usize,
}

impl<K: Kernel> Guarded<K> {
    fn new(kernel: K, n_inputs: usize, n_outputs: usize) -> Self {
        Self {
            kernel,
            k: 0,
            n_inputs,
            n_outputs,
            held: vec![0.0; n_outputs],
            bad: false,
            faults: 0,
        }
    }
}

impl<K: Kernel> Stepper for Guarded<K> {
    fn n_inputs(&self) -> usize {
        self.n_inputs
    }
    fn n_outputs(&self) -> usize {
        self.n_outputs
    }
    fn reset(&mut self) {
        self.kernel.reset();
        self.k = 0;
        self.held.iter_mut().for_each(|v| *v = 0.0);
        self.bad = false;
        self.faults = 0;
    }
    fn step(&mut self, u: &[f64], y: &mut [f64]) -> Result<()> {
        if u.len() != self.n_inputs || y.len() != self.n_outputs {
            return Err(Error::ModelMismatch(format!(
                "the model takes {} input(s) and gives {} output(s) a step, {} and {} given",
                self.n_inputs,
                self.n_outputs,
                u.len(),
                y.len()
            )));
        }
        self.bad = is_bad(u);
        if self.bad {
            self.faults += 1;
            y.copy_from_slice(&self.held);
            return Ok(());
        }
        self.kernel.step(self.k, u, y)?;
        if let Some(c) = y.iter().position(|v| !v.is_finite()) {
            return Err(Error::Diverged {
                index: self.k,
                reason: format!(
                    "output {} is {}; the model is unstable or its parameters are out of range for this input",
                    c + 1,
                    y[c]
                ),
            });
        }
        self.held.copy_from_slice(y);
        self.k += 1;
        Ok(())
    }
    fn error(&self) -> bool {
        self.bad
    }
    fn faults(&self) -> usize {
        self.faults
    }
}

/// An inverse kernel with the checks every compensator makes: bad (non-finite) references
/// skipped ([`crate::model::limits`]), the command's limits, a finite command, the count k of
/// good references and the clipped count.
#[derive(Debug)]
struct GuardedInverse<K> {
    kernel: K,
    k: usize,
    clipped: usize,
    limits: Option<Limits>,
    /// The last good step (the limits' midpoint, or 0, before any).
    held: CompensatorStep,
    bad: bool,
    faults: usize,
}

impl<K: InverseKernel> GuardedInverse<K> {
    fn new(kernel: K) -> Self {
        Self {
            kernel,
            k: 0,
            clipped: 0,
            limits: None,
            held: CompensatorStep {
                u: 0.0,
                predicted: 0.0,
                clipped: false,
            },
            bad: false,
            faults: 0,
        }
    }
}

impl<K: InverseKernel> Compensator for GuardedInverse<K> {
    fn reset(&mut self) {
        self.kernel.reset();
        self.k = 0;
        self.clipped = 0;
        self.held = CompensatorStep {
            u: self.limits.map_or(0.0, |l| l.midpoint()),
            predicted: 0.0,
            clipped: false,
        };
        self.bad = false;
        self.faults = 0;
    }
    fn preview(&self) -> usize {
        self.kernel.preview()
    }
    fn step(&mut self, reference: f64) -> Result<CompensatorStep> {
        self.bad = is_bad(&[reference]);
        if self.bad {
            self.faults += 1;
            return Ok(CompensatorStep {
                clipped: false,
                ..self.held
            });
        }
        let mut step = self.kernel.step(self.k, reference)?;
        if !step.u.is_finite() {
            return Err(Error::Diverged {
                index: self.k,
                reason: format!(
                    "the command is {}; the model's inverse cannot be computed for this reference",
                    step.u
                ),
            });
        }
        if let Some(limits) = &self.limits {
            let (u, limited) = limits.apply(step.u);
            step.u = u;
            step.clipped |= limited;
        }
        self.clipped += usize::from(step.clipped);
        self.held = step;
        self.k += 1;
        Ok(step)
    }
    fn clipped(&self) -> usize {
        self.clipped
    }
    fn limits(&self) -> Option<Limits> {
        self.limits
    }
    fn set_limits(&mut self, limits: Option<Limits>) {
        self.limits = limits;
        self.reset();
    }
    fn error(&self) -> bool {
        self.bad
    }
    fn faults(&self) -> usize {
        self.faults
    }
}

impl FittedModel {
    /// The model one sample at a time (see the [module doc](self)): `ts` and `y0` mean what
    /// they mean for [`FittedModel::simulate`] (`ts` is used by grey-box models; `y0` by a
    /// Coleman–Hodgdon hysteresis that starts from the measured output).
    pub fn stepper(&self, ts: f64, y0: Option<f64>) -> Result<Box<dyn Stepper>> {
        match self.as_kind() {
            Some(kind) => kind.stepper(ts, y0),
            None => Err(self.not_causal()),
        }
    }

    /// The model's compensator one sample at a time (see the [module doc](self)); the kinds
    /// [`compensate`](crate::model::compensate::compensate) inverts, with its errors. `ts` is
    /// the sample time, as for [`FittedModel::stepper`] (every kind with an inverse is
    /// discrete-time today, so none reads it).
    pub fn compensator(&self, _ts: f64) -> Result<Box<dyn Compensator>> {
        match self.as_kind() {
            Some(kind) => kind.compensator(),
            None => Err(self.not_causal()),
        }
    }

    /// Why a one-sample step differs from this model's batch simulation, if it does: a
    /// grey-box or equation model saved with `band_limited` input interpolation (streamed
    /// with linear interpolation); None when they agree.
    pub fn streaming_differs(&self) -> Option<String> {
        match (self, self.as_kind()) {
            (_, Some(kind)) => kind.streaming_differs(),
            (
                FittedModel::Prefiltered { model, .. } | FittedModel::InverseDynamics { model, .. },
                None,
            ) => model.streaming_differs(),
            (_, None) => None,
        }
    }

    /// The one-line refusal of a model whose records were processed non-causally.
    fn not_causal(&self) -> Error {
        let kind = self.to_file().kind().to_string();
        let why = match self {
            FittedModel::InverseDynamics { .. } => {
                "it predicts the drive signal from a zero-phase filtered and differentiated \
                 position, which needs the whole record; stream its rigid body instead"
            }
            _ => {
                "it was fitted to records pre-filtered forward and backward (zero phase), \
                 which needs the whole record; refit it without the pre-filter to stream it"
            }
        };
        Error::UnsupportedKind {
            kind,
            operation: format!("streaming one sample at a time: {why}"),
        }
    }
}

/// The stepper of the Coleman–Hodgdon hysteresis `model` starting from the output `v0`.
pub(crate) fn hysteresis_stepper(model: &ColemanHodgdon, v0: f64) -> Box<dyn Stepper> {
    let kernel = coleman_hodgdon::HysteresisStream::new(model.clone(), v0);
    Box::new(Guarded::new(kernel, 1, 1))
}

/// The compensator of the Coleman–Hodgdon hysteresis `model` (its per-sample solve).
pub(crate) fn hysteresis_compensator(
    model: &ColemanHodgdon,
    initial: InitialOutput,
) -> Box<dyn Compensator> {
    Box::new(GuardedInverse::new(
        coleman_hodgdon::HysteresisInverse::new(model.clone(), initial),
    ))
}

/// The stepper of the Coleman–Hodgdon cascade `model`.
pub(crate) fn ch_cascade_stepper(model: &HysteresisCascade) -> Box<dyn Stepper> {
    Box::new(Guarded::new(cascade::ChCascadeStream::new(model), 1, 1))
}

/// The stepper of the operator cascade `model`.
pub(crate) fn operator_cascade_stepper(model: &OperatorCascade) -> Result<Box<dyn Stepper>> {
    let kernel = cascade::OperatorCascadeStream::new(model)?;
    Ok(Box::new(Guarded::new(kernel, 1, 1)))
}

/// The compensator of the operator cascade `model` (refused unless B is minimum phase).
pub(crate) fn operator_cascade_compensator(
    model: &OperatorCascade,
) -> Result<Box<dyn Compensator>> {
    let kernel = cascade::OperatorCascadeInverse::new(model)?;
    Ok(Box::new(GuardedInverse::new(kernel)))
}

/// The grey-box stepper of `model` with values `theta`.
pub(crate) fn grey_box(
    model: Box<dyn crate::model::greybox::StateSpaceModel>,
    theta: Vec<f64>,
    initial_state: &[f64],
    simulation: &crate::model::greybox::Simulation,
    ts: f64,
) -> Result<Box<dyn Stepper>> {
    let (n_in, n_out) = (model.inputs().len(), model.outputs().len());
    let kernel =
        greybox::GreyBoxStream::new(model, theta, initial_state.to_vec(), *simulation, ts)?;
    Ok(Box::new(Guarded::new(kernel, n_in, n_out)))
}

/// Feeds the input channels `inputs` (one slice per input, of equal length) to `stepper` from
/// its current state and returns its output channels.
pub fn run(stepper: &mut dyn Stepper, inputs: &[&[f64]]) -> Result<Vec<Vec<f64>>> {
    if inputs.len() != stepper.n_inputs() {
        return Err(Error::CountMismatch {
            model: "the model".into(),
            what: "input channels",
            expected: stepper.n_inputs(),
            given: inputs.len(),
        });
    }
    let n = inputs.first().map_or(0, |c| c.len());
    if inputs.iter().any(|c| c.len() != n) {
        return Err(Error::InvalidData(
            "the input channels differ in length; give every channel the same samples".into(),
        ));
    }
    let mut outputs = vec![Vec::with_capacity(n); stepper.n_outputs()];
    let (mut u, mut y) = (vec![0.0; inputs.len()], vec![0.0; stepper.n_outputs()]);
    for k in 0..n {
        for (uc, c) in u.iter_mut().zip(inputs) {
            *uc = c[k];
        }
        stepper.step(&u, &mut y)?;
        for (o, v) in outputs.iter_mut().zip(&y) {
            o.push(*v);
        }
    }
    Ok(outputs)
}

/// [`compensate`](crate::model::compensate::compensate) by a compensator, from its initial
/// state (it is reset first): step s is given r_{s+p}, p its
/// [`preview`](Compensator::preview), the last reference repeated past the record's end, as
/// the batch does; equal to the batch ([`compensate_within`] with the compensator's
/// [`limits`](Compensator::limits)).
///
/// [`compensate_within`]: crate::model::compensate::compensate_within
pub fn compensate_stream(
    compensator: &mut dyn Compensator,
    reference: &[f64],
) -> Result<Compensation> {
    crate::model::compensate::check_reference(reference)?;
    compensator.reset();
    let (n, preview) = (reference.len(), compensator.preview());
    let (mut u, mut predicted, mut clipped) =
        (Vec::with_capacity(n), Vec::with_capacity(n), Vec::new());
    for s in 0..n {
        let step = compensator.step(reference[(s + preview).min(n - 1)])?;
        u.push(step.u);
        predicted.push(step.predicted);
        if step.clipped {
            clipped.push(s);
        }
    }
    Ok(Compensation {
        reference: reference.to_vec(),
        u,
        predicted,
        clipped,
        settled_from: preview,
    })
}
