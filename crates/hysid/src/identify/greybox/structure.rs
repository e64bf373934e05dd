//! A grey-box model bound to data: the model, its simulation settings and its initial states
//! per experiment, as an [`OutputErrorModel`].
//!
//! # Parameter vector
//!
//! `[model parameters…, initial states…]`: after the model's own parameters come the initial
//! states of every experiment, named `x0.<state>.e<k>` (k = 1…E), fixed unless asked to be
//! estimated (MATLAB's `InitialStates(i).Fixed`).

use crate::data::IdData;
use crate::identify::output_error::{OutputErrorModel, SensitivitySink};
use crate::model::greybox::simulate::{
    simulate, simulate_sensitivities, InputTrack, Integrator, Simulation,
};
use crate::model::greybox::StateSpaceModel;
use crate::model::{Parameter, ParameterSet};
use crate::{Error, Result};
use std::sync::Arc;

/// Initial states of every experiment and which of them are estimated.
#[derive(Clone, Debug, PartialEq)]
pub struct InitialStates {
    /// x(t₀) per experiment.
    pub values: Vec<Vec<f64>>,
    /// Per state: estimated (true) or fixed at its value (false), the same in every
    /// experiment.
    pub estimated: Vec<bool>,
}

impl InitialStates {
    /// All states start at zero, fixed (a system at rest).
    pub fn at_rest(n_states: usize, n_experiments: usize) -> Self {
        Self {
            values: vec![vec![0.0; n_states]; n_experiments],
            estimated: vec![false; n_states],
        }
    }
}

/// A model bound to data (see the module docs).
pub struct GreyBox {
    model: Arc<dyn StateSpaceModel>,
    sim: Simulation,
    initial: InitialStates,
    tracks: Vec<InputTrack>,
    ts: f64,
}

impl GreyBox {
    /// Binds `model` to the experiments of `data` (its input and output channels must match
    /// the model's in number), preparing the inputs for `sim`.
    pub fn new(
        model: Arc<dyn StateSpaceModel>,
        data: &IdData,
        sim: Simulation,
        initial: InitialStates,
    ) -> Result<Self> {
        let (nu, ny, nx) = (
            model.inputs().len(),
            model.outputs().len(),
            model.states().len(),
        );
        let model_name = || format!("the {} model", model.kind());
        for (what, expected, given) in [
            ("input channels", nu, data.input_channels().len()),
            ("output channels", ny, data.output_channels().len()),
        ] {
            if given != expected {
                return Err(Error::CountMismatch {
                    model: model_name(),
                    what,
                    expected,
                    given,
                });
            }
        }
        if initial.values.len() != data.n_experiments() {
            return Err(Error::CountMismatch {
                model: format!("the data ({} experiments)", data.n_experiments()),
                what: "initial-state vectors, one per experiment",
                expected: data.n_experiments(),
                given: initial.values.len(),
            });
        }
        let lengths = initial.values.iter().map(Vec::len);
        if let Some(given) = lengths
            .chain([initial.estimated.len()])
            .find(|&len| len != nx)
        {
            return Err(Error::CountMismatch {
                model: model_name(),
                what: "states (initial-state values per experiment)",
                expected: nx,
                given,
            });
        }
        let tracks = data
            .experiments()
            .iter()
            .map(|e| {
                let channels: Vec<&[f64]> = (0..nu).map(|c| e.input(c)).collect();
                InputTrack::new(&channels, &sim)
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Self {
            model,
            sim,
            initial,
            tracks,
            ts: data.ts(),
        })
    }

    /// The model.
    pub fn model(&self) -> &dyn StateSpaceModel {
        self.model.as_ref()
    }

    /// The simulation settings.
    pub fn simulation(&self) -> Simulation {
        self.sim
    }

    /// The full parameter set: the model's parameters (`model_params`, e.g. with the user's
    /// initial values and bounds) followed by the initial states.
    pub fn parameter_set(&self, model_params: &ParameterSet) -> ParameterSet {
        let states = self.model.states();
        let mut params: Vec<Parameter> = model_params.iter().cloned().collect();
        for (e, x0) in self.initial.values.iter().enumerate() {
            for (i, state) in states.iter().enumerate() {
                params.push(
                    Parameter::new(format!("x0.{}.e{}", state.name, e + 1), x0[i])
                        .unit(state.unit.clone())
                        .fixed(!self.initial.estimated[i]),
                );
            }
        }
        ParameterSet::new(params).expect("state and parameter names do not clash")
    }

    fn n_model_params(&self) -> usize {
        self.model.parameters().len()
    }

    /// x(t₀) of experiment `exp` from the full parameter vector.
    fn initial_state<'t>(&self, theta: &'t [f64], exp: usize) -> &'t [f64] {
        let n = self.model.states().len();
        let start = self.n_model_params() + exp * n;
        &theta[start..start + n]
    }
}

/// Where one entry ∂y_o/∂p of the sensitivity pass comes from, p a free parameter.
#[derive(Clone, Copy, Debug)]
enum Entry {
    /// An initial state of another experiment: no effect here.
    Zero,
    /// Column `c` of S, plus the direct term ∂h/∂θ of model parameter `direct`.
    Column { c: usize, direct: Option<usize> },
}

impl Entry {
    /// The entry for the output's Jacobian rows `hx` = ∂h_o/∂x and `ht` = ∂h_o/∂θ and
    /// S (row-major n × q): Σ_j hx_j·S_jc in the order of j, from −0 as `Iterator::sum`
    /// starts, then + ht of the direct term.
    #[inline]
    fn derivative(self, hx: &[f64], ht: &[f64], s: &[f64], q: usize) -> f64 {
        match self {
            Entry::Zero => 0.0,
            Entry::Column { c, direct } => {
                let mut acc = -0.0;
                for (j, h) in hx.iter().enumerate() {
                    acc += h * s[j * q + c];
                }
                if let Some(i) = direct {
                    acc += ht[i];
                }
                acc
            }
        }
    }
}

