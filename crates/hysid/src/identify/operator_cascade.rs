//! Identification of an operator cascade ([`OperatorCascade`]: any hysteresis family
//! followed by a linear block with b1 = 1) from input and output data alone.
//!
//! The shape of the Coleman–Hodgdon cascade pipeline ([`super::cascade`]): a global
//! initialisation that needs no start, then output-error refinement of every parameter, then
//! asymptotic standard deviations.
//!
//! **Initialisation, families linear in their weights** (`pi`, `maxwell-slip`, and `backlash`
//! at a fixed half-width r). With basis signals φ_l\[u\] (PI: u, the plays F_{rᵢ}\[u\], 1;
//! Maxwell-slip: u, the stops E_{δᵢ}\[u\], 1; backlash: F_r\[u\], 1) the operator is
//! v = Σ θ_l φ_l, so the cascade is the *over-parameterised* linear regression
//!
//! ```text
//! y(t) = −Σᵢ aᵢ y(t−i) + Σⱼ Σ_l c_{jl} φ_l(t−k−j+1),     c_{jl} = bⱼ θ_l,
//! ```
//!
//! solved by equation-error least squares (signals zero before t = 0, as the model starts from
//! rest). The coefficient matrix C = b θᵀ has rank one; its best rank-one approximation
//! σ₁ u₁ v₁ᵀ (SVD) gives b = u₁/u₁,₁ (b1 = 1) and θ = σ₁ u₁,₁ v₁ (Bai 1998). A negative overall
//! slope is the decreasing orientation (Γ = −G), and weights are projected onto the family's
//! monotone set. Backlash profiles this over a grid of r (r = k·(max u − min u)/(2P)) and keeps
//! the r of least equation error. The thresholds (widths) sit on the family's grid
//! rᵢ = i·(max u − min u)/(2(n + 1)).
//!
//! **Initialisation, the other families** (`gpi`, `preisach`, `jiles-atherton`, `bouc-wen`,
//! `duhem`, `dahl`): the family's own recipe fitted to the loop (u, y) gives Γ₀ — its search
//! over the family's few nonlinear parameters is the grid stage — then an ARX least-squares
//! fit of y on past y and v₀ = Γ₀\[u\] gives A and an unnormalised B; b1 is moved into Γ by
//! the family's output scale ([`OperatorModel::scaled`]) where it has one.
//!
//! **Refinement**: output error over every free parameter of both blocks with the bounded
//! Levenberg–Marquardt engine ([`super::output_error`]), finite-difference sensitivities,
//! standard deviations σ²(JᵀJ)⁻¹ at the optimum (Ljung 1999, §9.3).
//!
//! References: I. Vörös, Nonlinear Dynamics 79 (2015) (the cascade and b1 = 1); E.-W. Bai,
//! "An optimal two-stage identification algorithm for Hammerstein–Wiener nonlinear systems",
//! Automatica 34 (1998) 333–338 (over-parameterisation and the rank-one SVD factorisation);
//! L. Ljung, *System Identification*, 2nd ed., 1999.

use super::operators::differential_fit::linear_fit;
use super::operators::family::{self, Family, FamilyOptions};
use super::operators::linear_support::threshold_grid;
use super::output_error::{OutputError, OutputErrorFit, OutputErrorModel};
use crate::data::IdData;
use crate::model::operators::{OperatorModel, Orientation};
use crate::model::{LinearBlock, OperatorCascade, ParameterSet};
use crate::numerics::{Control, IterationRecord, Termination};
use crate::{Error, Result};
use nalgebra::DMatrix;
use std::time::Instant;

/// Settings of the operator-cascade identification.
#[derive(Clone, Debug, PartialEq)]
pub struct OperatorCascadeIdentification {
    /// The operator family (an operator family of the registry, not ch4/ch6).
    pub family: Family,
    /// The family's settings (thresholds, Preisach grid, …), as for `identify operator`.
    pub options: FamilyOptions,
    /// Order n of A(q⁻¹).
    pub na: usize,
    /// Number m ≥ 1 of B coefficients (b1 = 1 included).
    pub nb: usize,
    /// Input delay k of the linear block.
    pub delay: usize,
    /// Maximum Levenberg–Marquardt iterations of the refinement (200).
    pub max_iterations: usize,
}

