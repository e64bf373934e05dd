//! The family registry: every hysteresis family by its name, and one function that fits any
//! of them to a measured input u and output y.
//!
//! The families are the registry's ([`Family`], [`crate::model::operators::registry`]); each
//! implements [`Identify`] in its own module of [`crate::identify::operators`]; `ch4` and `ch6`
//! are the Coleman–Hodgdon hysteresis alone ([`crate::identify::hysteresis`]).
//!
//! [`fit_operator`] returns the fitted model as a [`FittedModel`] (kind `operator`, or
//! `coleman_hodgdon` for ch4/ch6), so every family saves, simulates and compensates the same way.

use super::differential_fit::masked_covariance;
use super::OperatorFit;
use crate::data::IdData;
use crate::identify::hysteresis::HysteresisIdentification;
use crate::identify::operator_cascade::OperatorCascadeIdentification;
use crate::model::coleman_hodgdon::{simulate_switched, InitialOutput};
pub use crate::model::operators::Family;
use crate::model::operators::{
    InitialState, LoopOrientation, OperatorFamily, OperatorModel, Orientation,
};
use crate::model::saved::FittedModel;
use crate::model::saved::{FittedHysteresis, FittedHysteresisOperator};
use crate::model::OperatorCascade;
use crate::model::{ChForm, ColemanHodgdon, Parameter, ParameterSet};
use crate::numerics::levenberg_marquardt::Control;
use crate::numerics::metrics;
use crate::numerics::Observer;
use crate::{Error, Result};
use nalgebra::DMatrix;
use std::time::Instant;

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
    /// Dead zones on each side of the generalised PI (4) when they are not chosen
    /// (`choose_dead_zones` false, `choose_thresholds` false, or a `threshold_grid` given).
    pub dead_zones: usize,
    /// The loop orientation of the linear-in-weights families as their model files store it
    /// (trend and Γ = G or G⁻¹); overrides `loop_orientation`. Detected from the data when
    /// both are None.
    pub orientation: Option<Orientation>,
    /// The loop's turning sense in the (u, y) plane as the user gives it (`--orientation
    /// ccw|cw`, Python `orientation=`), the trend still detected; None: detected from the area
    /// between the branches ([`LoopOrientation::detect`]). Read by every family with
    /// [`FamilySetting::Orientation`].
    pub loop_orientation: Option<LoopOrientation>,
    /// Sees the starts and iterations of the differential families' searches (Jiles–Atherton,
    /// Bouc–Wen, Duhem, Dahl) and may stop them with the best result so far.
    pub observer: Observer,
    /// The initial state (`--initial-state`, Python `initial_state=`; default
    /// [`InitialState::Estimate`]), read by every operator family: the differential ones
    /// (Jiles–Atherton, Bouc–Wen, Duhem, Dahl) fit x₀; the linear-in-weights ones regress
    /// from the declared history, and under `estimate` keep the least-loss of the
    /// demagnetised, descending and ascending starts
    /// (`linear_support::fit_initial_state`). ch4/ch6 ignore it (their output starts at the
    /// measured first sample).
    pub initial_state: InitialState,
    /// Choose the threshold count and placement of PI, generalised PI and Maxwell-slip from
    /// the data ([`crate::identify::operators::model_size`]: counts 4, 6, 8, 10, 14, 20,
    /// each uniform and geometric, scored on a held-out part) instead of the `thresholds`
    /// uniform grid (default true; ignored when `threshold_grid` is given). The command line
    /// sets it false when `--thresholds` is given, Python when `thresholds=` is.
    pub choose_thresholds: bool,
    /// Choose the Preisach and KP grid from the data (intervals 6, 8, 10, 14, 20, 30, 40,
    /// within the work bound) instead of `grid` (default true; false when `--grid` or
    /// `grid=` is given).
    pub choose_grid: bool,
    /// The PI's static envelope (`--envelope`, Python `envelope=`; default
    /// [`EnvelopeChoice::Auto`]).
    pub envelope: EnvelopeChoice,
    /// Choose the generalised PI's dead zones per side among [`DEAD_ZONE_CANDIDATES`] with
    /// its thresholds (when those are chosen) instead of `dead_zones` (default true; false
    /// when `--dead-zones` or `dead_zones=` is given).
    pub choose_dead_zones: bool,
}

