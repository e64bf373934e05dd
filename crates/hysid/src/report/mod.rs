//! The report every command writes: `hysid.report/1`.
//!
//! One typed [`Report`] (serde both ways, JSON Schema generated from the types by
//! [`report_schema`]) with the same top-level keys for every command:
//!
//! | key | content |
//! |---|---|
//! | `schema` | `"hysid.report/1"` |
//! | `command` | the command that wrote it, e.g. `"identify cascade"` |
//! | `version` | hysid's version |
//! | `data` | [`DataSummary`]: source files, samples, experiments, sample time |
//! | `model` | the saved-model object ([`ModelFile`], `hysid.model/1`) |
//! | `fit` | [`FitSummary`]: fit %, RMSE, loss, FPE, AIC, and per experiment |
//! | `search` | [`SearchSummary`]: iterations, evaluations, termination `{code, message}`, elapsed |
//! | `uncertainty` | [`UncertaintySummary`]: how the standard deviations were obtained |
//! | `validation` | [`ValidationEntry`] per validation/test record |
//! | `details` | command-specific (documented per command in `docs/report.md`) |
//! | `warnings` | one line per warning the command printed on stderr about its result |
//!
//! A key that does not apply is `null` (an empty list for `validation` and `warnings`), never
//! missing.
//! Multi-step commands put each step's report in `details.steps`, each a `Report` itself.
//!
//! fit % is the normalised RMSE fit 100 (1 − ‖y − ŷ‖ / ‖y − ȳ‖) of MATLAB's `compare`;
//! FPE and AIC are Akaike's (Ljung, *System Identification*, 2nd ed., 1999, §16.4).

pub mod actuator;
pub mod cascade;
pub mod compare;
pub mod compensation;
pub mod greybox;
pub mod operator;
pub mod plot;
pub mod rigid_body;
pub mod simulate;

pub use cascade::{
    cascade_report, hysteresis_report, operator_cascade_model, operator_cascade_report,
};
pub use compare::compare_report;
pub use compensation::compensation_report;
pub use greybox::{bouc_wen_benchmark_report, greybox_report, greybox_residuals};
pub use operator::{operator_report, operator_simulation};
pub use rigid_body::{rigid_body_model, rigid_body_report, RigidBodyRecord};
pub use simulate::{simulate_report, simulate_report_after};

use crate::data::IdData;
use crate::identify::OutputErrorFit;
use crate::model::saved::ModelFile;
use crate::numerics::{metrics, LmReport, Termination};
use crate::{Error, Result};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The schema tag of a report.
pub const REPORT_SCHEMA: &str = "hysid.report/1";

/// The report of one command (see the module docs).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Report {
    /// Always `hysid.report/1`.
    pub schema: String,
    /// The command that wrote the report (`identify cascade`, `greybox fit`, …).
    pub command: String,
    /// hysid's version.
    pub version: String,
    /// The data the command read or made.
    pub data: Option<DataSummary>,
    /// The fitted or simulated model (`hysid.model/1`).
    pub model: Option<ModelFile>,
    /// How well the model's simulated output fits the data.
    pub fit: Option<FitSummary>,
    /// How the search went.
    pub search: Option<SearchSummary>,
    /// How the standard deviations were obtained.
    pub uncertainty: Option<UncertaintySummary>,
    /// One entry per validation or test record.
    pub validation: Vec<ValidationEntry>,
    /// Command-specific details (null when there are none).
    pub details: serde_json::Value,
    /// Warnings about the result, one line each, the same as the command printed on stderr
    /// (e.g. a band-limited input held between samples in a grey-box fit); empty when there
    /// are none (and when read from a report written before the key existed).
    #[serde(default)]
    pub warnings: Vec<String>,
}

/// The data a command read or made.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DataSummary {
    /// The files (or built-in generators) the data came from.
    pub source: Vec<String>,
    /// Samples over all experiments.
    pub samples: usize,
    /// Experiments.
    pub experiments: usize,
    /// Sample time in seconds.
    pub ts: Option<f64>,
}

impl DataSummary {
    /// The summary of `data` read from `source`.
    pub fn of(data: &IdData, source: Vec<String>) -> Self {
        Self {
            source,
            samples: data.n_samples(),
            experiments: data.n_experiments(),
            ts: Some(data.ts()),
        }
    }
}

