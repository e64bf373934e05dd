//! Grey-box models (the built-in ones and equation files) one sample at a time, with the
//! saved integrator, sub-steps and input interpolation.
//!
//! A step is lazy by one interval: step k first integrates the state over the interval
//! [t_{k−1}, t_k] — now that both of its ends u_{k−1}, u_k are known — then gives
//! y_k = h(x(t_k), u_k). The interval is integrated by the batch's own code
//! (`greybox::simulate::advance_interval`) on a two-sample track [u_{k−1}, u_k] with the time
//! origin at t_{k−1}, so with zero-order hold *and* with linear interpolation the stream
//! equals the batch simulation to the bit (the fixed-size RK4 kernels the batch takes for
//! some models equal its generic path to the bit, `fixed_path_equals_the_generic_path`). The
//! one exception: with linear interpolation the batch reads u_k at the sample as
//! u_k + 0·(u_{k+1} − u_k), which turns an input of −0.0 into +0.0 when u_{k+1} ≥ u_k; the
//! stream passes u_k itself to h.
//!
//! A band-limited input is interpolated from the whole record's spectrum (non-causal): the
//! stream integrates it with linear interpolation between the samples instead, and
//! [`FittedModel::streaming_differs`](crate::model::saved::FittedModel::streaming_differs)
//! says so.

use super::Kernel;
use crate::model::greybox::simulate::{advance_interval, check_integrator, InputTrack, Workspace};
use crate::model::greybox::{InputInterpolation, Simulation, StateSpaceModel};
use crate::{Error, Result};

/// A state-space model streamed.
pub(super) struct GreyBoxStream {
    model: Box<dyn StateSpaceModel>,
    theta: Vec<f64>,
    x0: Vec<f64>,
    x: Vec<f64>,
    simulation: Simulation,
    ts: f64,
    /// [u_{k−1}, u_k]: the interval the next step integrates.
    track: InputTrack,
    /// The integrator's buffers, kept from sample to sample (no allocation per step).
    work: Workspace,
    /// The discrete-time recursion's next state.
    next: Vec<f64>,
}

impl std::fmt::Debug for GreyBoxStream {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GreyBoxStream")
            .field("kind", &self.model.kind())
            .field("theta", &self.theta)
            .field("x", &self.x)
            .field("simulation", &self.simulation)
            .field("ts", &self.ts)
            .finish()
    }
}

impl GreyBoxStream {
    /// `model` with values `theta` from the initial state `x0`, sampled every `ts`.
    pub(super) fn new(
        model: Box<dyn StateSpaceModel>,
        theta: Vec<f64>,
        x0: Vec<f64>,
        simulation: Simulation,
        ts: f64,
    ) -> Result<Self> {
        if !(ts.is_finite() && ts > 0.0) {
            return Err(Error::InvalidData(format!(
                "the sample time is {ts}; give the sample time in seconds, a positive finite number"
            )));
        }
        let interpolation = match simulation.interpolation {
            InputInterpolation::ZeroOrderHold => InputInterpolation::ZeroOrderHold,
            InputInterpolation::Linear | InputInterpolation::BandLimited => {
                InputInterpolation::Linear
            }
        };
        let simulation = Simulation {
            interpolation,
            ..simulation
        };
        let n_inputs = model.inputs().len();
        let zeros = vec![0.0; 2];
        let channels = vec![zeros.as_slice(); n_inputs];
        let track = InputTrack::new(&channels, &simulation)?;
        check_integrator(model.as_ref(), &track, simulation.integrator)?;
        Ok(Self {
            x: x0.clone(),
            next: vec![0.0; x0.len()],
            work: Workspace::new(x0.len(), n_inputs),
            x0,
            theta,
            simulation,
            ts,
            track,
            model,
        })
    }
}

impl Kernel for GreyBoxStream {
    fn reset(&mut self) {
        self.x.copy_from_slice(&self.x0);
    }
    fn step(&mut self, k: usize, u: &[f64], y: &mut [f64]) -> Result<()> {
        if k > 0 {
            self.track.set_sample(1, u);
            advance_interval(
                self.model.as_ref(),
                &self.theta,
                &self.track,
                self.ts,
                self.simulation.integrator,
                k - 1,
                &mut self.x,
                &mut self.work,
                &mut self.next,
            )?;
        }
        if self.x.iter().any(|v| !v.is_finite()) {
            return Err(Error::Diverged {
                index: k,
                reason: "the state is not finite".into(),
            });
        }
        self.model.output(&self.x, u, &self.theta, y);
        self.track.set_sample(0, u);
        Ok(())
    }
}