impl OutputErrorModel for GreyBox {
    fn parameters(&self) -> ParameterSet {
        self.parameter_set(&self.model.parameters())
    }

    fn n_outputs(&self) -> usize {
        self.model.outputs().len()
    }

    /// A simulation with sensitivities costs a few plain ones, and from a reasonable start
    /// nearly every trial point is accepted: computing them at every trial point saves the
    /// repeated simulation of each accepted one.
    fn speculative_sensitivities(&self) -> bool {
        true
    }

    /// Sub-steps times stages: RK4 four evaluations a sub-step, Newmark one, Dormand–Prince
    /// six stages at an assumed four steps a sample (the figure of the work estimate); a
    /// discrete-time recursion one.
    fn steps_per_sample(&self) -> u64 {
        if self.model.discrete_time() {
            return 1;
        }
        let (substeps, stages) = match self.sim.integrator {
            Integrator::Rk4 { substeps } => (substeps, 4),
            Integrator::Newmark { substeps } => (substeps, 1),
            Integrator::Adaptive { .. } => (4, 6),
        };
        u64::try_from(substeps.max(1)).unwrap_or(u64::MAX) * stages
    }

    fn simulate(
        &self,
        theta: &[f64],
        _data: &IdData,
        exp: usize,
        y: &mut [Vec<f64>],
    ) -> Result<()> {
        let p = self.n_model_params();
        let (model_theta, x0) = (&theta[..p], self.initial_state(theta, exp));
        let track = &self.tracks[exp];
        let mut u = vec![0.0; track.n_channels()];
        let mut out = vec![0.0; y.len()];
        simulate(
            self.model.as_ref(),
            model_theta,
            x0,
            track,
            self.ts,
            self.sim.integrator,
            |k, x| {
                track.at(k, 0.0, &mut u);
                self.model.output(x, &u, model_theta, &mut out);
                for (channel, v) in y.iter_mut().zip(&out) {
                    channel[k] = *v;
                }
            },
        )
    }

    fn simulate_sensitivities(
        &self,
        theta: &[f64],
        _data: &IdData,
        exp: usize,
        free: &[usize],
        sink: &mut SensitivitySink<'_>,
    ) -> Option<Result<()>> {
        let substeps = match self.sim.integrator {
            Integrator::Rk4 { substeps } => substeps,
            // A discrete-time model runs its recursion whatever the integrator.
            _ if self.model.discrete_time() => 1,
            _ => return None,
        };
        let p = self.n_model_params();
        let nx = self.model.states().len();
        let ny = self.model.outputs().len();
        let (model_theta, x0) = (&theta[..p], self.initial_state(theta, exp));
        // Columns of S: the free model parameters, then this experiment's free initial states.
        let params: Vec<usize> = free.iter().copied().filter(|&i| i < p).collect();
        let own = p + exp * nx..p + (exp + 1) * nx;
        let initial: Vec<usize> = free
            .iter()
            .filter(|i| own.contains(i))
            .map(|&i| i - own.start)
            .collect();
        let q = params.len() + initial.len();
        // Where each free index's sensitivity comes from.
        let entries: Vec<Entry> = free
            .iter()
            .map(|&i| {
                let (column, direct) = if i < p {
                    (params.iter().position(|&j| j == i), Some(i))
                } else if own.contains(&i) {
                    let state = initial.iter().position(|&j| j == i - own.start);
                    (state.map(|c| params.len() + c), None)
                } else {
                    (None, None)
                };
                column.map_or(Entry::Zero, |c| Entry::Column { c, direct })
            })
            .collect();
        let track = &self.tracks[exp];
        let mut u = vec![0.0; track.n_channels()];
        let (mut y, mut hx, mut ht) = (vec![0.0; ny], vec![0.0; ny * nx], vec![0.0; ny * p]);
        let mut row = vec![0.0; ny * free.len()];
        let model = self.model.as_ref();
        // What does not change from sample to sample is asked for once: the output's
        // Jacobians when the model says they are constant (at x(t₀), the input unread), the
        // input when the output does not read it.
        let constant_jacobians = model.output_jacobians_are_constant();
        let reads_input = model.output_reads_input();
        let mut has_output_jacobian =
            !constant_jacobians || model.output_jacobians(x0, &u, model_theta, &mut hx, &mut ht);
        let outcome = simulate_sensitivities(
            model,
            model_theta,
            x0,
            track,
            self.ts,
            substeps,
            &params,
            &initial,
            |k, x, s| {
                if reads_input {
                    track.at(k, 0.0, &mut u);
                }
                model.output(x, &u, model_theta, &mut y);
                if !constant_jacobians {
                    has_output_jacobian &=
                        model.output_jacobians(x, &u, model_theta, &mut hx, &mut ht);
                }
                // ∂y/∂p = h_x S + h_θ (the direct term only for model parameters).
                let nf = entries.len();
                for o in 0..ny {
                    let (hx, ht) = (&hx[o * nx..][..nx], &ht[o * p..][..p]);
                    for (value, entry) in row[o * nf..][..nf].iter_mut().zip(&entries) {
                        *value = entry.derivative(hx, ht, s, q);
                    }
                }
                sink(k, &y, &row)
            },
        );
        match outcome {
            Ok(true) if has_output_jacobian => Some(Ok(())),
            Ok(_) => None,
            Err(e) => Some(Err(e)),
        }
    }
}