/// How well a model's simulated output fits measured data.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct FitSummary {
    /// fit % over all experiments, stacked.
    pub fit_percent: f64,
    /// Root-mean-square error over all experiments.
    pub rmse: f64,
    /// The estimator's loss V (mean squared weighted residual); null for a plain simulation.
    pub loss: Option<f64>,
    /// Akaike's final prediction error.
    pub fpe: Option<f64>,
    /// Akaike's information criterion.
    pub aic: Option<f64>,
    /// Per experiment.
    pub per_experiment: Vec<ExperimentFit>,
}

/// The fit of one experiment.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ExperimentFit {
    /// The experiment's name.
    pub experiment: String,
    /// Samples.
    pub samples: usize,
    /// fit %.
    pub fit_percent: f64,
    /// RMSE.
    pub rmse: f64,
}

impl FitSummary {
    /// The fit of simulated outputs `yhat` against measured `y`, one pair per experiment
    /// (`names` name them); errors when a figure is not finite (the simulation failed).
    pub fn of(names: &[String], y: &[&[f64]], yhat: &[&[f64]]) -> Result<Self> {
        Self::with_figures(names, y, yhat, |y, yh, _| {
            metrics::fit_percent_and_mse(y, yh)
        })
    }

    /// [`of`](Self::of) with each experiment's (fit %, MSE) from `figures(y, ŷ, index)`.
    fn with_figures(
        names: &[String],
        y: &[&[f64]],
        yhat: &[&[f64]],
        mut figures: impl FnMut(&[f64], &[f64], usize) -> (f64, f64),
    ) -> Result<Self> {
        let per_experiment: Vec<ExperimentFit> = names
            .iter()
            .zip(y.iter().zip(yhat))
            .enumerate()
            .map(|(e, (name, (y, yh)))| {
                let (fit_percent, mse) = figures(y, yh, e);
                ExperimentFit {
                    experiment: name.clone(),
                    samples: y.len(),
                    fit_percent,
                    rmse: mse.sqrt(),
                }
            })
            .collect();
        // Stacked over the experiments; one experiment is its own stack.
        let (fit_percent, rmse) = match (y, yhat, &per_experiment[..]) {
            ([y], [yh], [one]) if y.len() == yh.len() => (one.fit_percent, one.rmse),
            _ => {
                let stacked = |s: &[&[f64]]| s.iter().flat_map(|v| v.iter().copied()).collect();
                let (ys, yhs): (Vec<f64>, Vec<f64>) = (stacked(y), stacked(yhat));
                (metrics::fit_percent(&ys, &yhs), metrics::rmse(&ys, &yhs))
            }
        };
        let summary = Self {
            fit_percent,
            rmse,
            loss: None,
            fpe: None,
            aic: None,
            per_experiment,
        };
        summary.check()?;
        Ok(summary)
    }

    /// The fit of output 0 of an output-error fit on `data`, with its loss, FPE and AIC.
    pub fn of_output_error(fit: &OutputErrorFit, data: &IdData) -> Result<Self> {
        let names: Vec<String> = data.experiments().iter().map(|e| e.name.clone()).collect();
        let y: Vec<&[f64]> = data.experiments().iter().map(|e| e.output(0)).collect();
        let yhat: Vec<&[f64]> = fit.simulated.iter().map(|s| s[0].as_slice()).collect();
        // A fit of one output over every sample (none skipped) summed these very figures
        // (`fit_percent_and_mse` of y and ŷ): taken over, they spare a pass over the record.
        let whole = fit.simulated.iter().all(|s| s.len() == 1)
            && fit.report.n_residuals == y.iter().map(|y| y.len()).sum::<usize>();
        let mut summary = Self::with_figures(&names, &y, &yhat, |y, yh, e| {
            match (whole, fit.fit_percent.get(e), fit.mse.get(e)) {
                (true, Some(f), Some(m)) => (f[0], m[0]),
                _ => metrics::fit_percent_and_mse(y, yh),
            }
        })?;
        summary.loss = Some(fit.loss);
        summary.fpe = fit.fpe.is_finite().then_some(fit.fpe);
        summary.aic = fit.aic.is_finite().then_some(fit.aic);
        summary.check()?;
        Ok(summary)
    }

    fn check(&self) -> Result<()> {
        let figures = [Some(self.fit_percent), Some(self.rmse), self.loss];
        let experiments = self
            .per_experiment
            .iter()
            .flat_map(|e| [Some(e.fit_percent), Some(e.rmse)]);
        if figures
            .into_iter()
            .chain(experiments)
            .flatten()
            .all(f64::is_finite)
        {
            Ok(())
        } else {
            Err(Error::NonFiniteOutput(
                "the model's simulated output is not finite on these data: the model is unstable or the data are outside its range".into(),
            ))
        }
    }
}

