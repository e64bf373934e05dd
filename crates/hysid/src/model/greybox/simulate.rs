//! Simulation of continuous-time state-space models from sampled inputs.
//!
//! # Alignment
//!
//! Samples are at t_k = k·ts, k = 0…N−1. The simulated output y(k) is h(x(t_k), u(t_k)), and
//! x(t_0) is the initial state: the first output sample is the output of the initial state,
//! the way MATLAB's `sim` aligns a continuous-time model with its data.
//!
//! # Input between samples
//!
//! * [`InputInterpolation::ZeroOrderHold`] (default): u(t) = u_k on [t_k, t_{k+1}) — right
//!   when the input came out of a digital controller.
//! * [`InputInterpolation::Linear`]: straight lines between samples.
//! * [`InputInterpolation::BandLimited`]: the input's Fourier series up to the Nyquist
//!   frequency (zero-padding of its DFT), right for band-limited *periodic* excitations such
//!   as multisines; for a non-periodic record the ends ring. docs/benchmarks.md §1.3 shows
//!   what the choice costs on the Bouc–Wen benchmark.
//!
//! # Integrators
//!
//! * [`Integrator::Rk4`]: classical fourth-order Runge–Kutta with an integer number of
//!   sub-steps per sample (default 10). Friction (sgn) and hysteresis (|ẋ|) make right-hand
//!   sides non-smooth, so a fixed step that never straddles a sample boundary is the robust
//!   default. With analytic Jacobians the forward sensitivities are integrated by the same
//!   stages, which gives the exact derivative of the discrete simulation.
//! * [`Integrator::Newmark`]: the average-acceleration Newmark scheme (γ = ½, β = ¼) for
//!   second-order mechanical models, extra first-order states by the trapezoidal rule
//!   (c = ½), a predictor with zero acceleration and rates, and a Newton corrector — the
//!   integrator the Bouc–Wen benchmark prescribes (Noël & Schoukens 2016).
//! * [`Integrator::Adaptive`]: Dormand–Prince 5(4) with error control, restarted at every
//!   sample (the input may jump there); the reference the tests compare the others with.

use super::fixed_rk4::Rk4Sensitivities;
use super::stick_slip::{Sensitivities, StickSlip};
use super::{JacobianScratch, StateSpaceModel};
use crate::numerics::integrate::Stage;
use crate::{Error, Result};
use std::ops::ControlFlow;

/// The integration method.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Integrator {
    /// Fixed-step RK4 with `substeps` steps per sample interval.
    Rk4 {
        /// Steps per sample interval (≥ 1).
        substeps: usize,
    },
    /// Newmark average acceleration with `substeps` steps per sample interval.
    Newmark {
        /// Steps per sample interval (≥ 1).
        substeps: usize,
    },
    /// Dormand–Prince 5(4) with relative and absolute tolerances.
    Adaptive {
        /// Relative tolerance.
        rtol: f64,
        /// Absolute tolerance.
        atol: f64,
    },
}

/// How the input is interpolated between samples (see the module docs).
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "snake_case")]
pub enum InputInterpolation {
    /// Held constant over each sample interval.
    ZeroOrderHold,
    /// Linear between samples.
    Linear,
    /// Band-limited (periodic Fourier series).
    BandLimited,
}

/// Integrator and input interpolation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Simulation {
    /// The integrator.
    pub integrator: Integrator,
    /// The input interpolation.
    pub interpolation: InputInterpolation,
}

impl Default for Simulation {
    /// RK4 with 10 sub-steps, zero-order hold.
    fn default() -> Self {
        Self {
            integrator: Integrator::Rk4 { substeps: 10 },
            interpolation: InputInterpolation::ZeroOrderHold,
        }
    }
}

