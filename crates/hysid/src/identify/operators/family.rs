//! The family registry: every hysteresis family by its name, and one function that fits any
//! of them to a measured input u and output y.
//!
//! | name | model | recipe |
//! |---|---|---|
//! | `pi` | Prandtl–Ishlinskii (Krejčí & Kuhnen 2001) | [`super::pi`] |
//! | `gpi` | generalised PI with dead zones (Kuhnen 2003) | [`super::gpi`] |
//! | `preisach` | discrete Preisach plane (Mayergoyz 1991) | [`super::preisach`] |
//! | `jiles-atherton` | Jiles & Atherton (1986) | [`super::jiles_atherton`] |
//! | `bouc-wen` | static Bouc–Wen operator (Wen 1976) | [`super::bouc_wen`] |
//! | `duhem` | generalised Duhem / Coleman–Hodgdon operator | [`super::duhem`] |
//! | `dahl` | Dahl friction (Dahl 1968) | [`super::dahl`] |
//! | `maxwell-slip` | generalised Maxwell-slip (Lampaert, Al-Bender & Swevers 2003) | [`super::maxwell_slip`] |
//! | `backlash` | play operator with gain (Krasnosel'skii & Pokrovskii 1989) | [`super::backlash`] |
//! | `ch4`, `ch6` | Coleman–Hodgdon hysteresis alone (Coleman & Hodgdon 1986; Vörös 2015) | [`crate::identify::hysteresis`] |
//!
//! [`fit_operator`] returns the fitted model as a [`FittedModel`] (kind `operator`, or
//! `coleman_hodgdon` for ch4/ch6), so every family saves, simulates and compensates the same way.

use super::{
    backlash, bouc_wen, dahl, duhem, gpi, jiles_atherton, maxwell_slip, pi, preisach, OperatorFit,
};
use crate::data::IdData;
use crate::identify::hysteresis::HysteresisIdentification;
use crate::model::coleman_hodgdon::{simulate_switched, InitialOutput};
use crate::model::operators::{OperatorModel, Orientation};
use crate::model::saved::FittedModel;
use crate::model::{ChForm, Parameter, ParameterSet};
use crate::numerics::levenberg_marquardt::Control;
use crate::numerics::metrics;
use crate::numerics::Observer;
use crate::{Error, Result};
use std::time::Instant;

/// A hysteresis family, named as on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[allow(missing_docs)] // each variant is its name (see the module table)
pub enum Family {
    Pi,
    Gpi,
    Preisach,
    JilesAtherton,
    BoucWen,
    Duhem,
    Dahl,
    MaxwellSlip,
    Backlash,
    Ch4,
    Ch6,
}

impl Family {
    /// Every family, in the order of the module table.
    pub const ALL: [Family; 11] = [
        Family::Pi,
        Family::Gpi,
        Family::Preisach,
        Family::JilesAtherton,
        Family::BoucWen,
        Family::Duhem,
        Family::Dahl,
        Family::MaxwellSlip,
        Family::Backlash,
        Family::Ch4,
        Family::Ch6,
    ];

    /// The family's name (`pi`, `gpi`, `preisach`, `jiles-atherton`, `bouc-wen`, `duhem`,
    /// `dahl`, `maxwell-slip`, `backlash`, `ch4`, `ch6`).
    pub fn name(self) -> &'static str {
        match self {
            Family::Pi => "pi",
            Family::Gpi => "gpi",
            Family::Preisach => "preisach",
            Family::JilesAtherton => "jiles-atherton",
            Family::BoucWen => "bouc-wen",
            Family::Duhem => "duhem",
            Family::Dahl => "dahl",
            Family::MaxwellSlip => "maxwell-slip",
            Family::Backlash => "backlash",
            Family::Ch4 => "ch4",
            Family::Ch6 => "ch6",
        }
    }

    /// The family named `name` (case-insensitive; `_` for `-` accepted).
    pub fn parse(name: &str) -> Result<Family> {
        let wanted = name.trim().to_ascii_lowercase().replace('_', "-");
        Family::ALL
            .into_iter()
            .find(|f| f.name() == wanted)
            .ok_or_else(|| {
                Error::invalid_option(
                    "family",
                    name,
                    format!(
                        "unknown hysteresis family '{name}'; use one of {}",
                        Family::ALL.map(Family::name).join(", ")
                    ),
                )
            })
    }

    /// A comma-separated list of families, or `all`.
    pub fn parse_list(list: &str) -> Result<Vec<Family>> {
        if list.trim().eq_ignore_ascii_case("all") {
            return Ok(Family::ALL.to_vec());
        }
        let mut out: Vec<Family> = Vec::new();
        for name in list.split(',').filter(|s| !s.trim().is_empty()) {
            let f = Family::parse(name)?;
            if !out.contains(&f) {
                out.push(f);
            }
        }
        if out.is_empty() {
            return Err(Error::invalid_option(
                "families",
                "[]",
                "the family list is empty; name at least one family, or all".into(),
            ));
        }
        Ok(out)
    }
}