/// How a search went.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SearchSummary {
    /// Iterations.
    pub iterations: usize,
    /// Criterion evaluations (simulations).
    pub evaluations: usize,
    /// Why the search stopped.
    pub termination: TerminationSummary,
    /// Wall-clock seconds.
    pub elapsed_s: f64,
    /// Model steps the command performed (samples × integration steps of every simulation,
    /// a simulation with p sensitivities counting 1 + p), the unit of the work budget; set
    /// by the command-line front end, absent where not counted.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model_steps: Option<u64>,
    /// The work budget's estimate of `model_steps`, made before the run; absent for a
    /// command without a budget check.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub estimated_model_steps: Option<u64>,
}

/// Why a search stopped: a stable code and a sentence.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TerminationSummary {
    /// `max_iterations`, `improvement_below_tolerance`, `step_below_tolerance`,
    /// `gradient_below_tolerance`, `zero_residual`, `no_descent`, `stopped`,
    /// `nothing_to_estimate`, `converged`, `flat_region`, `diverged`, `direct` for a direct
    /// solve, or
    /// `time_limit` when a front end's time limit stopped the search (the best result so far).
    pub code: String,
    /// The reason in words.
    pub message: String,
    /// True when the reason means the search reached a (local) optimum.
    pub converged: bool,
}

impl TerminationSummary {
    /// The summary of `termination`.
    pub fn of(termination: &Termination) -> Self {
        let code = serde_json::to_value(termination)
            .ok()
            .and_then(|v| v.get("code").and_then(|c| c.as_str()).map(String::from))
            .unwrap_or_else(|| "unknown".into());
        Self {
            code,
            message: termination.to_string(),
            converged: termination.converged(),
        }
    }

    /// A search a front end's time limit of `limit_s` seconds stopped: the code
    /// `time_limit`, not converged (the results are the best found so far).
    pub fn time_limit(limit_s: f64) -> Self {
        Self {
            code: "time_limit".into(),
            message: format!("time limit of {limit_s} s reached; the best result so far"),
            converged: false,
        }
    }

    /// A direct (non-iterative) solve, such as linear least squares.
    pub fn direct() -> Self {
        Self {
            code: "direct".into(),
            message: "direct solve (no iterations)".into(),
            converged: true,
        }
    }
}

impl SearchSummary {
    /// The summary of a Levenberg–Marquardt report, timed over `elapsed_s`.
    pub fn of(report: &LmReport, elapsed_s: f64) -> Self {
        Self {
            iterations: report.iterations,
            evaluations: report.function_evaluations,
            termination: TerminationSummary::of(&report.termination),
            elapsed_s,
            model_steps: None,
            estimated_model_steps: None,
        }
    }

    /// A direct solve that took `elapsed_s`.
    pub fn direct(elapsed_s: f64) -> Self {
        Self {
            iterations: 0,
            evaluations: 1,
            termination: TerminationSummary::direct(),
            elapsed_s,
            model_steps: None,
            estimated_model_steps: None,
        }
    }
}

/// How the standard deviations were obtained.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct UncertaintySummary {
    /// `asymptotic` (σ²(JᵀJ)⁻¹ at the estimate), `bootstrap` (parametric bootstrap with
    /// re-identification), `least_squares` (the covariance of a linear regression) or `none`.
    pub method: String,
    /// Bootstrap replicates.
    pub replicates: Option<usize>,
    /// Bootstrap replicates that failed to identify.
    pub failed: Option<usize>,
    /// The covariance of the estimates that have a standard deviation (null when the
    /// command gives none, and in reports written before the key existed).
    #[serde(default)]
    pub covariance: Option<CovarianceSummary>,
}

/// The covariance matrix of the estimates with a standard deviation in the report's model
/// (those not fixed and not held at a bound), in the model file's parameter order.
///
/// cov(θᵢ, θⱼ) = σᵢ σⱼ ρᵢⱼ, with σ the model file's standard deviations and ρ the
/// correlation of the estimator's covariance: σ²(JᵀJ)⁻¹ at the estimate for a search,
/// σ²(ΦᵀΦ)⁻¹ on the free set for a (non-negative) least-squares solve (Ljung, *System
/// Identification*, 2nd ed., 1999, §9.3). Where σ is the estimator's own (every operator
/// family, grey-box and operator-cascade fit) the matrix is σ²(JᵀJ)⁻¹ itself; where a
/// standard deviation comes from elsewhere (the Coleman–Hodgdon threshold d's truncated
/// normal, a bootstrap) its row and column are the asymptotic correlations scaled to it, so
/// the diagonal is always σ².
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CovarianceSummary {
    /// The parameters of the rows and columns, in order.
    pub parameters: Vec<String>,
    /// The matrix, row by row (symmetric, its diagonal the squared standard deviations).
    pub matrix: Vec<Vec<f64>>,
}