/// A fitted operator cascade with the figures every recipe returns.
#[derive(Clone, Debug)]
pub struct OperatorCascadeFit {
    /// The estimate.
    pub model: OperatorCascade,
    /// The global initialisation's model (the refinement's start).
    pub start: OperatorCascade,
    /// How the start was obtained (`equation-error least squares, rank-one factorisation` or
    /// `family fit and ARX`).
    pub initialisation: &'static str,
    /// The fitted operator's loop orientation and where it came from.
    pub orientation: Option<family::OrientationUsed>,
    /// The output-error refinement (parameters, covariance, history, simulated output).
    pub output_error: OutputErrorFit,
    /// fit % = 100 (1 − ‖y − ŷ‖/‖y − ȳ‖) on the first experiment.
    pub fit_percent: f64,
    /// Root-mean-square error of the simulated output.
    pub rmse: f64,
    /// Loss V = mean squared residual.
    pub loss: f64,
    /// Akaike's final prediction error.
    pub fpe: f64,
    /// Akaike's information criterion.
    pub aic: f64,
    /// Levenberg–Marquardt iterations.
    pub iterations: usize,
    /// Why the refinement stopped.
    pub termination: Termination,
    /// Standard deviation per parameter (None for fixed or unidentifiable ones).
    pub std: Vec<Option<f64>>,
    /// Wall-clock seconds.
    pub elapsed_s: f64,
}

impl OperatorCascadeIdentification {
    /// Settings with the family's default options and 200 refinement iterations.
    pub fn new(family: Family, na: usize, nb: usize, delay: usize) -> Self {
        Self {
            family,
            options: FamilyOptions::default(),
            na,
            nb,
            delay,
            max_iterations: 200,
        }
    }

    /// Identifies the cascade from the first input and output channel of `data` (all its
    /// experiments in the refinement, the first in the initialisation). `callback` sees every
    /// accepted refinement iteration.
    pub fn estimate(
        &self,
        data: &IdData,
        callback: &mut dyn FnMut(&IterationRecord) -> Control,
    ) -> Result<OperatorCascadeFit> {
        let started = Instant::now();
        self.check(data)?;
        let (u, y) = (data.input(0, 0), data.output(0, 0));
        let (start, initialisation) = self.initialise(u, y)?;
        let structure = Structure {
            template: start.clone(),
        };
        let params = start.parameters();
        let oe = OutputError::new()
            .max_iterations(self.max_iterations)
            .improvement_tolerance(1e-12)
            .estimate(&structure, data, &params, callback)?;
        let model = start.with_values(&oe.parameters.values())?;
        let orientation =
            family::OrientationUsed::of(self.family, Some(&model.operator), &self.options, true);
        let std = oe
            .std()
            .iter()
            .zip(oe.parameters.iter())
            .map(|(s, p)| (!p.fixed && s.is_finite()).then_some(*s))
            .collect();
        Ok(OperatorCascadeFit {
            fit_percent: oe.fit_percent[0][0],
            rmse: oe.mse[0][0].sqrt(),
            loss: oe.loss,
            fpe: oe.fpe,
            aic: oe.aic,
            iterations: oe.report.iterations,
            termination: oe.report.termination.clone(),
            std,
            model,
            start,
            initialisation,
            orientation,
            output_error: oe,
            elapsed_s: started.elapsed().as_secs_f64(),
        })
    }

    fn check(&self, data: &IdData) -> Result<()> {
        Family::parse_operator(self.family.name())?;
        self.options.validate()?;
        if self.nb == 0 {
            return Err(Error::invalid_option(
                "nb",
                0,
                "the linear block needs at least one B coefficient (b1 = 1); give nb >= 1".into(),
            ));
        }
        if data.input_channels().len() != 1 || data.output_channels().len() != 1 {
            return Err(Error::ModelMismatch(format!(
                "an operator cascade has one input and one output; the data have {} and {}",
                data.input_channels().len(),
                data.output_channels().len()
            )));
        }
        let n = data.experiment(0).len();
        let needed = 10 * (self.na + self.nb + self.delay + 2);
        if n < needed {
            return Err(Error::TooFewSamples {
                samples: n,
                parameters: self.na + self.nb,
                needed,
            });
        }
        Ok(())
    }