/// Whether a PI fit carries a monotone static envelope E(u) beside its plays
/// (`model::operators::envelope`): `--envelope auto|none|cubic`, Python `envelope=`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum EnvelopeChoice {
    /// Chosen with the thresholds: every candidate size is tried without and with a cubic
    /// envelope on the held-out part ([`FamilyOptions::choose_thresholds`]); with fixed
    /// thresholds (`--thresholds N`, a grid) none, today's fixed recipe.
    #[default]
    Auto,
    /// No envelope.
    None,
    /// A cubic envelope, whatever the thresholds.
    Cubic,
}

impl EnvelopeChoice {
    /// Every choice, in the order the help lists them.
    pub const ALL: [EnvelopeChoice; 3] = [Self::Auto, Self::None, Self::Cubic];

    /// The name on the command line and in Python.
    pub fn name(self) -> &'static str {
        match self {
            Self::Auto => "auto",
            Self::None => "none",
            Self::Cubic => "cubic",
        }
    }

    /// The choice named `name`; the error lists them.
    pub fn parse(name: &str) -> Result<Self> {
        Self::ALL
            .into_iter()
            .find(|c| c.name() == name)
            .ok_or_else(|| {
                Error::invalid_option(
                    "envelope",
                    name,
                    "choose auto (chosen with the thresholds), none or cubic".into(),
                )
            })
    }

    /// The envelope variants a size choice tries: both under `auto`, else the one asked for.
    pub fn variants(self) -> &'static [bool] {
        match self {
            Self::Auto => &[false, true],
            Self::None => &[false],
            Self::Cubic => &[true],
        }
    }

    /// Whether a fit of fixed size carries an envelope (only under `cubic`).
    pub fn fixed(self) -> bool {
        self == Self::Cubic
    }
}

/// The candidate threshold counts of [`FamilyOptions::choose_thresholds`].
pub const THRESHOLD_CANDIDATES: [usize; 6] = [4, 6, 8, 10, 14, 20];

/// The generalised PI's dead-zone counts per side the size choice tries with its thresholds
/// (`model_size`): the static map S of a saturating record needs more pieces than the
/// default 4 (on magnet-like records 12 of them cut the held-out error by 3 to 6).
pub const DEAD_ZONE_CANDIDATES: [usize; 3] = [4, 8, 12];

/// The candidate grid sizes of [`FamilyOptions::choose_grid`].
pub const GRID_CANDIDATES: [usize; 7] = [6, 8, 10, 14, 20, 30, 40];

impl Default for FamilyOptions {
    fn default() -> Self {
        Self {
            thresholds: 10,
            threshold_grid: None,
            grid: 20,
            lambda: 1e-6,
            dead_zones: 4,
            orientation: None,
            loop_orientation: None,
            observer: Observer::none(),
            initial_state: InitialState::Estimate,
            choose_thresholds: true,
            choose_grid: true,
            envelope: EnvelopeChoice::Auto,
            choose_dead_zones: true,
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

impl FamilyOptions {
    /// The orientation a linear-in-weights family with a counter-clockwise core is to use:
    /// `orientation` if given, else `loop_orientation` with the data's trend
    /// ([`Orientation::for_loop`]), else None (the family detects it).
    pub fn given_orientation(&self, u: &[f64], y: &[f64]) -> Result<Option<Orientation>> {
        match (self.orientation, self.loop_orientation) {
            (Some(o), _) => Ok(Some(o)),
            (None, Some(l)) => Ok(Some(Orientation::for_loop(l, Orientation::trend(u, y)?))),
            (None, None) => Ok(None),
        }
    }
}

/// Where a fit's loop orientation came from (the reports' `details.orientation_source`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum OrientationSource {
    /// Given by the user (`--orientation`, `orientation=`).
    Given,
    /// Detected from the area between the branches ([`LoopOrientation::detect`]).
    Detected,
    /// Detected by `compare` on all the data it compares, when its training part cannot
    /// tell (a single loop measured from its tip), and given to each family whose own
    /// detection on the training part could not tell either.
    Record,
    /// A result of the fitted parameters (Duhem: the sign of c − a).
    Fitted,
    /// The family's native orientation, assumed (an operator cascade's start linear in the
    /// weights, which is counter-clockwise, or clockwise for Maxwell-slip, up to the trend).
    Assumed,
}

impl OrientationSource {
    /// `given`, `detected`, `record`, `fitted` or `assumed`.
    pub fn name(self) -> &'static str {
        match self {
            OrientationSource::Given => "given",
            OrientationSource::Detected => "detected",
            OrientationSource::Record => "record",
            OrientationSource::Fitted => "fitted",
            OrientationSource::Assumed => "assumed",
        }
    }
}

/// The loop orientation a fitted operator has, and where it came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OrientationUsed {
    /// The turning sense of the fitted model's loop in the (u, y) plane.
    pub orientation: LoopOrientation,
    /// Given, detected, record (`compare`), fitted or assumed.
    pub source: OrientationSource,
}

