//! Recursive least squares with exponential forgetting: online identification, as the
//! conclusion of Vörös (2015) proposes, over the two regressions of this project.
//!
//! * [`RecursiveCascade`]: the key-term-separation regression of the cascade
//!   ([`super::key_term`]), y(t) − v̂(t−k−1) = φ̂(t)ᵀθ + e(t), with the internal variables
//!   from an *auxiliary model* (ĥ from its d, v̂ from its hysteresis recursion).
//! * [`RecursiveHysteresis`]: the separated regression of the hysteresis alone,
//!   Δy(t) = φ_h(t)ᵀθ_h + e(t), when its input and output are both measured; ĥ(t) comes from
//!   the current d̂.
//!
//! # Update
//!
//! ```text
//! K(t) = P(t−1)φ(t) / (λ + φ(t)ᵀP(t−1)φ(t))
//! θ̂(t) = θ̂(t−1) + K(t)[z(t) − φ(t)ᵀθ̂(t−1)]
//! P(t) = [P(t−1) − K(t)φ(t)ᵀP(t−1)] / λ
//! ```
//!
//! with forgetting factor λ ∈ (0, 1] (memory ≈ 1/(1 − λ) samples). P is re-symmetrised at
//! every step — round-off otherwise destroys its positive definiteness over long records and
//! the recursion diverges — and its trace is capped at its initial value (constant-trace
//! bound) against the wind-up that forgetting causes in poorly excited directions, such as
//! the outer segment of the material functions while the input stays below d.
//!
//! The physical parameters are recovered from θ̂ at every sample (α = θ4, m1 = θ1/α, …,
//! docs/models/coleman-hodgdon-cascade.md §5); they keep their last valid values when the
//! recovery is undefined.
//!
//! References: L. Ljung, T. Söderström, Theory and Practice of Recursive Identification, MIT
//! Press 1983, ch. 2 and §5.6; D. Wang, F. Ding, Y. Chu, Information Sciences 222, 2013
//! (key-term separation with recursive least squares).

use crate::model::{ChForm, ColemanHodgdon, HysteresisCascade};
use crate::{Error, Result};
use nalgebra::{DMatrix, DVector};

/// The recursive least-squares core shared by both estimators.
#[derive(Clone, Debug)]
struct Recursion {
    theta: DVector<f64>,
    cov: DMatrix<f64>,
    forgetting: f64,
    max_trace: f64,
}

impl Recursion {
    fn new(theta: Vec<f64>, initial_covariance: f64, forgetting: f64) -> Result<Self> {
        if !(forgetting > 0.0 && forgetting <= 1.0) {
            return Err(Error::invalid_option(
                "forgetting",
                forgetting,
                format!("forgetting factor must be in (0, 1], got {forgetting}"),
            ));
        }
        if !(initial_covariance > 0.0 && initial_covariance.is_finite()) {
            return Err(Error::invalid_option(
                "initial_covariance",
                initial_covariance,
                format!("initial covariance must be finite and > 0, got {initial_covariance}"),
            ));
        }
        let p = theta.len();
        Ok(Self {
            theta: DVector::from_vec(theta),
            cov: DMatrix::identity(p, p) * initial_covariance,
            forgetting,
            max_trace: initial_covariance * p as f64,
        })
    }

    /// One update with regressor `phi` and target `z`.
    fn update(&mut self, phi: &DVector<f64>, z: f64) {
        let p_phi = &self.cov * phi;
        let gain = &p_phi / (self.forgetting + phi.dot(&p_phi));
        self.theta += &gain * (z - phi.dot(&self.theta));
        self.cov = (&self.cov - &gain * p_phi.transpose()) / self.forgetting;
        self.cov = (&self.cov + self.cov.transpose()) * 0.5;
        let trace = self.cov.trace();
        if trace > self.max_trace {
            self.cov *= self.max_trace / trace;
        }
    }
}

/// Settings shared by the recursive estimators.
#[derive(Clone, Debug)]
pub struct RlsSettings {
    /// Forgetting factor λ ∈ (0, 1].
    pub forgetting: f64,
    /// Initial covariance P(0) = p0·I; small when starting from a batch estimate.
    pub initial_covariance: f64,
    /// Keep the physical parameters every `record_every` samples.
    pub record_every: usize,
}

impl Default for RlsSettings {
    fn default() -> Self {
        Self {
            forgetting: 0.995,
            initial_covariance: 1.0,
            record_every: 10,
        }
    }
}

/// The recorded trajectory of the physical parameters.
#[derive(Clone, Debug)]
pub struct RlsTrack {
    /// Sample index of each record.
    pub t: Vec<usize>,
    /// Physical parameters at each record.
    pub params: Vec<Vec<f64>>,
}

impl RlsTrack {
    fn push(&mut self, t: usize, params: Vec<f64>) {
        self.t.push(t);
        self.params.push(params);
    }

    /// The parameters recorded last before or at sample `t`.
    pub fn at(&self, t: usize) -> Option<&[f64]> {
        let i = self.t.partition_point(|&s| s <= t);
        i.checked_sub(1).map(|i| self.params[i].as_slice())
    }
}