impl CovarianceSummary {
    /// The covariance of the parameters of `model` that have a standard deviation, from the
    /// estimator's covariance `c` (`c(i, j)`) over the parameters `names`: σᵢ σⱼ ρᵢⱼ (see
    /// the type). None when a parameter with a standard deviation is not among `names`, or
    /// when none has one.
    pub fn of(
        model: &ModelFile,
        names: &[String],
        c: impl Fn(usize, usize) -> f64,
    ) -> Option<Self> {
        let mut rows = Vec::new();
        for p in model.parameters() {
            if let (false, Some(s)) = (p.fixed, p.std) {
                rows.push((p.name.clone(), names.iter().position(|n| *n == p.name)?, s));
            }
        }
        if rows.is_empty() {
            return None;
        }
        // The upper triangle, mirrored: a symmetric matrix to the bit.
        let mut matrix = vec![vec![0.0; rows.len()]; rows.len()];
        for (a, &(_, i, si)) in rows.iter().enumerate() {
            matrix[a][a] = si * si;
            for (b, &(_, j, sj)) in rows.iter().enumerate().skip(a + 1) {
                let (cii, cjj) = (c(i, i), c(j, j));
                let rho = 0.5 * (c(i, j) + c(j, i)) / (cii * cjj).sqrt();
                let v = if cii > 0.0 && cjj > 0.0 && rho.is_finite() {
                    si * sj * rho.clamp(-1.0, 1.0)
                } else {
                    0.0
                };
                matrix[a][b] = v;
                matrix[b][a] = v;
            }
        }
        Some(Self {
            parameters: rows.into_iter().map(|(n, _, _)| n).collect(),
            matrix,
        })
    }

    /// The covariance of an output-error fit's parameters for `model` ([`Self::of`] on
    /// σ²(JᵀJ)⁻¹ of `fit`).
    pub fn of_output_error(model: &ModelFile, fit: &OutputErrorFit) -> Option<Self> {
        let m = &fit.covariance.matrix;
        Self::of(model, &fit.parameters.names(), |i, j| m[(i, j)])
    }
}

impl UncertaintySummary {
    /// Asymptotic standard deviations.
    pub fn asymptotic() -> Self {
        Self::named("asymptotic")
    }

    /// Standard deviations of a linear regression.
    pub fn least_squares() -> Self {
        Self::named("least_squares")
    }

    /// A parametric bootstrap of `replicates` replicates, `failed` of which failed.
    pub fn bootstrap(replicates: usize, failed: usize) -> Self {
        Self {
            method: "bootstrap".into(),
            replicates: Some(replicates),
            failed: Some(failed),
            covariance: None,
        }
    }

    fn named(method: &str) -> Self {
        Self {
            method: method.into(),
            replicates: None,
            failed: None,
            covariance: None,
        }
    }

    /// The summary with the estimates' covariance matrix.
    pub fn with_covariance(mut self, covariance: Option<CovarianceSummary>) -> Self {
        self.covariance = covariance;
        self
    }
}

/// The model's figures on one validation or test record.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ValidationEntry {
    /// The record's source.
    pub source: String,
    /// Samples scored.
    pub samples: usize,
    /// fit %.
    pub fit_percent: f64,
    /// RMSE.
    pub rmse: f64,
    /// The benchmark's error measure where one defines it (Bouc–Wen: e_RMS).
    pub e_rms: Option<f64>,
}

impl ValidationEntry {
    /// The entry of a scored Bouc–Wen benchmark test record (fit %, RMSE and e_RMS).
    pub fn of_benchmark(test: &crate::identify::bouc_wen_benchmark::BenchmarkTest) -> Result<Self> {
        Self::of(test.source.clone(), &test.y, &test.yhat, Some(test.e_rms))
    }

    /// The figures of simulated `yhat` against measured `y` from `source`.
    pub fn of(source: String, y: &[f64], yhat: &[f64], e_rms: Option<f64>) -> Result<Self> {
        let entry = Self {
            source,
            samples: y.len(),
            fit_percent: metrics::fit_percent(y, yhat),
            rmse: metrics::rmse(y, yhat),
            e_rms,
        };
        if entry.fit_percent.is_finite()
            && entry.rmse.is_finite()
            && entry.e_rms.is_none_or(f64::is_finite)
        {
            Ok(entry)
        } else {
            Err(Error::NonFiniteOutput(format!(
                "the model's output on {} is not finite: the model is unstable or the data are outside its range",
                entry.source
            )))
        }
    }
}