impl Simulation {
    /// The settings of the same model sampled every `to` seconds instead of the `from` it was
    /// fitted at: a fixed-step integrator (RK4, Newmark) takes n′ = ⌈n·to/from⌉ sub-steps of
    /// h′ = to/n′ ≤ h = from/n, the smallest number whose steps are no longer than the
    /// fitted model's, so its local error (O(h⁵) per step for RK4, O(h³) for Newmark) is no
    /// larger per step; the adaptive integrator keeps its tolerances. The interpolation is
    /// unchanged.
    pub fn resampled(&self, from: f64, to: f64) -> Self {
        let more = |n: usize| {
            let n = n.max(1) as f64;
            // The 1e-9 margin keeps an integer ratio (to = 2·from) from rounding up by one.
            ((n * to / from) * (1.0 - 1e-9)).ceil().max(1.0) as usize
        };
        let integrator = match self.integrator {
            Integrator::Rk4 { substeps } => Integrator::Rk4 {
                substeps: more(substeps),
            },
            Integrator::Newmark { substeps } => Integrator::Newmark {
                substeps: more(substeps),
            },
            adaptive @ Integrator::Adaptive { .. } => adaptive,
        };
        Self {
            integrator,
            interpolation: self.interpolation,
        }
    }

    /// Points per sample interval at which the integrator evaluates the input (RK4 needs the
    /// half steps).
    fn input_resolution(&self) -> usize {
        match self.integrator {
            Integrator::Rk4 { substeps } => 2 * substeps.max(1),
            Integrator::Newmark { substeps } => substeps.max(1),
            Integrator::Adaptive { .. } => 16,
        }
    }
}

/// The inputs of one experiment, ready to be read at any time inside the record.
#[derive(Clone, Debug)]
pub struct InputTrack {
    samples: Vec<Vec<f64>>,
    interpolation: InputInterpolation,
    /// Band-limited values at `resolution` points per sample interval, per channel.
    fine: Vec<Vec<f64>>,
    resolution: usize,
}

impl InputTrack {
    /// Prepares the input channels `u` (each a slice of the samples) for `sim`.
    pub fn new(u: &[&[f64]], sim: &Simulation) -> Result<Self> {
        let resolution = sim.input_resolution();
        let fine = if sim.interpolation == InputInterpolation::BandLimited {
            u.iter()
                .map(|c| band_limited_upsample(c, resolution))
                .collect()
        } else {
            Vec::new()
        };
        Ok(Self {
            samples: u.iter().map(|c| c.to_vec()).collect(),
            interpolation: sim.interpolation,
            fine,
            resolution,
        })
    }

    /// Overwrites sample `k` of every channel with `values` (a streaming step's two-sample
    /// track; not for a band-limited track, whose table is computed once).
    pub(crate) fn set_sample(&mut self, k: usize, values: &[f64]) {
        for (channel, &v) in self.samples.iter_mut().zip(values) {
            channel[k] = v;
        }
    }

    /// Number of input channels.
    pub fn n_channels(&self) -> usize {
        self.samples.len()
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.samples.first().map_or(0, |s| s.len())
    }

    /// True when the track holds no samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Points per sample interval of the input grid ([`at_node`](Self::at_node)).
    pub fn resolution(&self) -> usize {
        self.resolution
    }

    /// u at node `index` ∈ [0, resolution] of the grid of [`resolution`](Self::resolution)
    /// points per sample interval k, i.e. u(t_k + index/resolution·ts): read from the table
    /// prepared once in [`new`](Self::new) (band-limited) or the samples, never searched for.
    /// RK4 with m sub-steps evaluates the input only at these nodes when the resolution
    /// is 2m.
    #[inline]
    pub fn at_node(&self, k: usize, index: usize, out: &mut [f64]) {
        for (c, o) in out.iter_mut().enumerate() {
            let s = &self.samples[c];
            *o = match self.interpolation {
                InputInterpolation::ZeroOrderHold => s[k],
                InputInterpolation::Linear => {
                    let tau = index as f64 / self.resolution as f64;
                    let next = s.get(k + 1).copied().unwrap_or(s[k]);
                    s[k] + tau * (next - s[k])
                }
                InputInterpolation::BandLimited => {
                    let f = &self.fine[c];
                    f[(k * self.resolution + index).min(f.len() - 1)]
                }
            };
        }
    }