impl std::fmt::Display for Family {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The settings of the families' recipes that a user chooses (the rest are each recipe's
/// defaults).
#[derive(Clone, Debug, PartialEq)]
pub struct FamilyOptions {
    /// Thresholds n of the PI and generalised-PI grids, and Maxwell-slip elements (10).
    pub thresholds: usize,
    /// An explicit threshold grid r₁ < … < rₙ (PI, GPI; slip widths of Maxwell-slip) instead
    /// of the uniform one; must be strictly increasing and > 0.
    pub threshold_grid: Option<Vec<f64>>,
    /// Intervals N of the Preisach grid (20: N(N+1)/2 = 210 cells).
    pub grid: usize,
    /// Smoothness penalty λ of the Preisach fit (1e-6).
    pub lambda: f64,
    /// Dead zones on each side of the generalised PI (4).
    pub dead_zones: usize,
    /// The loop orientation; detected from the data when None (linear-in-weights families).
    pub orientation: Option<Orientation>,
    /// Sees the starts and iterations of the differential families' searches (Jiles–Atherton,
    /// Bouc–Wen, Duhem, Dahl) and may stop them with the best result so far.
    pub observer: Observer,
}

impl Default for FamilyOptions {
    fn default() -> Self {
        Self {
            thresholds: 10,
            threshold_grid: None,
            grid: 20,
            lambda: 1e-6,
            dead_zones: 4,
            orientation: None,
            observer: Observer::none(),
        }
    }
}

/// The largest threshold count, Preisach grid size and dead-zone count accepted: beyond them
/// the regressions grow past what a record of ordinary length can determine.
pub const MAX_THRESHOLDS: usize = 200;
/// See [`MAX_THRESHOLDS`] (a 100-interval Preisach grid has 5050 cells).
pub const MAX_GRID: usize = 100;
/// See [`MAX_THRESHOLDS`].
pub const MAX_DEAD_ZONES: usize = 20;

impl FamilyOptions {
    /// Checks the ranges: 1 ≤ thresholds ≤ [`MAX_THRESHOLDS`], 1 ≤ grid ≤ [`MAX_GRID`],
    /// 0 ≤ dead zones ≤ [`MAX_DEAD_ZONES`], finite λ ≥ 0, a threshold grid strictly increasing
    /// and > 0.
    pub fn validate(&self) -> Result<()> {
        let range = |what: &str, v: usize, lo: usize, hi: usize| {
            if (lo..=hi).contains(&v) {
                Ok(())
            } else {
                Err(Error::invalid_option(
                    what,
                    v,
                    format!("{what} = {v} is outside {lo}..={hi}; choose a value in that range"),
                ))
            }
        };
        range("the threshold count", self.thresholds, 1, MAX_THRESHOLDS)?;
        range("the Preisach grid size", self.grid, 1, MAX_GRID)?;
        range("the dead-zone count", self.dead_zones, 0, MAX_DEAD_ZONES)?;
        if !(self.lambda.is_finite() && self.lambda >= 0.0) {
            return Err(Error::invalid_option(
                "lambda",
                self.lambda,
                format!(
                    "the Preisach smoothness lambda = {} must be finite and >= 0",
                    self.lambda
                ),
            ));
        }
        if let Some(g) = &self.threshold_grid {
            crate::model::operators::validate_thresholds("threshold", g)?;
        }
        Ok(())
    }
}

/// A fitted model of any family and how it was obtained: the figures of [`OperatorFit`] on
/// the estimation data, with the model as a [`FittedModel`].
#[derive(Clone, Debug)]
pub struct FittedOperator {
    /// The family.
    pub family: Family,
    /// The model and the fit figures; `fit.model` saves with [`FittedModel::to_file`].
    pub fit: OperatorFit<FittedModel>,
}

impl FittedOperator {
    /// The number of estimated parameters (those not held fixed).
    pub fn estimated_parameters(&self) -> usize {
        self.fit.parameters.iter().filter(|p| !p.fixed).count()
    }
}

/// Fits `family` to input `u` and output `y` with `options`.
pub fn fit_operator(
    family: Family,
    u: &[f64],
    y: &[f64],
    options: &FamilyOptions,
) -> Result<FittedOperator> {
    options.validate()?;
    let o = options.orientation;
    let fit = match family {
        Family::Pi => boxed(
            pi::fit(
                u,
                y,
                &pi::PiOptions {
                    thresholds: options.thresholds,
                    grid: options.threshold_grid.clone(),
                    orientation: o,
                    select: None,
                },
            )?,
            OperatorModel::Pi,
        ),
        Family::Gpi => boxed(
            gpi::fit(
                u,
                y,
                &gpi::GpiOptions {
                    thresholds: options.thresholds,
                    grid: options.threshold_grid.clone(),
                    dead_zones: options.dead_zones,
                    orientation: o,
                    ..gpi::GpiOptions::default()
                },
            )?,
            OperatorModel::Gpi,
        ),
        Family::Preisach => boxed(
            preisach::fit(
                u,
                y,
                &preisach::PreisachOptions {
                    levels: options.grid,
                    lambda: options.lambda,
                    orientation: o,
                    ..preisach::PreisachOptions::default()
                },
            )?,
            OperatorModel::Preisach,
        ),
        Family::MaxwellSlip => boxed(
            maxwell_slip::fit(
                u,
                y,
                &maxwell_slip::MaxwellSlipOptions {
                    elements: options.thresholds,
                    widths: options.threshold_grid.clone(),
                    orientation: o,
                    ..maxwell_slip::MaxwellSlipOptions::default()
                },
            )?,
            OperatorModel::MaxwellSlip,
        ),
        Family::Backlash => boxed(
            backlash::fit(
                u,
                y,
                &backlash::BacklashOptions {
                    orientation: o,
                    ..backlash::BacklashOptions::default()
                },
            )?,
            OperatorModel::Backlash,
        ),
        Family::JilesAtherton => boxed(
            jiles_atherton::fit(
                u,
                y,
                &jiles_atherton::JilesAthertonOptions {
                    observer: options.observer.clone(),
                    ..Default::default()
                },
            )?,
            OperatorModel::JilesAtherton,
        ),
        Family::BoucWen => boxed(
            bouc_wen::fit(
                u,
                y,
                &bouc_wen::BoucWenOptions {
                    observer: options.observer.clone(),
                    ..Default::default()
                },
            )?,
            OperatorModel::BoucWen,
        ),
        Family::Duhem => boxed(
            duhem::fit(
                u,
                y,
                &duhem::DuhemOptions {
                    observer: options.observer.clone(),
                    ..Default::default()
                },
            )?,
            OperatorModel::Duhem,
        ),
        Family::Dahl => boxed(
            dahl::fit(
                u,
                y,
                &dahl::DahlOptions {
                    observer: options.observer.clone(),
                    ..Default::default()
                },
            )?,
            OperatorModel::Dahl,
        ),
        Family::Ch4 => coleman_hodgdon(ChForm::Saturated4, u, y)?,
        Family::Ch6 => coleman_hodgdon(ChForm::General6, u, y)?,
    };
    Ok(FittedOperator { family, fit })
}

/// An operator fit with its model wrapped as a [`FittedModel`].
fn boxed<M>(
    fit: OperatorFit<M>,
    wrap: impl FnOnce(M) -> OperatorModel,
) -> OperatorFit<FittedModel> {
    let std = fit.std.iter().map(|s| s.unwrap_or(f64::NAN)).collect();
    OperatorFit {
        model: FittedModel::operator(wrap(fit.model), std),
        parameters: fit.parameters,
        std: fit.std,
        simulated: fit.simulated,
        fit_percent: fit.fit_percent,
        rmse: fit.rmse,
        loss: fit.loss,
        fpe: fit.fpe,
        aic: fit.aic,
        iterations: fit.iterations,
        evaluations: fit.evaluations,
        termination: fit.termination,
        elapsed_s: fit.elapsed_s,
    }
}

/// The Coleman–Hodgdon hysteresis alone ([`HysteresisIdentification`]), its output starting
/// at the measured first sample.
fn coleman_hodgdon(form: ChForm, u: &[f64], y: &[f64]) -> Result<OperatorFit<FittedModel>> {
    let started = Instant::now();
    // Equal lengths, enough samples, an input that reverses (a loop, not a curve) — the
    // recipe itself accepts a monotone input, on which d and the loop are not identifiable.
    super::differential_fit::check_record(form.short_name(), u, y, form.n_params())?;
    let data = IdData::siso(1.0, "u", u.to_vec(), "y", y.to_vec())?;
    let id = HysteresisIdentification::new(form);
    let fit = id.estimate(&data, &mut |_| Control::Continue)?;
    let std = fit.std();
    let simulated = simulate_switched(&fit.model, u, y[0], None);
    let parameters = ParameterSet::new(
        form.parameter_names()
            .iter()
            .zip(fit.model.params())
            .map(|(name, v)| Parameter::new(*name, v))
            .collect(),
    )?;
    let n = y.len();
    let p = form.n_params();
    let loss = metrics::mse(y, &simulated);
    let report = &fit.output_error.report;
    Ok(OperatorFit {
        model: FittedModel::Hysteresis {
            model: fit.model.clone(),
            initial: InitialOutput::Measured,
            std: std.clone(),
        },
        parameters,
        std: std.iter().map(|s| s.is_finite().then_some(*s)).collect(),
        fit_percent: metrics::fit_percent(y, &simulated),
        rmse: loss.sqrt(),
        loss,
        fpe: metrics::fpe(loss, n, p),
        aic: metrics::aic(loss, n, p),
        simulated,
        iterations: report.iterations,
        evaluations: report.function_evaluations,
        termination: report.termination.clone(),
        elapsed_s: started.elapsed().as_secs_f64(),
    })
}