    /// The global initialisation (module doc): the family's [`Identify::cascade_start`].
    /// A turning sense the user gave (`options.loop_orientation`) that the start cannot take
    /// (a start linear in the weights has its family's native turning sense, up to the
    /// trend) is refused.
    fn initialise(&self, u: &[f64], y: &[f64]) -> Result<(OperatorCascade, &'static str)> {
        let (start, how) = family::cascade_start(self.family, self, u, y, &self.options)?;
        if let Some(given) = self.options.loop_orientation {
            let got = start.operator.loop_orientation();
            if got != given {
                return Err(Error::Unsupported(format!(
                    "a {} cascade's start gives a {} operator on this record, not the {} one \
                     asked for (--orientation {}); its start is linear in the weights and keeps \
                     the family's own turning sense: drop --orientation or use another family",
                    self.family.name(),
                    got.short_name(),
                    given.short_name(),
                    given.short_name()
                )));
            }
        }
        Ok((start, how))
    }

    /// Equation-error least squares of y on past y and the lagged basis signals; returns
    /// (a, b with b1 = 1, θ) from the rank-one factorisation, and the residual sum of squares.
    pub(crate) fn rank_one(&self, y: &[f64], basis: &[Vec<f64>]) -> Result<RankOne> {
        let (na, nb, k) = (self.na, self.nb, self.delay);
        let l = basis.len();
        let mut columns: Vec<Vec<f64>> = (1..=na).map(|i| lagged(y, i, -1.0)).collect();
        for j in 0..nb {
            columns.extend(basis.iter().map(|phi| lagged(phi, k + j, 1.0)));
        }
        let refs: Vec<&[f64]> = columns.iter().map(Vec::as_slice).collect();
        let (coef, sse) = linear_fit(&refs, y).ok_or_else(|| Error::NotExciting {
            channel: "u".into(),
            reason: "the equation-error regression of the cascade is singular; the input \
                     must excite the operator and the linear block (reversals, varied amplitude)"
                .into(),
        })?;
        let a = coef[..na].to_vec();
        let c = DMatrix::from_fn(nb, l, |j, m| coef[na + j * l + m]);
        let svd = c.svd(true, true);
        let (Some(us), Some(vt)) = (svd.u, svd.v_t) else {
            return Err(Error::Singular("rank-one factorisation failed".into()));
        };
        let best = svd.singular_values.iter().enumerate().fold(0, |b, (i, s)| {
            if *s > svd.singular_values[b] {
                i
            } else {
                b
            }
        });
        let sigma = svd.singular_values[best];
        let u1 = us.column(best);
        if u1[0].abs() <= 1e-12 * u1.amax() || sigma == 0.0 {
            return Err(Error::NotExciting {
                channel: "u".into(),
                reason: "the first B coefficient is not identifiable from these data (b1 ≈ 0); \
                         check the delay"
                    .into(),
            });
        }
        let b: Vec<f64> = u1.iter().map(|v| v / u1[0]).collect();
        let theta: Vec<f64> = vt.row(best).iter().map(|v| sigma * u1[0] * v).collect();
        Ok(RankOne { a, b, theta, sse })
    }

    /// The start's cascade; an unstable A from the equation error (a misfitting Γ₀ can give
    /// one) has its poles pulled radially inside the unit circle, aᵢ ← aᵢ ρⁱ with
    /// ρ = 0.95/(spectral radius), because output error cannot start from a diverging
    /// simulation.
    pub(crate) fn cascade(
        &self,
        operator: OperatorModel,
        a: Vec<f64>,
        b: Vec<f64>,
    ) -> Result<OperatorCascade> {
        let mut linear = LinearBlock::new(a, b, self.delay)?;
        let radius = linear.spectral_radius();
        if radius >= 0.99 {
            let rho = 0.95 / radius;
            let a = linear
                .a()
                .iter()
                .zip(1..)
                .map(|(ai, i)| ai * rho.powi(i))
                .collect();
            linear = LinearBlock::new(a, linear.b().to_vec(), self.delay)?;
        }
        OperatorCascade::new(operator, linear)
    }

    /// The rank-one start of an operator that is a superposition c₀u + Σ cᵢ e_{rᵢ}\[u\] + c of
    /// elements `element(u, rᵢ)` (plays for PI, stops for Maxwell-slip) on the threshold grid
    /// of `options` (the given grid, else the uniform one of `options.thresholds`): the grid,
    /// A, B (b1 = 1), the linear parameters [c₀, c₁ … cₙ, c] oriented so that the slope
    /// c₀ + … + cₙ is ≥ 0, and that orientation.
    pub(crate) fn superposition_start(
        &self,
        u: &[f64],
        y: &[f64],
        options: &FamilyOptions,
        element: impl Fn(&[f64], f64) -> Vec<f64>,
    ) -> Result<SuperpositionStart> {
        let grid = match &options.threshold_grid {
            Some(grid) => grid.clone(),
            None => threshold_grid(u, options.thresholds)?,
        };
        let n = grid.len();
        let mut basis = vec![u.to_vec()];
        basis.extend(grid.iter().map(|&r| element(u, r)));
        basis.push(vec![1.0; u.len()]);
        let RankOne { a, b, theta, .. } = self.rank_one(y, &basis)?;
        let (theta, orientation) = oriented(theta, |t| t[..=n].iter().sum::<f64>());
        Ok(SuperpositionStart {
            grid,
            a,
            b,
            theta,
            orientation,
        })
    }