    /// The input at every node 0, 1, …, [`resolution`](Self::resolution) of sample interval
    /// k, node-major (`out[node · channels + c]`), each the value [`at_node`](Self::at_node)
    /// gives: one call per sample for an integrator that reads several nodes.
    ///
    /// # Panics
    /// If `out` is shorter than (resolution + 1) · channels.
    #[inline]
    pub fn nodes(&self, k: usize, out: &mut [f64]) {
        let (channels, res) = (self.n_channels(), self.resolution);
        let out = &mut out[..(res + 1) * channels];
        // One band-limited channel away from the record's end: the nodes are one run of the
        // fine table (the values of the general loop below, copied at once).
        if let (InputInterpolation::BandLimited, [f]) = (self.interpolation, &self.fine[..]) {
            if let Some(run) = f.get(k * res..k * res + res + 1) {
                out.copy_from_slice(run);
                return;
            }
        }
        for (c, s) in self.samples.iter().enumerate() {
            let column = out.iter_mut().skip(c).step_by(channels);
            match self.interpolation {
                InputInterpolation::ZeroOrderHold => column.for_each(|o| *o = s[k]),
                InputInterpolation::Linear => {
                    let next = s.get(k + 1).copied().unwrap_or(s[k]);
                    for (index, o) in column.enumerate() {
                        let tau = index as f64 / res as f64;
                        *o = s[k] + tau * (next - s[k]);
                    }
                }
                InputInterpolation::BandLimited => {
                    let f = &self.fine[c];
                    for (index, o) in column.enumerate() {
                        *o = f[(k * res + index).min(f.len() - 1)];
                    }
                }
            }
        }
    }

    /// u(t_k + τ·ts) for τ ∈ [0, 1], written into `out`. With zero-order hold τ = 1 still
    /// gives u_k: the value held over the interval that ends there.
    #[inline]
    pub fn at(&self, k: usize, tau: f64, out: &mut [f64]) {
        for (c, o) in out.iter_mut().enumerate() {
            let s = &self.samples[c];
            *o = match self.interpolation {
                InputInterpolation::ZeroOrderHold => s[k],
                InputInterpolation::Linear => {
                    let next = s.get(k + 1).copied().unwrap_or(s[k]);
                    s[k] + tau * (next - s[k])
                }
                InputInterpolation::BandLimited => {
                    let pos = (k as f64 + tau) * self.resolution as f64;
                    let f = &self.fine[c];
                    let i = (pos.floor() as usize).min(f.len() - 1);
                    let frac = pos - i as f64;
                    let next = f.get(i + 1).copied().unwrap_or(f[i]);
                    f[i] + frac * (next - f[i])
                }
            };
        }
    }
}

/// The band-limited interpolation of a periodic record at `factor` points per sample:
/// zero-padding of its DFT, the Nyquist bin split between the positive and negative halves
/// (in the `hysid-spectral` crate, where the FFT planner is compiled once).
pub use hysid_spectral::band_limited_upsample;

/// Simulates `model` over the samples of `input` with sample time `ts` from the initial
/// state `x0`, calling `on_sample(k, x(t_k))` at every sample. Errors with
/// [`Error::Diverged`] at the first sample where the state is not finite. A discrete-time
/// model runs its recursion instead, `integrator` unused ([`super::discrete`]).
pub fn simulate(
    model: &dyn StateSpaceModel,
    theta: &[f64],
    x0: &[f64],
    input: &InputTrack,
    ts: f64,
    integrator: Integrator,
    mut on_sample: impl FnMut(usize, &[f64]),
) -> Result<()> {
    if model.discrete_time() {
        return super::discrete::simulate(model, theta, x0, input, ts, on_sample);
    }
    if let Integrator::Rk4 { substeps } = integrator {
        let m = substeps.max(1);
        if input.resolution() == 2 * m {
            // The model's fixed-size path without sensitivity columns, if it has one.
            let run = Rk4Sensitivities {
                theta,
                x0,
                s0: &[],
                input,
                ts,
                substeps: m,
                params: &[],
                initial: &[],
            };
            let mut states_only = |k: usize, x: &[f64], _: &[f64]| {
                on_sample(k, x);
                ControlFlow::Continue(())
            };
            if let Some(done) = model.fixed_rk4_sensitivities(&run, &mut states_only) {
                return done;
            }
        }
    }
    let n = input.len();
    let mut x = x0.to_vec();
    let mut stepper = Stepper::new(model, theta, input, ts, integrator)?;
    for k in 0..n {
        if x.iter().any(|v| !v.is_finite()) {
            return Err(diverged(k));
        }
        on_sample(k, &x);
        if k + 1 < n {
            stepper.advance(k, &mut x)?;
        }
    }
    Ok(())
}