impl OrientationUsed {
    /// The orientation of the fitted operator `model` of `family` (None for ch4/ch6) and its
    /// source: given when
    /// `options` give one, fitted for a family that does not read the setting, else
    /// detected (`cascade`: assumed for the cascade starts that are linear in the weights);
    /// None for the Coleman–Hodgdon hysteresis.
    pub fn of(
        family: Family,
        model: Option<&OperatorModel>,
        options: &FamilyOptions,
        cascade: bool,
    ) -> Option<OrientationUsed> {
        let orientation = model?.loop_orientation();
        let reads = family.settings().contains(&FamilySetting::Orientation);
        let source = if options.orientation.is_some() || options.loop_orientation.is_some() {
            OrientationSource::Given
        } else if !reads {
            OrientationSource::Fitted
        } else if cascade
            && matches!(
                family,
                Family::Pi
                    | Family::MaxwellSlip
                    | Family::Backlash
                    | Family::Gpi
                    | Family::Preisach
                    | Family::Kp
            )
        {
            OrientationSource::Assumed
        } else {
            OrientationSource::Detected
        };
        Some(OrientationUsed {
            orientation,
            source,
        })
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
    /// The fitted model's loop orientation and where it came from (None for ch4/ch6).
    pub orientation: Option<OrientationUsed>,
}

impl FittedOperator {
    /// The number of estimated parameters (those not held fixed).
    pub fn estimated_parameters(&self) -> usize {
        self.fit.parameters.iter().filter(|p| !p.fixed).count()
    }
}

/// A family's identification recipe: implemented for each operator type of the registry
/// ([`crate::model::operators::registry`]) in the family's own module of
/// [`crate::identify::operators`].
pub trait Identify: OperatorFamily + Into<OperatorModel> {
    /// The settings of [`FamilyOptions`] this family's fit reads; it ignores the others
    /// (the command line refuses them for it, naming the families that read them).
    const SETTINGS: &'static [FamilySetting];

    /// Fits the family to input `u` and output `y` from the data alone (no initial guess),
    /// with the user's `options` (the settings that do not apply to the family are ignored).
    fn identify(u: &[f64], y: &[f64], options: &FamilyOptions) -> Result<OperatorFit<Self>>;

    /// The global start of an operator cascade with this family's operator (the refinement
    /// of [`OperatorCascadeIdentification`] takes it from there), with a short description
    /// of how it was obtained. The default: the family's own fit to the loop (u, y) in the
    /// counter-clockwise orientation, then an ARX fit of y on v₀ = Γ₀\[u\]
    /// ([`OperatorCascadeIdentification::family_arx_start`]).
    fn cascade_start(
        cascade: &OperatorCascadeIdentification,
        u: &[f64],
        y: &[f64],
        options: &FamilyOptions,
    ) -> Result<(OperatorCascade, &'static str)> {
        // Γ₀ = G (Γ₀ = G⁻¹ when the user gave a clockwise loop); the linear block carries
        // the sign
        // the cascade's start keeps its fixed sizes (its refinement sees the whole record)
        let options = FamilyOptions {
            choose_thresholds: false,
            choose_grid: false,
            orientation: Some(match options.loop_orientation {
                Some(LoopOrientation::Clockwise) => Orientation::CLOCKWISE,
                _ => Orientation::COUNTER_CLOCKWISE,
            }),
            ..options.clone()
        };
        let start = Self::identify(u, y, &options)?.model.into();
        Ok((cascade.family_arx_start(start, u, y)?, FAMILY_ARX))
    }
}

/// A setting of [`FamilyOptions`] that some families read ([`Identify::SETTINGS`]; the
/// observer is read by every family with a search).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FamilySetting {
    /// [`FamilyOptions::thresholds`].
    Thresholds,
    /// [`FamilyOptions::threshold_grid`].
    ThresholdGrid,
    /// [`FamilyOptions::grid`].
    Grid,
    /// [`FamilyOptions::lambda`].
    Lambda,
    /// [`FamilyOptions::dead_zones`].
    DeadZones,
    /// [`FamilyOptions::orientation`].
    Orientation,
    /// [`FamilyOptions::envelope`].
    Envelope,
}

