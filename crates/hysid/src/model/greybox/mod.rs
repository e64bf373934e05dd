//! Nonlinear grey-box models: continuous-time state-space models with physical parameters
//! (MATLAB's `idnlgrey`), their simulation and their output-error estimation.
//!
//! A model implements [`StateSpaceModel`]:
//!
//! ```text
//! ẋ(t) = f(t, x(t), u(t), θ)        y(t) = h(x(t), u(t), θ)
//! ```
//!
//! with named states, inputs, outputs and parameters (value, unit, bounds, fixed flag), and
//! optionally the analytic Jacobians ∂f/∂x, ∂f/∂θ, ∂h/∂x, ∂h/∂θ. With them, the estimator
//! integrates the forward sensitivity equations Ṡ = (∂f/∂x)S + ∂f/∂θ alongside the states,
//! which gives the exact derivative of the discretised simulation; without them it uses
//! finite differences, one simulation per free parameter, in parallel.
//!
//! * [`simulate`]: integrators (RK4 with sub-steps, Newmark, adaptive Dormand–Prince) and the
//!   input interpolation between samples.
//! * [`fixed_rk4`]: RK4 with sensitivities on fixed-size arrays, for models that offer it.
//! * [`stick_slip`]: RK4 steps that integrate Coulomb friction as stick–slip.
//! * [`sensitivity`]: the right-hand side of the forward sensitivity equations.
//! * [`native`]: equation-file models compiled to machine code (with the tape interpreter
//!   as fallback and reference).
//! * [`discrete`]: discrete-time models (x\[k+1\] = f(…), [`StateSpaceModel::discrete_time`]),
//!   simulated by their recursion, with its exact sensitivities.
//!
//! Binding a model to data and estimating its parameters is the identify layer's
//! ([`crate::identify::greybox`]).
//! * [`models`]: the built-in models (Bouc–Wen oscillator, rigid body with friction).

pub mod discrete;
mod equation_kernel;
pub mod equation_model;
pub mod fixed_rk4;
pub mod models;
pub mod native;
pub mod sensitivity;
pub mod simulate;
pub mod stick_slip;

pub use simulate::{InputInterpolation, Integrator, Simulation};

use crate::data::Channel;
use crate::model::ParameterSet;
pub use sensitivity::JacobianScratch;

/// A continuous-time state-space model with physical parameters.
pub trait StateSpaceModel: Sync + Send {
    /// The kind written in model files (`bouc_wen`, `rigid_body`, …).
    fn kind(&self) -> &'static str;

    /// The states, with units.
    fn states(&self) -> Vec<Channel>;

    /// The inputs, with units.
    fn inputs(&self) -> Vec<Channel>;

    /// The outputs, with units.
    fn outputs(&self) -> Vec<Channel>;

    /// The parameters with default values, units, bounds and fixed flags.
    fn parameters(&self) -> ParameterSet;

    /// ẋ = f(t, x, u, θ), written into `dx`.
    fn rhs(&self, t: f64, x: &[f64], u: &[f64], theta: &[f64], dx: &mut [f64]);

    /// y = h(x, u, θ), written into `y`.
    fn output(&self, x: &[f64], u: &[f64], theta: &[f64], y: &mut [f64]);

    /// ∂f/∂x (n × n) and ∂f/∂θ (n × p), row-major, written into `fx` and `ftheta`; returns
    /// false when the model does not provide them (the default).
    fn rhs_jacobians(
        &self,
        _t: f64,
        _x: &[f64],
        _u: &[f64],
        _theta: &[f64],
        _fx: &mut [f64],
        _ftheta: &mut [f64],
    ) -> bool {
        false
    }

    /// ∂h/∂x (n_y × n) and ∂h/∂θ (n_y × p), row-major; false when not provided.
    fn output_jacobians(
        &self,
        _x: &[f64],
        _u: &[f64],
        _theta: &[f64],
        _hx: &mut [f64],
        _htheta: &mut [f64],
    ) -> bool {
        false
    }

    /// Whether ∂h/∂x and ∂h/∂θ ([`output_jacobians`](Self::output_jacobians)) are the same
    /// at every state and input, for a given θ (an output that is a state, say): a fit's
    /// sensitivity pass then asks for them once instead of at every sample. False (the
    /// default) unless the model says so.
    fn output_jacobians_are_constant(&self) -> bool {
        false
    }

    /// Whether y = h(x, u, θ) reads the input u: when it does not, a fit's sensitivity pass
    /// does not interpolate the input at the samples for the output. True (the default)
    /// unless the model says otherwise.
    fn output_reads_input(&self) -> bool {
        true
    }