/// ẋ at sample interval k of the track (interval `sample` of the record, which sets the
/// time), fraction τ, into `out`.
#[allow(clippy::too_many_arguments)]
#[inline]
fn rate(
    model: &dyn StateSpaceModel,
    theta: &[f64],
    input: &InputTrack,
    ts: f64,
    u: &mut [f64],
    (k, sample): (usize, usize),
    tau: f64,
    x: &[f64],
    out: &mut [f64],
) {
    input.at(k, tau, u);
    model.rhs((sample as f64 + tau) * ts, x, u, theta, out);
}

/// Advances `x` over sample interval `sample` of a record (t_sample → t_sample+1) exactly as
/// [`simulate`] does, the input read from `track`, a two-sample track [u_sample,
/// u_sample+1]: the step of a streaming simulation (`crate::model::stream`), which keeps the
/// integrator's buffers in `work` ([`Workspace::new`] of the model's sizes) from sample to
/// sample. A discrete-time model takes its recursion's step (`next` is its scratch space, of
/// the state's length).
#[allow(clippy::too_many_arguments)]
pub(crate) fn advance_interval(
    model: &dyn StateSpaceModel,
    theta: &[f64],
    track: &InputTrack,
    ts: f64,
    integrator: Integrator,
    sample: usize,
    x: &mut [f64],
    work: &mut Workspace,
    next: &mut [f64],
) -> Result<()> {
    if model.discrete_time() {
        track.at(0, 0.0, &mut work.u);
        model.rhs(sample as f64 * ts, x, &work.u, theta, next);
        x.copy_from_slice(next);
        return Ok(());
    }
    // The caller's buffers for this interval, handed back after it (an empty workspace
    // stands in meanwhile: no allocation).
    let buffers = std::mem::replace(work, Workspace::new(0, 0));
    let mut stepper = Stepper::with_workspace(model, theta, track, ts, integrator, buffers)
        .inspect_err(|_| *work = Workspace::new(x.len(), track.n_channels()))?;
    stepper.first = sample;
    let result = stepper.advance(0, x);
    *work = stepper.work;
    result
}

/// Refuses an integrator the model cannot be simulated with, as [`simulate`] does (Coulomb
/// friction needs RK4; Newmark a second-order mechanical model).
pub(crate) fn check_integrator(
    model: &dyn StateSpaceModel,
    track: &InputTrack,
    integrator: Integrator,
) -> Result<()> {
    if model.discrete_time() {
        return Ok(());
    }
    Stepper::new(model, &[], track, 1.0, integrator).map(|_| ())
}

/// The input at a stage of RK4 sub-step j of m in sample interval k: from the input grid when
/// the stage lies on it, else interpolated at τ.
#[inline]
fn stage_input(
    input: &InputTrack,
    m: usize,
    k: usize,
    j: usize,
    stage: Stage,
    tau: f64,
    u: &mut [f64],
) {
    match stage.node {
        Some(node) if input.resolution() == 2 * m => input.at_node(k, 2 * j + node as usize, u),
        _ => input.at(k, tau, u),
    }
}

pub(super) fn diverged(k: usize) -> Error {
    Error::Diverged {
        index: k,
        reason: "the state is not finite".into(),
    }
}