impl Report {
    /// The report of a run whose searches a front end's time limit of `limit_s` seconds
    /// stopped: its `search.termination` says so ([`TerminationSummary::time_limit`]); a
    /// report without a search of its own (`compare`, whose families each searched) says so
    /// in `details.stopped_by_time_limit_s`.
    pub fn stopped_by_time_limit(mut self, limit_s: f64) -> Self {
        if let Some(search) = &mut self.search {
            search.termination = TerminationSummary::time_limit(limit_s);
        } else if let Some(details) = self.details.as_object_mut() {
            details.insert("stopped_by_time_limit_s".into(), limit_s.into());
        }
        self
    }

    /// An empty report of `command`: every key present, null where nothing is filled in.
    pub fn new(command: &str) -> Self {
        Self {
            schema: REPORT_SCHEMA.into(),
            command: command.into(),
            version: env!("CARGO_PKG_VERSION").into(),
            data: None,
            model: None,
            fit: None,
            search: None,
            uncertainty: None,
            validation: Vec::new(),
            details: serde_json::Value::Null,
            warnings: Vec::new(),
        }
    }

    /// The report of an output-error fit of `model` on `data` (read from `source`).
    pub fn of_output_error(
        command: &str,
        data: &IdData,
        source: Vec<String>,
        model: ModelFile,
        fit: &OutputErrorFit,
        elapsed_s: f64,
        uncertainty: UncertaintySummary,
    ) -> Result<Self> {
        let covariance = CovarianceSummary::of_output_error(&model, fit);
        Ok(Self {
            data: Some(DataSummary::of(data, source)),
            model: Some(model),
            fit: Some(FitSummary::of_output_error(fit, data)?),
            search: Some(SearchSummary::of(&fit.report, elapsed_s)),
            uncertainty: Some(uncertainty.with_covariance(covariance)),
            ..Self::new(command)
        })
    }

    /// Sets the model and the figures of its fit.
    pub fn with_model(
        mut self,
        model: Option<ModelFile>,
        fit: Option<FitSummary>,
        search: Option<SearchSummary>,
        uncertainty: Option<UncertaintySummary>,
    ) -> Self {
        self.model = model;
        self.fit = fit;
        self.search = search;
        self.uncertainty = uncertainty;
        self
    }

    /// Sets `details`.
    pub fn with_details(mut self, details: serde_json::Value) -> Self {
        self.details = details;
        self
    }

    /// The report as pretty JSON, refused when any number in it is not finite (serde would
    /// write it as null and hide the failure).
    pub fn to_json(&self) -> Result<String> {
        self.check_finite()?;
        serde_json::to_string_pretty(self).map_err(|e| Error::Serialization(format!("report: {e}")))
    }

    /// Errors naming the first non-finite number of the fit, search, validation or model.
    pub fn check_finite(&self) -> Result<()> {
        let mut bad = Vec::new();
        if let Some(m) = &self.model {
            bad.extend(
                m.parameters()
                    .iter()
                    .filter(|p| !p.value.is_finite() || p.std.is_some_and(|s| !s.is_finite()))
                    .map(|p| format!("model parameter {}", p.name)),
            );
        }
        if let Some(f) = &self.fit {
            if f.check().is_err() {
                bad.push("fit".into());
            }
        }
        if let Some(s) = &self.search {
            if !s.elapsed_s.is_finite() {
                bad.push("search.elapsed_s".into());
            }
        }
        let covariance = self
            .uncertainty
            .as_ref()
            .and_then(|u| u.covariance.as_ref());
        if covariance.is_some_and(|c| c.matrix.iter().flatten().any(|v| !v.is_finite())) {
            bad.push("uncertainty.covariance".into());
        }
        match bad.first() {
            None => Ok(()),
            Some(what) => Err(Error::NonFiniteOutput(format!(
                "{what} is not a finite number; the estimate failed numerically"
            ))),
        }
    }
}

/// The JSON Schema of [`Report`], generated from the types (published in
/// `docs/schema/hysid.report.v1.json`).
pub fn report_schema() -> serde_json::Value {
    serde_json::to_value(schemars::schema_for!(Report)).unwrap_or_default()
}

/// The JSON Schema of the saved-model file (published in `docs/schema/hysid.model.v1.json`).
pub fn model_schema() -> serde_json::Value {
    serde_json::to_value(schemars::schema_for!(ModelFile)).unwrap_or_default()
}