impl Family {
    /// The settings this family's fit reads (none for ch4 and ch6, which have no options).
    pub fn settings(self) -> &'static [FamilySetting] {
        by_family::settings(self)
    }

    /// The families whose fit reads `setting`, in the registry's order.
    pub fn reading(setting: FamilySetting) -> Vec<Family> {
        Family::ALL
            .iter()
            .copied()
            .filter(|f| f.settings().contains(&setting))
            .collect()
    }
}

/// How [`Identify::cascade_start`]'s default start is obtained.
pub const FAMILY_ARX: &str = "family fit and ARX";

/// The smallest model of any family — (parameters, samples it needs): a gain and one shape
/// parameter, with the samples the linear families'
/// data check asks of that many parameters, max(2p, p + 10).
const SMALLEST_MODEL: (usize, usize) = (2, 12);

/// Fits `family` to input `u` and output `y` with `options`.
pub fn fit_operator(
    family: Family,
    u: &[f64],
    y: &[f64],
    options: &FamilyOptions,
) -> Result<FittedOperator> {
    options.validate()?;
    // A record too short for any family's smallest model is said to be so before anything
    // (its loop's orientation first) is read from it.
    if u.len() < SMALLEST_MODEL.1 {
        return Err(Error::TooFewSamples {
            samples: u.len(),
            parameters: SMALLEST_MODEL.0,
            needed: SMALLEST_MODEL.1,
        });
    }
    let fit = match family {
        Family::Ch4 => coleman_hodgdon(ChForm::Saturated4, u, y)?,
        Family::Ch6 => coleman_hodgdon(ChForm::General6, u, y)?,
        operator => by_family::fit(operator, u, y, options)?,
    };
    let operator = match &fit.model {
        FittedModel::Operator(FittedHysteresisOperator { model, .. }) => Some(model),
        _ => None,
    };
    let orientation = OrientationUsed::of(family, operator, options, false);
    Ok(FittedOperator {
        family,
        fit,
        orientation,
    })
}

/// The start of an operator cascade of `family` (an operator family, not ch4/ch6).
pub(crate) fn cascade_start(
    family: Family,
    cascade: &OperatorCascadeIdentification,
    u: &[f64],
    y: &[f64],
    options: &FamilyOptions,
) -> Result<(OperatorCascade, &'static str)> {
    by_family::cascade_start(family, cascade, u, y, options)
}

/// The dispatch from a [`Family`] to its type's [`Identify`] implementation, generated
/// from the registry's list.
mod by_family {
    use super::*;

    macro_rules! dispatch {
        ($($variant:ident: $ty:ty),* $(,)?) => {
            pub(super) fn settings(family: Family) -> &'static [FamilySetting] {
                match family {
                    $(Family::$variant => <$ty as Identify>::SETTINGS,)*
                    Family::Ch4 | Family::Ch6 => &[],
                }
            }

            pub(super) fn fit(
                family: Family,
                u: &[f64],
                y: &[f64],
                options: &FamilyOptions,
            ) -> Result<OperatorFit<FittedModel>> {
                match family {
                    $(Family::$variant => Ok(boxed(<$ty as Identify>::identify(u, y, options)?, u)),)*
                    other => Err(not_an_operator(other)),
                }
            }

            pub(super) fn cascade_start(
                family: Family,
                cascade: &OperatorCascadeIdentification,
                u: &[f64],
                y: &[f64],
                options: &FamilyOptions,
            ) -> Result<(OperatorCascade, &'static str)> {
                match family {
                    $(Family::$variant => <$ty as Identify>::cascade_start(cascade, u, y, options),)*
                    other => Err(not_an_operator(other)),
                }
            }
        };
    }
    crate::model::operators::operator_families!(dispatch);

    fn not_an_operator(family: Family) -> Error {
        Error::Unsupported(format!(
            "{family} is the Coleman–Hodgdon hysteresis, not an operator family; \
             identify it with `identify hysteresis` or `identify cascade --hysteresis {family}`"
        ))
    }
}