/// One integrator's working buffers.
struct Stepper<'a> {
    model: &'a dyn StateSpaceModel,
    theta: &'a [f64],
    input: &'a InputTrack,
    ts: f64,
    integrator: Integrator,
    /// The record's sample at the track's position 0 (the time origin of a streaming step).
    first: usize,
    work: Workspace,
}

/// The working buffers of an integration: the input at a stage, RK4's with its stick–slip
/// trial step, and the seven stage rates of Dormand–Prince (Newmark uses the first three).
/// A streaming step keeps them from sample to sample ([`advance_interval`]).
pub(crate) struct Workspace {
    u: Vec<f64>,
    rk4: StickSlip,
    k: [Vec<f64>; 7],
}

impl Workspace {
    /// Buffers for `n` states and `n_inputs` inputs.
    pub(crate) fn new(n: usize, n_inputs: usize) -> Self {
        Self {
            u: vec![0.0; n_inputs],
            rk4: StickSlip::new(n),
            k: std::array::from_fn(|_| vec![0.0; n]),
        }
    }
}

impl<'a> Stepper<'a> {
    fn new(
        model: &'a dyn StateSpaceModel,
        theta: &'a [f64],
        input: &'a InputTrack,
        ts: f64,
        integrator: Integrator,
    ) -> Result<Self> {
        let work = Workspace::new(model.states().len(), input.n_channels());
        Self::with_workspace(model, theta, input, ts, integrator, work)
    }

    /// [`Stepper::new`] with the buffers `work` (of the model's sizes).
    fn with_workspace(
        model: &'a dyn StateSpaceModel,
        theta: &'a [f64],
        input: &'a InputTrack,
        ts: f64,
        integrator: Integrator,
        work: Workspace,
    ) -> Result<Self> {
        if model.stick_slip_velocity().is_some() && !matches!(integrator, Integrator::Rk4 { .. }) {
            return Err(Error::Unsupported(format!(
                "{} has Coulomb friction, and only RK4 integrates its stick phases; use the RK4 integrator",
                model.kind()
            )));
        }
        if let Integrator::Newmark { .. } = integrator {
            if model.mechanical_dofs().is_none() {
                return Err(Error::Unsupported(format!(
                    "Newmark integration needs a second-order mechanical model; {} is not one (use RK4)",
                    model.kind()
                )));
            }
        }
        Ok(Self {
            model,
            theta,
            input,
            ts,
            integrator,
            first: 0,
            work,
        })
    }

    /// Advances x from t_k to t_{k+1}.
    fn advance(&mut self, k: usize, x: &mut [f64]) -> Result<()> {
        match self.integrator {
            Integrator::Rk4 { substeps } => {
                let m = substeps.max(1);
                for j in 0..m {
                    self.rk4_step(k, j, m, x);
                }
                Ok(())
            }
            Integrator::Newmark { substeps } => {
                let m = substeps.max(1);
                for j in 0..m {
                    self.newmark_step(k, j as f64 / m as f64, 1.0 / m as f64, x)?;
                }
                Ok(())
            }
            Integrator::Adaptive { rtol, atol } => self.dopri_interval(k, x, rtol, atol),
        }
    }

    /// ẋ at (k, τ) into self.k[slot].
    #[inline]
    fn eval(&mut self, k: usize, tau: f64, x: &[f64], slot: usize) {
        rate(
            self.model,
            self.theta,
            self.input,
            self.ts,
            &mut self.work.u,
            (k, self.first + k),
            tau,
            x,
            &mut self.work.k[slot],
        );
    }

    /// RK4 sub-step j of m of sample interval k (stick–slip aware, see
    /// [`super::stick_slip`]).
    fn rk4_step(&mut self, k: usize, j: usize, m: usize, x: &mut [f64]) {
        let (model, theta, input, ts) = (self.model, self.theta, self.input, self.ts);
        let sample = self.first + k;
        let (tau, dtau) = (j as f64 / m as f64, 1.0 / m as f64);
        let u = &mut self.work.u;
        let mut f = |stage: Stage, x: &[f64], held: Option<f64>, out: &mut [f64]| {
            let tau = tau + stage.dt / ts;
            stage_input(input, m, k, j, stage, tau, u);
            let t = (sample as f64 + tau) * ts;
            match held {
                Some(d) => model.rhs_sliding(t, x, u, theta, d, out),
                None => model.rhs(t, x, u, theta, out),
            }
        };
        let velocity = model.stick_slip_velocity();
        self.work.rk4.step(&mut f, x, dtau * ts, velocity, None);
    }

