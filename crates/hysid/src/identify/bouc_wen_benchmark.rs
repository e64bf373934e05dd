//! The hysteretic benchmark of Noël & Schoukens (2016) as one typed recipe: fit the Bouc–Wen
//! oscillator on a training record, score test records by e_RMS in simulation mode, and
//! generate test records by the benchmark's own recipe (docs/benchmarks.md §1).
//!
//! # Protocol
//!
//! * Records are sampled at f_s = 750 Hz, with columns `t_s`, `u_N`, `y_m`.
//! * The model is [`BoucWen`] (m ÿ + c ẏ + k y + z = u, ż = α ẏ − β(γ|ẏ||z|^{ν−1}z − δ ẏ|z|^ν)),
//!   fitted by output error from rest with RK4 and band-limited input interpolation.
//! * A test record is scored by e_RMS = √(1/N Σ (y(k) − ŷ(k))²), ŷ simulated from rest or, in
//!   the periodic steady state, as the second half of a simulation of the input repeated
//!   twice.
//! * A test record is generated as the official simulator does: the input at 15 kHz
//!   (20 × 750 Hz), Newmark-β (γ = ½, β = ¼) at 15 kHz, low-pass filtering and decimation back
//!   to 750 Hz, then optional white Gaussian output noise.
//!
//! Reference: J.-P. Noël, M. Schoukens, "Hysteretic benchmark with a dynamic nonlinearity",
//! Workshop on Nonlinear System Identification Benchmarks, 2016.

use crate::model::saved::FittedGreyBox;
use std::sync::Arc;

use crate::data::{CsvSpec, IdData};
use crate::error::{Error, Result};
use crate::identify::greybox::{GreyBoxEstimation, GreyBoxFit, InitialStates};
use crate::model::greybox::models::BoucWen;
use crate::model::greybox::simulate::band_limited_upsample;
use crate::model::greybox::{InputInterpolation, Integrator, Simulation, StateSpaceModel};
use crate::model::saved::FittedModel;
use crate::model::ParameterSet;
use crate::numerics::metrics;
use crate::numerics::signal::{decimate_fir, gaussian_noise, multisine, sine_sweep};
use crate::numerics::{Control, IterationRecord, LmConfig, Observer};

/// Sampling frequency of the benchmark records \[Hz\].
pub const FS: f64 = 750.0;

/// Upsampling factor of the official simulator (750 Hz → 15 kHz).
pub const UP: usize = 20;

/// Published e_RMS \[m\] on the official multisine test set (docs/benchmarks.md §1.4).
pub const PUBLISHED: [(&str, f64); 3] = [
    ("dynoNet (Forgione & Piga 2021)", 4.52e-5),
    ("decoupled polynomial nonlinear state space", 1.87e-5),
    ("local-model network", 16.3e-5),
];

/// The column layout of a benchmark record: inputs `u_N`, outputs `y_m`, time `t_s`.
pub fn record_spec() -> CsvSpec {
    CsvSpec {
        inputs: vec!["u_N".into()],
        outputs: vec!["y_m".into()],
        time: Some("t_s".into()),
        ts: None,
        ..CsvSpec::default()
    }
}

/// The settings of the benchmark fit.
#[derive(Clone, Debug)]
pub struct BoucWenBenchmark {
    /// RK4 substeps per sample (≥ 1).
    pub substeps: usize,
    /// Multi-start starts (≥ 1).
    pub starts: usize,
    /// Seed of the multi-start draws.
    pub seed: u64,
    /// Score test records in the periodic steady state instead of from rest.
    pub steady_state: bool,
    /// Sees the multi-start's progress and may stop it (see [`GreyBoxEstimation::observer`]).
    pub observer: Observer,
}

/// The benchmark fit and its test scores.
#[derive(Clone, Debug)]
pub struct BoucWenResult {
    /// The output-error fit on the training record.
    pub fit: GreyBoxFit,
    /// The fitted model, as saved and simulated.
    pub model: FittedModel,
    /// e_RMS of the simulated output on the training record \[m\].
    pub training_e_rms: f64,
    /// One score per test record.
    pub tests: Vec<BenchmarkTest>,
}

/// A scored test record.
#[derive(Clone, Debug)]
pub struct BenchmarkTest {
    /// Where the record came from (a file name).
    pub source: String,
    /// e_RMS \[m\].
    pub e_rms: f64,
    /// fit % of the simulated output.
    pub fit_percent: f64,
    /// Measured output \[m\].
    pub y: Vec<f64>,
    /// Simulated output \[m\].
    pub yhat: Vec<f64>,
}

impl BenchmarkTest {
    /// The measured minus the simulated output.
    pub fn error(&self) -> Vec<f64> {
        self.y.iter().zip(&self.yhat).map(|(a, b)| a - b).collect()
    }
}

impl BoucWenBenchmark {
    /// The nominal parameters of the benchmark with every free start value multiplied by
    /// `start_factor` (the protocol's test of robustness to the start).
    pub fn start_values(start_factor: f64) -> Result<ParameterSet> {
        if !(start_factor.is_finite() && start_factor > 0.0) {
            return Err(Error::invalid_option(
                "start_factor",
                start_factor,
                format!(
                "start factor {start_factor}: give a finite positive multiple of the nominal values"
            ),
            ));
        }
        let mut params = BoucWen.parameters();
        for i in params.free_indices() {
            params.get_mut(i).value *= start_factor;
        }
        Ok(params)
    }

    /// The integrator settings of the fit: RK4 with band-limited input interpolation.
    pub fn simulation(&self) -> Simulation {
        Simulation {
            integrator: Integrator::Rk4 {
                substeps: self.substeps.max(1),
            },
            interpolation: InputInterpolation::BandLimited,
        }
    }