/// Recursive least squares over the key-term-separation regression of the cascade.
#[derive(Clone, Debug, Default)]
pub struct RecursiveCascade {
    /// Forgetting, initial covariance, recording.
    pub settings: RlsSettings,
    /// Per-sample rate μ at which the auxiliary model's hysteresis follows the estimates,
    /// θ_aux ← θ_aux + μ(θ̂ − θ_aux), the recursive counterpart of relaxation. The default 0
    /// holds the auxiliary hysteresis at the initial (batch) estimate, so the recursion tracks
    /// the linear block. μ > 0 lets the hysteresis follow too, but, as in the batch iteration
    /// without relaxation, the loop through the internal variables is fragile; to track the
    /// hysteresis itself from its measured input and output use [`RecursiveHysteresis`].
    pub auxiliary_rate: f64,
}

impl RecursiveCascade {
    /// Runs over (x, y) from `initial` (typically a batch estimate on an early part of the
    /// record). Records [`HysteresisCascade::params`]-ordered vectors.
    pub fn run(&self, x: &[f64], y: &[f64], initial: &HysteresisCascade) -> Result<RlsTrack> {
        check_lengths(x, y)?;
        let form = initial.hysteresis.form();
        let (na, nb, k) = (
            initial.linear.na(),
            initial.linear.nb(),
            initial.linear.delay(),
        );
        let nh = form.n_params();
        let mut theta0 = initial.hysteresis.separated_params();
        theta0.extend_from_slice(&initial.linear.b()[1..]);
        theta0.extend_from_slice(initial.linear.a());
        let mut rls = Recursion::new(
            theta0,
            self.settings.initial_covariance,
            self.settings.forgetting,
        )?;
        let mut auxiliary = initial.hysteresis.clone();
        let mut estimate = initial.hysteresis.clone();
        let mut v = vec![0.0; x.len()];
        let mut phi = DVector::zeros(rls.theta.len());
        let mut buf = vec![0.0; nh];
        let mut track = RlsTrack {
            t: Vec::new(),
            params: Vec::new(),
        };
        let t0 = na.max(k + 1).max(k + nb - 1);
        for t in t0..x.len() {
            ColemanHodgdon::separated_regressor(
                form,
                auxiliary.d(),
                x[t - k - 1],
                x[t - k],
                v[t - k - 1],
                &mut buf,
            );
            phi.rows_mut(0, nh).copy_from_slice(&buf);
            for j in 2..=nb {
                phi[nh + j - 2] = v[t - k - j + 1];
            }
            for i in 1..=na {
                phi[nh + nb - 2 + i] = -y[t - i];
            }
            rls.update(&phi, y[t] - v[t - k - 1]);
            if let Ok(h) = ColemanHodgdon::from_separated(form, &rls.theta.as_slice()[..nh]) {
                estimate = h;
            }
            if self.auxiliary_rate > 0.0 {
                auxiliary = follow(&auxiliary, &estimate, self.auxiliary_rate);
            }
            // Extend the auxiliary model by one sample.
            v[t - k] = auxiliary.step(v[t - k - 1], x[t - k - 1], x[t - k]);
            if (t - t0) % self.settings.record_every.max(1) == 0 || t + 1 == x.len() {
                let mut params = estimate.params();
                params.extend(rls.theta.iter().skip(nh));
                track.push(t, params);
            }
        }
        Ok(track)
    }
}

/// Recursive least squares over the separated regression of the hysteresis alone.
#[derive(Clone, Debug, Default)]
pub struct RecursiveHysteresis {
    /// Forgetting, initial covariance, recording.
    pub settings: RlsSettings,
}

impl RecursiveHysteresis {
    /// Runs over the measured hysteresis input x and output y from `initial`. Records
    /// [`ChForm::parameter_names`]-ordered vectors.
    pub fn run(&self, x: &[f64], y: &[f64], initial: &ColemanHodgdon) -> Result<RlsTrack> {
        check_lengths(x, y)?;
        let form: ChForm = initial.form();
        let mut rls = Recursion::new(
            initial.separated_params(),
            self.settings.initial_covariance,
            self.settings.forgetting,
        )?;
        let mut estimate = initial.clone();
        let mut buf = vec![0.0; form.n_params()];
        let mut track = RlsTrack {
            t: Vec::new(),
            params: Vec::new(),
        };
        for t in 1..x.len() {
            ColemanHodgdon::separated_regressor(
                form,
                estimate.d(),
                x[t - 1],
                x[t],
                y[t - 1],
                &mut buf,
            );
            rls.update(&DVector::from_column_slice(&buf), y[t] - y[t - 1]);
            if let Ok(h) = ColemanHodgdon::from_separated(form, rls.theta.as_slice()) {
                estimate = h;
            }
            if (t - 1) % self.settings.record_every.max(1) == 0 || t + 1 == x.len() {
                track.push(t, estimate.params());
            }
        }
        Ok(track)
    }
}

fn check_lengths(x: &[f64], y: &[f64]) -> Result<()> {
    if x.len() != y.len() {
        return Err(Error::InvalidData(format!(
            "input has {} samples, output {}",
            x.len(),
            y.len()
        )));
    }
    Ok(())
}

/// `from` moved toward `to` by the fraction `rate` in every physical parameter.
fn follow(from: &ColemanHodgdon, to: &ColemanHodgdon, rate: f64) -> ColemanHodgdon {
    let moved: Vec<f64> = from
        .params()
        .iter()
        .zip(to.params())
        .map(|(a, b)| a + rate * (b - a))
        .collect();
    ColemanHodgdon::from_params(from.form(), &moved).unwrap_or_else(|_| from.clone())
}