    /// One Newmark step (see the module docs) of fraction `dtau` from τ.
    fn newmark_step(&mut self, k: usize, tau: f64, dtau: f64, x: &mut [f64]) -> Result<()> {
        const GAMMA: f64 = 0.5;
        const BETA: f64 = 0.25;
        const C: f64 = 0.5;
        let dofs = self.model.mechanical_dofs().expect("checked in new");
        let n = x.len();
        let h = dtau * self.ts;
        // Rates at the start of the step.
        self.eval(k, tau, x, 0);
        let start = x.to_vec();
        let rate0 = self.work.k[0].clone();
        // Unknowns: accelerations (dofs) and first-order rates (n − 2·dofs) at the end.
        let mut unknown = vec![0.0; n - dofs];
        let state_of = |unknown: &[f64], out: &mut [f64]| {
            for i in 0..dofs {
                let (q, v, a0, a1) = (start[i], start[dofs + i], rate0[dofs + i], unknown[i]);
                out[i] = q + h * v + h * h * ((0.5 - BETA) * a0 + BETA * a1);
                out[dofs + i] = v + h * ((1.0 - GAMMA) * a0 + GAMMA * a1);
            }
            for j in 2 * dofs..n {
                let r = unknown[j - dofs];
                out[j] = start[j] + h * ((1.0 - C) * rate0[j] + C * r);
            }
        };
        let mut trial = vec![0.0; n];
        let mut residual = vec![0.0; n - dofs];
        let m = n - dofs;
        for _ in 0..50 {
            state_of(&unknown, &mut trial);
            self.eval(k, tau + dtau, &trial, 1);
            for (r, (i, u)) in residual.iter_mut().zip(unknown.iter().enumerate()) {
                *r = u - self.work.k[1][dofs + i];
            }
            let scale = unknown.iter().map(|v| v.abs()).fold(1.0, f64::max);
            if residual.iter().all(|r| r.abs() <= 1e-13 * scale) {
                break;
            }
            // Newton matrix I − ∂(rates)/∂(unknown), by differences of the right-hand side.
            let mut jac = nalgebra::DMatrix::<f64>::identity(m, m);
            for c in 0..m {
                let step = 1e-7 * unknown[c].abs().max(1e-6 * scale);
                let mut bumped = unknown.clone();
                bumped[c] += step;
                let mut xb = vec![0.0; n];
                state_of(&bumped, &mut xb);
                self.eval(k, tau + dtau, &xb, 2);
                for r in 0..m {
                    jac[(r, c)] -= (self.work.k[2][dofs + r] - self.work.k[1][dofs + r]) / step;
                }
            }
            let delta = jac
                .lu()
                .solve(&nalgebra::DVector::from_column_slice(&residual))
                .ok_or_else(|| Error::Diverged {
                    index: self.first + k,
                    reason: "the Newmark corrector's Newton matrix is singular".into(),
                })?;
            for (u, d) in unknown.iter_mut().zip(delta.iter()) {
                *u -= d;
            }
        }
        state_of(&unknown, x);
        Ok(())
    }