    /// The start from an operator Γ₀ fitted to the loop (u, y): an ARX fit of y on past y and
    /// v₀ = Γ₀\[u\] gives A and an unnormalised B, whose b1 moves into Γ₀'s output scale
    /// ([`OperatorModel::scaled`]) where it has one.
    pub fn family_arx_start(
        &self,
        op: OperatorModel,
        u: &[f64],
        y: &[f64],
    ) -> Result<OperatorCascade> {
        let v = op.as_operator().simulate(u)?;
        // With the single basis signal v₀ the factorisation returns b/b1 and θ = b1.
        let RankOne { a, b, theta, .. } = self.rank_one(y, &[v])?;
        let op = op.scaled(theta[0]).unwrap_or(op);
        self.cascade(op, a, b)
    }
}

/// How the families linear in their weights start (the over-parameterised equation error and
/// its rank-one factorisation, module doc).
pub const RANK_ONE: &str = "equation-error least squares, rank-one factorisation";

/// What [`OperatorCascadeIdentification::superposition_start`] finds.
pub(crate) struct SuperpositionStart {
    /// The thresholds rᵢ.
    pub grid: Vec<f64>,
    /// A's coefficients a1 … an.
    pub a: Vec<f64>,
    /// B's coefficients with b1 = 1.
    pub b: Vec<f64>,
    /// The operator's linear parameters [c₀, c₁ … cₙ, c], oriented.
    pub theta: Vec<f64>,
    /// The orientation that makes the slope non-negative.
    pub orientation: Orientation,
}

/// The rank-one factorisation of the over-parameterised regression: A, B (b1 = 1), the
/// operator's linear parameters θ and the equation error's residual sum of squares.
pub(crate) struct RankOne {
    /// A's coefficients a1 … an.
    pub a: Vec<f64>,
    /// B's coefficients with b1 = 1.
    pub b: Vec<f64>,
    /// The operator's linear parameters.
    pub theta: Vec<f64>,
    /// The equation error's residual sum of squares.
    pub sse: f64,
}

/// (θ, orientation): θ negated with the decreasing orientation when its slope is negative.
pub(crate) fn oriented(theta: Vec<f64>, slope: impl Fn(&[f64]) -> f64) -> (Vec<f64>, Orientation) {
    if slope(&theta) < 0.0 {
        let o = Orientation {
            inverse: false,
            decreasing: true,
        };
        (theta.iter().map(|v| -v).collect(), o)
    } else {
        (theta, Orientation::COUNTER_CLOCKWISE)
    }
}

/// The nearest weights with a₀ ≥ 0 and every partial sum a₀ + … + aᵢ ≥ 0 (a monotone PI).
pub(crate) fn monotone_weights(a0: f64, weights: &[f64]) -> (f64, Vec<f64>) {
    let a0 = a0.max(0.0);
    let mut partial = a0;
    let w = weights
        .iter()
        .map(|&a| {
            let a = a.max(-partial);
            partial += a;
            a
        })
        .collect();
    (a0, w)
}

/// s·x(t − lag), zero before the start.
fn lagged(x: &[f64], lag: usize, s: f64) -> Vec<f64> {
    (0..x.len())
        .map(|t| t.checked_sub(lag).map_or(0.0, |p| s * x[p]))
        .collect()
}

/// The cascade as an output-error model: the start's structure with free values.
struct Structure {
    template: OperatorCascade,
}

impl OutputErrorModel for Structure {
    fn parameters(&self) -> ParameterSet {
        self.template.parameters()
    }
    fn n_outputs(&self) -> usize {
        1
    }
    fn simulate(&self, theta: &[f64], data: &IdData, exp: usize, y: &mut [Vec<f64>]) -> Result<()> {
        let model = self.template.with_values(theta)?;
        let out = model.simulate(data.input(exp, 0))?;
        y[0].copy_from_slice(&out.y);
        Ok(())
    }
}