/// An operator fit on the input `u` with its model wrapped as a [`FittedModel`] (a declared
/// history keeps the turn the fit used on `u`).
fn boxed<M: Into<OperatorModel>>(fit: OperatorFit<M>, u: &[f64]) -> OperatorFit<FittedModel> {
    let std = fit.std.iter().map(|s| s.unwrap_or(f64::NAN)).collect();
    let model: OperatorModel = fit.model.into();
    let turn = fit.history_turn.or_else(|| {
        fit.initial_state
            .and_then(|state| state.turning_input(model.as_operator(), u))
    });
    OperatorFit {
        model: FittedModel::operator(model, std).with_initial_state(fit.initial_state, turn),
        parameters: fit.parameters,
        std: fit.std,
        covariance: fit.covariance,
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
        initial_state: fit.initial_state,
        history_turn: turn,
        model_size: fit.model_size,
    }
}

/// The Coleman–Hodgdon hysteresis alone ([`HysteresisIdentification`]), its output starting
/// at the measured first sample.
///
/// The fit runs on the record in units of unit size, x' = x/sₓ and y' = y/s_y (powers of
/// two, `differential_fit::unit_scale`), and the parameters return in the record's units: (D) is unchanged
/// by α = α'/sₓ, m = m'·s_y/sₓ, c = c'·s_y/sₓ, d = d'·sₓ, so a record in kV and nm fits as
/// the same record in V and µm does.
fn coleman_hodgdon(form: ChForm, u: &[f64], y: &[f64]) -> Result<OperatorFit<FittedModel>> {
    let started = Instant::now();
    // Equal lengths, enough samples, an input that reverses (a loop, not a curve) — the
    // recipe itself accepts a monotone input, on which d and the loop are not identifiable.
    super::differential_fit::check_record(form.short_name(), u, y, form.n_params())?;
    let (sx, sy) = (
        super::differential_fit::unit_scale(u),
        super::differential_fit::unit_scale(y),
    );
    let scaled = |v: &[f64], s: f64| v.iter().map(|x| x / s).collect::<Vec<f64>>();
    let data = IdData::siso(1.0, "u", scaled(u, sx), "y", scaled(y, sy))?;
    // the zoo's ch6 starts no worse than its nested ch4 (`better_start`)
    let id = HysteresisIdentification {
        nested_start: true,
        ..HysteresisIdentification::new(form)
    };
    // a refusal quotes α and Δx in the record's units
    let fit = id
        .estimate(&data, &mut |_| Control::Continue)
        .map_err(|e| match e {
            Error::RateLimit {
                index,
                alpha,
                dx,
                product,
            } => Error::RateLimit {
                index,
                alpha: alpha / sx,
                dx: dx * sx,
                product,
            },
            e => e,
        })?;
    // α, the slopes m and c, then d
    let factor: Vec<f64> = (0..form.n_params())
        .map(|k| match k {
            0 => 1.0 / sx,
            k if k + 1 == form.n_params() => sx,
            _ => sy / sx,
        })
        .collect();
    let unscale = |v: Vec<f64>| -> Vec<f64> { v.iter().zip(&factor).map(|(v, f)| v * f).collect() };
    let model = ColemanHodgdon::from_params(form, &unscale(fit.model.params()))?;
    let std = unscale(fit.std());
    let covariance = DMatrix::from_fn(factor.len(), factor.len(), |i, j| {
        fit.output_error.covariance.matrix[(i, j)] * factor[i] * factor[j]
    });
    let std_present: Vec<Option<f64>> = std.iter().map(|s| s.is_finite().then_some(*s)).collect();
    let simulated = simulate_switched(&model, u, y[0], None);
    let parameters = ParameterSet::new(
        form.parameter_names()
            .iter()
            .zip(model.params())
            .map(|(name, v)| Parameter::new(*name, v))
            .collect(),
    )?;
    let n = y.len();
    let p = form.n_params();
    let loss = metrics::mse(y, &simulated);
    let report = &fit.output_error.report;
    Ok(OperatorFit {
        model: FittedModel::Hysteresis(FittedHysteresis {
            model,
            initial: InitialOutput::Measured,
            std: std.clone(),
        }),
        parameters,
        covariance: masked_covariance(&covariance, &std_present),
        std: std_present,
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
        initial_state: None,
        history_turn: None,
        model_size: None,
    })
}