    /// Integrates over one sample interval with Dormand–Prince 5(4) and error control.
    fn dopri_interval(&mut self, k: usize, x: &mut [f64], rtol: f64, atol: f64) -> Result<()> {
        let n = x.len();
        let mut tau = 0.0;
        let mut dtau: f64 = 0.1;
        let mut y5 = vec![0.0; n];
        let mut err = vec![0.0; n];
        let mut guard = 0;
        while tau < 1.0 - 1e-15 {
            guard += 1;
            if guard > 1_000_000 {
                return Err(Error::Diverged {
                    index: self.first + k,
                    reason: "the adaptive integrator's step size collapsed (stiff or discontinuous model)".into(),
                });
            }
            dtau = dtau.min(1.0 - tau);
            self.dopri_stages(k, tau, dtau, x, &mut y5, &mut err);
            let norm = (0..n)
                .map(|i| {
                    let sc = atol + rtol * x[i].abs().max(y5[i].abs());
                    (err[i] / sc).powi(2)
                })
                .sum::<f64>()
                / n as f64;
            let norm = norm.sqrt();
            if norm <= 1.0 || dtau < 1e-12 {
                tau += dtau;
                x.copy_from_slice(&y5);
                if x.iter().any(|v| !v.is_finite()) {
                    return Err(diverged(self.first + k));
                }
            }
            let factor = if norm == 0.0 {
                5.0
            } else {
                (0.9 * norm.powf(-0.2)).clamp(0.2, 5.0)
            };
            dtau *= factor;
        }
        Ok(())
    }

    /// The seven Dormand–Prince stages; the fifth-order solution into `y5`, the difference to
    /// the embedded fourth-order one into `err`.
    fn dopri_stages(
        &mut self,
        k: usize,
        tau: f64,
        dtau: f64,
        x: &[f64],
        y5: &mut [f64],
        err: &mut [f64],
    ) {
        use dormand_prince::{A, B4, B5, C};
        let h = dtau * self.ts;
        let n = x.len();
        for s in 0..7 {
            let mut stage = x.to_vec();
            for (j, a) in A[s].iter().enumerate().take(s) {
                for (st, kj) in stage.iter_mut().zip(&self.work.k[j]) {
                    *st += h * a * kj;
                }
            }
            self.eval(k, tau + C[s] * dtau, &stage, s);
        }
        for i in 0..n {
            let (mut s5, mut s4) = (0.0, 0.0);
            for s in 0..7 {
                s5 += B5[s] * self.work.k[s][i];
                s4 += B4[s] * self.work.k[s][i];
            }
            y5[i] = x[i] + h * s5;
            err[i] = h * (s5 - s4);
        }
    }
}

/// Simulates with RK4 and the forward sensitivities S = ∂x/∂p for the parameters listed in
/// `params` (indices into θ) followed by the initial states listed in `initial` (indices into
/// x). Calls `on_sample(k, x(t_k), S(t_k))` with S row-major n × q; `Break` ends the
/// simulation there (Ok(true): the caller that said so knows the rest is missing). Needs
/// the model's analytic Jacobians; returns Ok(false) without simulating when it has none. A
/// discrete-time model runs its recursion and its chain rule instead, `substeps` unused
/// ([`super::discrete`]).
#[allow(clippy::too_many_arguments)]
pub fn simulate_sensitivities(
    model: &dyn StateSpaceModel,
    theta: &[f64],
    x0: &[f64],
    input: &InputTrack,
    ts: f64,
    substeps: usize,
    params: &[usize],
    initial: &[usize],
    mut on_sample: impl FnMut(usize, &[f64], &[f64]) -> ControlFlow<()>,
) -> Result<bool> {
    if model.discrete_time() {
        return super::discrete::simulate_sensitivities(
            model, theta, x0, input, ts, params, initial, on_sample,
        );
    }
    let n = x0.len();
    let n_samples = input.len();
    let p = theta.len();
    let q = params.len() + initial.len();
    let mut scratch = JacobianScratch::new(n, p);
    let mut u = vec![0.0; input.n_channels()];
    input.at(0, 0.0, &mut u);
    let (mut dx, mut ds) = (vec![0.0; n], vec![0.0; n * q]);
    let s0 = vec![0.0; n * q];
    if !model.rhs_sensitivities(
        0.0,
        x0,
        &u,
        theta,
        None,
        params,
        &s0,
        &mut scratch,
        &mut dx,
        &mut ds,
    ) {
        return Ok(false);
    }
    // Augmented state z = [x, S (row-major n × q)], allocated once.
    let dim = n + n * q;
    let mut z = vec![0.0; dim];
    z[..n].copy_from_slice(x0);
    for (c, &i) in initial.iter().enumerate() {
        z[n + i * q + params.len() + c] = 1.0;
    }
    let m = substeps.max(1);
    if input.resolution() == 2 * m {
        let run = Rk4Sensitivities {
            theta,
            x0,
            s0: &z[n..],
            input,
            ts,
            substeps: m,
            params,
            initial,
        };
        if let Some(done) = model.fixed_rk4_sensitivities(&run, &mut on_sample) {
            return done.map(|()| true);
        }
    }
    let h = ts / m as f64;
    let mut rk4 = StickSlip::new(dim);
    let velocity = model.stick_slip_velocity();
    let layout = Some(Sensitivities { n, q });
    for k in 0..n_samples {
        if z.iter().any(|v| !v.is_finite()) {
            return Err(diverged(k));
        }
        if on_sample(k, &z[..n], &z[n..]).is_break() || k + 1 == n_samples {
            break;
        }
        for j in 0..m {
            let tau = j as f64 / m as f64;
            let mut f = |stage: Stage, zs: &[f64], held: Option<f64>, out: &mut [f64]| {
                let tau = tau + stage.dt / ts;
                stage_input(input, m, k, j, stage, tau, &mut u);
                let t = (k as f64 + tau) * ts;
                let (x, s) = zs.split_at(n);
                let (dx, ds) = out.split_at_mut(n);
                model.rhs_sensitivities(t, x, &u, theta, held, params, s, &mut scratch, dx, ds);
            };
            rk4.step(&mut f, &mut z, h, velocity, layout);
        }
    }
    Ok(true)
}

