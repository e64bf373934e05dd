//! The report of one hysteresis family fitted to a record (`hysid identify operator`, Python's
//! `hysid.identify_operator`): the same report from both front ends.

use super::{CovarianceSummary, UncertaintySummary};
use super::{DataSummary, FitSummary, Report, SearchSummary, TerminationSummary};
use crate::data::IdData;
use crate::identify::operators::FittedOperator;
use crate::model::operators::Family;
use crate::model::saved::{ModelFile, SavedModel};
use crate::Result;
use serde_json::json;

/// The output the report's fit is computed from: the saved model's own simulation of the
/// first experiment, so that `hysid simulate` on the model file reproduces the report.
pub fn operator_simulation(fitted: &FittedOperator, data: &IdData) -> Result<Vec<f64>> {
    let exp = data.experiment(0);
    let (u, y) = (exp.input(0), exp.output(0));
    Ok(fitted
        .fit
        .model
        .simulate(&[u], data.ts(), y.first().copied())?
        .swap_remove(0))
}

/// The report of `fitted` on the first experiment of `data` (read from `sources`), whose
/// [`operator_simulation`] is `simulated`: data, fit, search, uncertainty, the model, and
/// `details` with the family, the number of estimated parameters, whether the search
/// converged, AIC and FPE (null when not finite, e.g. the AIC of an exact fit), and the
/// model's loop orientation (`ccw`/`cw`) with its source (`given`, `detected`, `fitted`).
pub fn operator_report(
    fitted: &FittedOperator,
    data: &IdData,
    simulated: &[f64],
    sources: Vec<String>,
) -> Result<Report> {
    let exp = data.experiment(0);
    let y = exp.output(0);
    let fit = &fitted.fit;
    let mut report = Report::new("identify operator");
    report.data = Some(DataSummary::of(data, sources));
    report.fit = Some(FitSummary::of(
        std::slice::from_ref(&exp.name),
        &[y],
        &[simulated],
    )?);
    report.search = Some(SearchSummary {
        iterations: fit.iterations,
        evaluations: fit.evaluations,
        termination: TerminationSummary::of(&fit.termination),
        elapsed_s: fit.elapsed_s,
        // Every criterion evaluation simulates the operator over the record once.
        model_steps: Some(
            u64::try_from(fit.evaluations.saturating_mul(y.len())).unwrap_or(u64::MAX),
        ),
        estimated_model_steps: None,
    });
    let mut model = fit.model.to_file();
    nnls_bounds(&mut model, fitted.family);
    let covariance =
        CovarianceSummary::of(&model, &fit.parameters.names(), |i, j| fit.covariance[i][j]);
    report.uncertainty = Some(
        if fit.iterations == 0 {
            UncertaintySummary::least_squares()
        } else {
            UncertaintySummary::asymptotic()
        }
        .with_covariance(covariance),
    );
    report.model = Some(model);
    let finite = |v: f64| v.is_finite().then_some(v);
    report.details = json!({
        "family": fitted.family.name(),
        "estimated_parameters": fitted.estimated_parameters(),
        "converged": fit.termination.converged(),
        "aic": finite(fit.aic),
        "fpe": finite(fit.fpe),
        "orientation": fitted.orientation.map(|o| o.orientation.short_name()),
        "orientation_source": fitted.orientation.map(|o| o.source.name()),
        // The state the fitted model starts from (`demagnetised` for a family whose
        // structure holds its start).
        "initial_state": fit.initial_state.map_or("demagnetised", |s| s.name()),
        // The size chosen from the data and every candidate's held-out score (absent when
        // the options fixed it).
        "model_size": fit.model_size,
    });
    Ok(report)
}

/// The fitted model file with the bounds its fit held: the weights a₁…aₙ of a PI or GPI
/// operator are the non-negative least-squares solution (aᵢ ≥ 0, `identify::operators::pi`,
/// `gpi`), so their records say `lower: 0` (the model itself admits a negative weight while
/// every partial sum a₀ + … + aᵢ stays non-negative, as an operator cascade fits it). A
/// weight at 0 is then a parameter on its bound, without a standard deviation.
fn nnls_bounds(model: &mut ModelFile, family: Family) {
    if !matches!(family, Family::Pi | Family::Gpi) {
        return;
    }
    if let SavedModel::Operator(operator) = &mut model.model {
        for p in operator.parameters.iter_mut() {
            let weight = p
                .name
                .strip_prefix('a')
                .and_then(|i| i.parse::<usize>().ok())
                .is_some_and(|i| i >= 1);
            if weight && !p.fixed && p.lower.is_none() && p.value >= 0.0 {
                p.lower = Some(0.0);
            }
        }
    }
}