    /// The grey-box estimation the fit runs (for its work estimate, before running it).
    pub fn estimation(&self) -> GreyBoxEstimation {
        GreyBoxEstimation {
            simulation: self.simulation(),
            starts: self.starts.max(1),
            seed: self.seed,
            observer: self.observer.clone(),
            // The benchmark's published figures come from the improvement rule alone.
            lm: LmConfig::improvement_rule(),
            ..GreyBoxEstimation::default()
        }
    }

    /// Fits the oscillator to `train` from the start values `params` and scores every record
    /// of `tests` (`(source, record)` pairs).
    pub fn run(
        &self,
        train: &IdData,
        params: &ParameterSet,
        tests: &[(String, IdData)],
        callback: &mut dyn FnMut(&IterationRecord) -> Control,
    ) -> Result<BoucWenResult> {
        // A test output that does not vary leaves its fit % undefined: refused before the fit.
        for (source, data) in tests {
            if !crate::data::varies(data.experiment(0).output(0)) {
                return Err(Error::InvalidData(format!(
                    "test record {source}: the output does not vary at double precision, so it cannot score a model (fit % undefined); check the output column"
                )));
            }
        }
        let simulation = self.simulation();
        let fit = self.estimation().estimate(
            Arc::new(BoucWen),
            train,
            params,
            InitialStates::at_rest(3, 1),
            callback,
        )?;
        let model = fit.fitted_model(&BoucWen, simulation);
        let tests = tests
            .iter()
            .map(|(source, data)| score(&model, source, data, self.steady_state))
            .collect::<Result<Vec<_>>>()?;
        Ok(BoucWenResult {
            training_e_rms: fit.fit.mse[0][0].sqrt(),
            fit,
            model,
            tests,
        })
    }
}

/// e_RMS of `model` on a test record, from rest or in the periodic steady state.
pub fn score(
    model: &FittedModel,
    source: &str,
    data: &IdData,
    steady_state: bool,
) -> Result<BenchmarkTest> {
    let exp = data.experiment(0);
    let (u, y) = (exp.input(0), exp.output(0));
    let yhat = if steady_state {
        let twice: Vec<f64> = u.iter().chain(u).copied().collect();
        model.simulate(&[&twice], data.ts(), None)?.remove(0)[u.len()..].to_vec()
    } else {
        model.simulate(&[u], data.ts(), None)?.remove(0)
    };
    Ok(BenchmarkTest {
        source: source.to_string(),
        e_rms: metrics::rmse(y, &yhat),
        fit_percent: metrics::fit_percent(y, &yhat),
        y: y.to_vec(),
        yhat,
    })
}

/// The excitation of a generated test record.
#[derive(Clone, Copy, Debug)]
pub enum TestSignal {
    /// The benchmark's random-phase multisine (5–150 Hz, 8192 samples per period, 50 N rms
    /// per line set) with `periods` periods (≥ 1).
    Multisine {
        /// Number of periods.
        periods: usize,
    },
    /// The benchmark's sine sweep (40 N, 18 Hz band, 1/6 Hz/s) of `samples` samples (≥ 2) at
    /// 750 Hz.
    Sweep {
        /// Number of samples at 750 Hz.
        samples: usize,
    },
}

/// A generated record at 750 Hz: time \[s\], force u \[N\], displacement y \[m\].
#[derive(Clone, Debug)]
pub struct GeneratedRecord {
    /// Time \[s\].
    pub t: Vec<f64>,
    /// Input force \[N\].
    pub u: Vec<f64>,
    /// Output displacement \[m\].
    pub y: Vec<f64>,
}

/// Simulates a test record by the official recipe (see the module documentation), with
/// white Gaussian output noise of standard deviation `noise` \[m\] (0 for none).
pub fn generate(signal: TestSignal, noise: f64, seed: u64) -> Result<GeneratedRecord> {
    let (u, u_fine) = match signal {
        TestSignal::Multisine { periods } => {
            if periods < 1 {
                return Err(Error::invalid_option(
                    "periods",
                    0,
                    "a multisine test record needs at least 1 period".into(),
                ));
            }
            let u = multisine(8192, periods, FS, 5.0, 150.0, 50.0, seed)?;
            // The multisine is band-limited and periodic: its 15 kHz samples are exact.
            let fine = band_limited_upsample(&u, UP);
            (u, fine)
        }
        TestSignal::Sweep { samples } => {
            if samples < 2 {
                return Err(Error::invalid_option(
                    "samples",
                    samples,
                    "a sine-sweep test record needs at least 2 samples".into(),
                ));
            }
            let fine = sine_sweep(samples * UP, FS * UP as f64, 40.0, 18.0, 1.0 / 6.0);
            (fine.iter().step_by(UP).copied().collect(), fine)
        }
    };
    let input = IdData::input_only(1.0 / (FS * UP as f64), "u", u_fine)?;
    let model = FittedModel::GreyBox(FittedGreyBox {
        kind: "bouc_wen".into(),
        parameters: BoucWen.parameters(),
        std: vec![0.0; 7],
        simulation: Simulation {
            integrator: Integrator::Newmark { substeps: 1 },
            interpolation: InputInterpolation::Linear,
        },
        initial_state: vec![0.0; 3],
    });
    let y_fine = model
        .simulate(&[input.experiment(0).input(0)], input.ts(), None)?
        .remove(0);
    let mut y = decimate_fir(&y_fine, UP);
    y.truncate(u.len());
    if noise > 0.0 {
        let e = gaussian_noise(y.len(), noise, seed.wrapping_add(7))?;
        y.iter_mut().zip(&e).for_each(|(a, b)| *a += b);
    }
    let t: Vec<f64> = (0..u.len()).map(|k| k as f64 / FS).collect();
    Ok(GeneratedRecord { t, u, y })
}