/// One RK4 step of length `h` from (t, x) with the input held at `u` (stick–slip aware, see
/// [`super::stick_slip`]): the building block of closed-loop simulations, where the input of
/// the next interval depends on the state.
pub fn rk4_step(
    model: &dyn StateSpaceModel,
    theta: &[f64],
    t: f64,
    x: &mut [f64],
    u: &[f64],
    h: f64,
) {
    let mut f = |stage: Stage, x: &[f64], held: Option<f64>, out: &mut [f64]| match held {
        Some(d) => model.rhs_sliding(t + stage.dt, x, u, theta, d, out),
        None => model.rhs(t + stage.dt, x, u, theta, out),
    };
    let velocity = model.stick_slip_velocity();
    StickSlip::new(x.len()).step(&mut f, x, h, velocity, None);
}

/// The Dormand–Prince 5(4) tableau (Dormand & Prince 1980): nodes `C`, matrix `A` (the last
/// row is the 5th-order weights, first same as last), and the weights of the 5th- and
/// 4th-order solutions. Shared with the exported integrator (`crate::export::greybox`).
pub(crate) mod dormand_prince {
    /// The nodes c.
    pub const C: [f64; 7] = [0.0, 0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0];
    /// The matrix A.
    pub const A: [[f64; 6]; 7] = [
        [0.0; 6],
        [0.2, 0.0, 0.0, 0.0, 0.0, 0.0],
        [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
        [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
        [
            19372.0 / 6561.0,
            -25360.0 / 2187.0,
            64448.0 / 6561.0,
            -212.0 / 729.0,
            0.0,
            0.0,
        ],
        [
            9017.0 / 3168.0,
            -355.0 / 33.0,
            46732.0 / 5247.0,
            49.0 / 176.0,
            -5103.0 / 18656.0,
            0.0,
        ],
        [
            35.0 / 384.0,
            0.0,
            500.0 / 1113.0,
            125.0 / 192.0,
            -2187.0 / 6784.0,
            11.0 / 84.0,
        ],
    ];
    /// The 5th-order weights.
    pub const B5: [f64; 7] = [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
        0.0,
    ];
    /// The 4th-order weights (embedded error estimate).
    pub const B4: [f64; 7] = [
        5179.0 / 57600.0,
        0.0,
        7571.0 / 16695.0,
        393.0 / 640.0,
        -92097.0 / 339200.0,
        187.0 / 2100.0,
        1.0 / 40.0,
    ];
}