    /// True for a discrete-time model: [`rhs`](Self::rhs) then gives the next state
    /// x\[k+1\] = f(t_k, x\[k\], u\[k\], θ) instead of ẋ, its Jacobians are those of this
    /// map, and simulation runs the recursion whatever the integrator ([`discrete`]).
    /// False (the default): continuous time.
    fn discrete_time(&self) -> bool {
        false
    }

    /// For second-order mechanical models, the number of degrees of freedom n: the first n
    /// states are positions, the next n their velocities (ẋᵢ = x_{n+i}). Newmark
    /// integration needs this layout.
    fn mechanical_dofs(&self) -> Option<usize> {
        None
    }

    /// For models with Coulomb friction: the index of the velocity state whose sign the
    /// friction follows. RK4 then integrates stick–slip ([`stick_slip`]): a step that starts
    /// sliding holds the friction direction ([`rhs_sliding`](Self::rhs_sliding)) and is cut
    /// where the velocity reaches zero; at exactly zero velocity [`rhs`](Self::rhs) decides
    /// between sticking and breaking away, so `rhs` must implement friction at rest as the
    /// force that holds the body, clamp(applied, −Fc, Fc) ([`models::coulomb_direction`]).
    /// None (the default) for smooth models.
    fn stick_slip_velocity(&self) -> Option<usize> {
        None
    }

    /// [`rhs`](Self::rhs) with the Coulomb friction held in `direction` (±1) whatever the sign
    /// of the velocity, so that no stage of a sliding step sees the friction flip. Models that
    /// name a [`stick_slip_velocity`](Self::stick_slip_velocity) must implement it; the
    /// default is `rhs`.
    fn rhs_sliding(
        &self,
        t: f64,
        x: &[f64],
        u: &[f64],
        theta: &[f64],
        _direction: f64,
        dx: &mut [f64],
    ) {
        self.rhs(t, x, u, theta, dx);
    }

    /// [`rhs_jacobians`](Self::rhs_jacobians) with the Coulomb friction held in `direction`
    /// (see [`rhs_sliding`](Self::rhs_sliding)); the default is `rhs_jacobians`.
    #[allow(clippy::too_many_arguments)]
    fn rhs_jacobians_sliding(
        &self,
        t: f64,
        x: &[f64],
        u: &[f64],
        theta: &[f64],
        _direction: f64,
        fx: &mut [f64],
        ftheta: &mut [f64],
    ) -> bool {
        self.rhs_jacobians(t, x, u, theta, fx, ftheta)
    }

    /// ẋ and the forward-sensitivity rates Ṡ = (∂f/∂x)·S + ∂f/∂θ[:, params] for S (n × q,
    /// row-major: first the columns of θ\[params\], then initial-state columns, which have no
    /// direct term), friction held in `held` when Some ([`sensitivity`]). Returns false when
    /// the model has no analytic Jacobians. The default evaluates [`rhs`](Self::rhs) and
    /// [`rhs_jacobians`](Self::rhs_jacobians) into `scratch`
    /// ([`sensitivity::default_rhs_sensitivities`]); a model may override it to fuse the two
    /// and skip known zeros, with the same values.
    #[allow(clippy::too_many_arguments)]
    fn rhs_sensitivities(
        &self,
        t: f64,
        x: &[f64],
        u: &[f64],
        theta: &[f64],
        held: Option<f64>,
        params: &[usize],
        s: &[f64],
        scratch: &mut JacobianScratch,
        dx: &mut [f64],
        ds: &mut [f64],
    ) -> bool {
        sensitivity::default_rhs_sensitivities(
            self, t, x, u, theta, held, params, s, scratch, dx, ds,
        )
    }

    /// How this model's simulations were evaluated, one line for a report: an equation
    /// model says whether its native code ran (compiled now, or loaded from the cache) or
    /// the tape interpreter, and why ([`native`]). None (the default) for a model whose
    /// code is part of hysid.
    fn evaluation(&self) -> Option<String> {
        None
    }

    /// RK4 with forward sensitivities through a path specialised to this model's sizes
    /// ([`fixed_rk4`]: fixed-size arrays, the parameters' constants computed once), giving
    /// the same numbers to the last bit as the generic path built on
    /// [`rhs_sensitivities`](Self::rhs_sensitivities). Called only for RK4 whose input lies
    /// on the half-step grid, also without columns (q = 0) for a plain simulation
    /// ([`simulate::simulate`]). None (the default) when the model has no such path for these
    /// columns: the generic path runs.
    fn fixed_rk4_sensitivities(
        &self,
        _run: &fixed_rk4::Rk4Sensitivities<'_>,
        _on_sample: &mut fixed_rk4::SampleSink<'_>,
    ) -> Option<crate::Result<()>> {
        None
    }
}
