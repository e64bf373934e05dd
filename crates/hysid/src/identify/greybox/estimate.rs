//! Output-error estimation of a grey-box model (MATLAB's `nlgreyest`), with multi-start.
//!
//! With several starts, each is first fitted for a few iterations on a leading part of the
//! records (screening); the best screened start is then fitted on all the data. Screening
//! keeps a multi-start affordable: most poor starts are recognisable after a few iterations.

use super::hold_check::{hold_check, HoldCheck};
use super::structure::{GreyBox, InitialStates};
use crate::data::IdData;
use crate::identify::multistart::{best_of, draw_starts, StartOutcome};
use crate::identify::{OutputError, OutputErrorFit};
use crate::model::greybox::{InputInterpolation, Simulation, StateSpaceModel};
use crate::model::saved::FittedGreyBox;
use crate::model::saved::FittedModel;
use crate::model::ParameterSet;
use crate::numerics::{Control, DampingScale, IterationRecord, LmConfig, Observer};
use crate::{Error, Result};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// Settings of a grey-box estimation.
#[derive(Clone, Debug)]
pub struct GreyBoxEstimation {
    /// Integrator and input interpolation.
    pub simulation: Simulation,
    /// Levenberg–Marquardt settings of the final fit.
    pub lm: LmConfig,
    /// Weight per output (default 1).
    pub output_weights: Option<Vec<f64>>,
    /// Number of starts (1: the given start only).
    pub starts: usize,
    /// Seed of the random starts.
    pub seed: u64,
    /// Iterations of each screening fit.
    pub screening_iterations: usize,
    /// Leading samples of each experiment used for screening (None: all).
    pub screening_samples: Option<usize>,
    /// Sees "start k/N" after each screening fit; [`Control::Stop`] skips the remaining
    /// starts (each is then only evaluated where it was drawn), keeping the best so far.
    pub observer: Observer,
}

impl Default for GreyBoxEstimation {
    fn default() -> Self {
        Self {
            simulation: Simulation::default(),
            // MINPACK's scaling: with it the engine certifies on NIST's problems
            // (docs/numerics.md §1.1).
            lm: LmConfig {
                damping_scale: DampingScale::RunningMax,
                // Past 100 iterations a search still improving goes on (to 1000), and one
                // that ends off a minimum restarts: MGH17, BoxBOD, MGH10 and Bennett5.
                extra_iterations: 900,
                restarts: 2,
                ..LmConfig::default()
            },
            output_weights: None,
            starts: 1,
            seed: 0,
            screening_iterations: 10,
            screening_samples: Some(16_384),
            observer: Observer::none(),
        }
    }
}

/// A fitted grey-box model.
#[derive(Clone, Debug)]
pub struct GreyBoxFit {
    /// The final output-error fit (parameters with initial states, std, fit %, report).
    pub fit: OutputErrorFit,
    /// The screening outcome of every start (empty for a single start).
    pub starts: Vec<StartOutcome>,
    /// Wall-clock time of the whole estimation.
    pub elapsed_s: f64,
    /// With zero-order hold of the input (the default): whether a band-limited input should
    /// have been interpolated band-limited ([`super::hold_check`](mod@super::hold_check)); None with another
    /// interpolation and for a discrete-time model.
    pub hold_check: Option<HoldCheck>,
    /// How the model was evaluated ([`StateSpaceModel::evaluation`]): native code or the
    /// tape of an equation model; None for a built-in model.
    pub evaluation: Option<String>,
}

impl GreyBoxFit {
    /// The warnings of the fit, one line each (the report's `warnings`).
    pub fn warnings(&self) -> Vec<String> {
        self.hold_check
            .iter()
            .filter_map(HoldCheck::warning)
            .collect()
    }

    /// The fitted model: the model's own parameters (the leading ones of the estimate) with
    /// their standard deviations, the first experiment's initial state, and `simulation`.
    pub fn fitted_model(&self, model: &dyn StateSpaceModel, simulation: Simulation) -> FittedModel {
        let p = model.parameters().len();
        let n = model.states().len();
        let all = &self.fit.parameters;
        let values = all.values();
        FittedModel::GreyBox(FittedGreyBox {
            kind: model.kind().to_string(),
            parameters: all.leading(p),
            std: self.fit.std()[..p].to_vec(),
            simulation,
            initial_state: values[p..p + n].to_vec(),
        })
    }

    /// The fitted initial states of the `experiments` experiments, fixed (for
    /// re-simulation): the estimate holds the model's own parameters first, then n states
    /// per experiment.
    pub fn initial_states(&self, model: &dyn StateSpaceModel, experiments: usize) -> InitialStates {
        let n = model.states().len();
        let p = model.parameters().len();
        let v = self.fit.parameters.values();
        InitialStates {
            values: (0..experiments)
                .map(|e| v[p + e * n..p + (e + 1) * n].to_vec())
                .collect(),
            estimated: vec![false; n],
        }
    }

    /// How many multi-start starts reached a screened criterion within the relative
    /// `tolerance` of the best one (e.g. 0.01: within 1 %).
    pub fn starts_near_best(&self, tolerance: f64) -> usize {
        let best = self
            .starts
            .iter()
            .map(|s| s.cost)
            .fold(f64::INFINITY, f64::min);
        self.starts
            .iter()
            .filter(|s| s.cost <= (1.0 + tolerance) * best)
            .count()
    }
}

/// Errors ([`Error::NotExciting`], naming the first input channel and the record) unless
/// every record has an input that takes more than one value.
fn check_inputs_move(data: &IdData) -> Result<()> {
    let channels = data.input_channels().len();
    for e in 0..data.n_experiments() {
        let moves = (0..channels).any(|c| {
            let u = data.input(e, c);
            u.split_first()
                .is_some_and(|(first, rest)| rest.iter().any(|v| v != first))
        });
        if !moves {
            let channel = data
                .input_channels()
                .first()
                .map_or_else(|| "u".to_string(), |c| c.name.clone());
            let record = if data.n_experiments() > 1 {
                format!(" in record {}", e + 1)
            } else {
                String::new()
            };
            return Err(Error::NotExciting {
                channel,
                reason: format!(
                    "it is constant{record}, so the record cannot show how the model responds \
                     to it; fit a record whose input varies (a step, a sweep, a multisine)"
                ),
            });
        }
    }
    Ok(())
}

impl GreyBoxEstimation {
    /// Fits `model` to `data` from the parameters `model_params` (values, bounds, fixed flags
    /// of the model's own parameters) and the initial states `initial`.
    ///
    /// Errors: [`Error::NotExciting`] when a record's inputs are all constant (the output
    /// error's cross-correlation with the input is then undefined, and the record cannot
    /// tell the input's effect from the parameters'); the model's and the data's errors.
    pub fn estimate(
        &self,
        model: Arc<dyn StateSpaceModel>,
        data: &IdData,
        model_params: &ParameterSet,
        initial: InitialStates,
        callback: &mut dyn FnMut(&IterationRecord) -> Control,
    ) -> Result<GreyBoxFit> {
        let clock = Instant::now();
        check_names(model.as_ref(), model_params)?;
        check_inputs_move(data)?;
        let structure = GreyBox::new(model.clone(), data, self.simulation, initial.clone())?;
        let params = structure.parameter_set(model_params);
        params.validate()?;
        let (start, starts) = if self.starts > 1 {
            self.screen(model.clone(), data, &params, initial)?
        } else {
            (params, Vec::new())
        };
        let estimator = OutputError {
            config: self.lm.clone(),
            output_weights: self.output_weights.clone(),
            skip: 0,
        };
        let fit = estimator.estimate(&structure, data, &start, callback)?;
        // A discrete-time model has no input between samples to interpolate.
        let held = self.simulation.interpolation == InputInterpolation::ZeroOrderHold
            && !model.discrete_time();
        let hold_check = held.then(|| hold_check(data, &fit.simulated));
        Ok(GreyBoxFit {
            fit,
            starts,
            elapsed_s: clock.elapsed().as_secs_f64(),
            hold_check,
            evaluation: model.evaluation(),
        })
    }

    /// Short fits from every start on the leading samples; the best start, moved to where its
    /// screening fit ended, and every outcome.
    fn screen(
        &self,
        model: Arc<dyn StateSpaceModel>,
        data: &IdData,
        params: &ParameterSet,
        initial: InitialStates,
    ) -> Result<(ParameterSet, Vec<StartOutcome>)> {
        let shortest = data
            .experiments()
            .iter()
            .map(|e| e.len())
            .min()
            .unwrap_or(0);
        let leading = self.screening_samples.map_or(shortest, |n| n.min(shortest));
        let screen_data = if leading < shortest {
            data.slice(0..leading)?
        } else {
            data.clone()
        };
        let structure = GreyBox::new(model, &screen_data, self.simulation, initial)?;
        let estimator = OutputError {
            config: LmConfig {
                max_iterations: self.screening_iterations,
                extra_iterations: 0,
                restarts: 0,
                ..self.lm.clone()
            },
            output_weights: self.output_weights.clone(),
            skip: 0,
        };
        let starts = draw_starts(params, self.starts, self.seed);
        let total = starts.len();
        let done = AtomicUsize::new(0);
        let fit = |p: &ParameterSet| {
            let observer = &self.observer;
            let mut stop_when_asked = |_: &IterationRecord| {
                if observer.should_stop("start") {
                    Control::Stop
                } else {
                    Control::Continue
                }
            };
            let result = estimator.estimate(&structure, &screen_data, p, &mut stop_when_asked);
            let finished = done.fetch_add(1, Ordering::Relaxed) + 1;
            observer.report("start", finished, total);
            result
        };
        let (best, outcomes) = best_of(&starts, &fit)?;
        Ok((best.parameters, outcomes))
    }
}

/// The given parameters must be the model's, in its order.
fn check_names(model: &dyn StateSpaceModel, params: &ParameterSet) -> Result<()> {
    let expected = model.parameters().names();
    if params.names() != expected {
        return Err(Error::ModelMismatch(format!(
            "the {} model's parameters are {}, got {}",
            model.kind(),
            expected.join(", "),
            params.names().join(", ")
        )));
    }
    Ok(())
}
