//! The common machinery of the differential (Duhem-type) operators: a state x that moves only
//! when the input moves,
//!
//! ```text
//! dx/du = F(u, x, δ),   δ = sign(du),   y = h(u, x),
//! ```
//!
//! so the output depends on the path of u, not on its timing (rate independence, Visintin
//! 1994, ch. 2). Jiles–Atherton, Bouc–Wen, Duhem/Coleman–Hodgdon and Dahl are all of this form.
//!
//! **Integration in the input.** Between two samples u_{k−1} → u_k the direction δ is fixed
//! and the state is integrated in u by the embedded Runge–Kutta 5(4) pair of Dormand & Prince
//! (1980) with error control (relative and absolute tolerance 1e-10 of the state's scale,
//! sub-steps no longer than the family's input scale). The result therefore does not depend on
//! how densely the record is sampled: a ramp given in 2 or in 2 000 samples gives the same
//! state at its end to the tolerance. Each interval starts afresh from its own end points, so
//! the state after a sample is a function of (x_{k−1}, u_{k−1}, u_k) alone — the inverse below
//! and a later simulation make exactly the same computation.
//!
//! **Inversion.** Along each branch the output after one sample, y_k(v) = h(v, x(v)), is
//! monotone in the new input v for the families here; the inverse finds v with y_k(v) = r_k by
//! bracketing (doubling steps from u_{k−1}) and the Illinois variant of regula falsi (Dowell &
//! Jarratt 1971). A reference that no input within the family's inversion span reaches is
//! clipped to the closest output found and listed. The first sample starts from the family's
//! anchor input; after a declared history ([`HistoryRun`]) its branch is the output after
//! the history's path v → u_turn → v, searched on the record's side of the saved turn only.
//!
//! **Parameter sensitivities.** A family that also implements [`InputOdeSensitivity`] gives
//! the partial derivatives ∂F/∂x, ∂F/∂θ, ∂h/∂x, ∂h/∂θ and ∂x₀/∂θ; [`simulate_with_sensitivities`]
//! then carries the tangents S = ∂x/∂θ through the very Runge–Kutta steps that move the state
//! (the derivative of the computed solution, "internal numerical differentiation", Bock 1981):
//! every stage X_i = x + h·Σ a_ij·k_j has the tangent S_i = S + h·Σ a_ij·k'_j with
//! k'_i = ∂F/∂x(X_i)·S_i + ∂F/∂θ(X_i), and the output's is ∂h/∂x·S + ∂h/∂θ. The state path is
//! bit for bit that of [`simulate`], the sensitivities are exact derivatives of it (the step
//! sizes held), and the cost is one simulation with p more scalars per stage instead of the
//! p further simulations of finite differences.
//!
//! References: J. R. Dormand, P. J. Prince, "A family of embedded Runge–Kutta formulae",
//! J. Comput. Appl. Math. 6 (1980) 19–26. A. Visintin, *Differential Models of Hysteresis*,
//! Springer 1994. M. Dowell, P. Jarratt, "A modified regula falsi method for computing the
//! root of an equation", BIT 11 (1971) 168–174. H. G. Bock, "Numerical treatment of inverse
//! problems in chemical reaction kinetics", in *Modelling of Chemical Reaction Systems*,
//! Springer 1981, 102–125.

use super::initial_state::History;
use super::streaming::CompensatorStep;
use super::Inversion;
use crate::{Error, Result};
use serde::{Deserialize, Serialize};

/// Relative (and, times the state scale, absolute) error tolerance of a sub-step: the
/// operator's own simulation. A coarser one ([`states_with_tolerance`]) serves where only an
/// approximate output is needed, e.g. the global stage of a fit.
pub const TOLERANCE: f64 = 1e-10;
/// Sub-steps allowed in one sample interval before the integration is declared divergent.
const MAX_SUBSTEPS: usize = 100_000;

/// The orientation (turning sense) of a hysteresis loop in the (u, y) plane, u horizontal.
///
/// Counter-clockwise (`ccw`): the ascending branch lies below the descending one (the output
/// lags the input, as a piezo stack or a magnet's B(H) loop). Clockwise (`cw`): the ascending
/// branch lies above (the output leads, as the friction force of an elasto-plastic contact).
/// It is the sign of the area between the branches, ∫ (y_desc − y_asc) du > 0 for
/// counter-clockwise (Mayergoyz, *Mathematical Models of Hysteresis*, 2003; MODELS.md §4.8),
/// detected by [`LoopOrientation::detect`].
///
/// How it maps onto the linear-in-weights families' stored [`super::Orientation`]
/// `{decreasing, inverse}` (whose core G is counter-clockwise): `ccw` is
/// `inverse == decreasing` (Γ = G, or Γ = −G⁻¹ for a decreasing trend), `cw` is
/// `inverse != decreasing` (Γ = G⁻¹, or Γ = −G); for Maxwell-slip, whose stop elements are
/// clockwise, the other way round ([`super::Orientation::loop_orientation`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LoopOrientation {
    /// Ascending branch below the descending one.
    CounterClockwise,
    /// Ascending branch above the descending one.
    Clockwise,
}

impl LoopOrientation {
    /// The orientation of a measured loop from the area between its ascending and descending
    /// branches, per reversal ([`super::orientation`]): right for open records, several runs,
    /// offsets, a decreasing trend and narrow loops on a wide range; an
    /// [`Error::UndeterminedOrientation`] when the record cannot tell (no reversal, a loop
    /// indistinguishable from noise).
    pub fn detect(u: &[f64], y: &[f64]) -> Result<Self> {
        super::orientation::loop_evidence(u, y).map(|e| e.orientation)
    }

    /// [`LoopOrientation::detect`], or where the record cannot tell, the sign of the path
    /// integral ∮ y du = Σ ½(y_k + y_{k−1})(u_k − u_{k−1}) (negative for a closed
    /// counter-clockwise path, Green's theorem): what the differential families' fits use,
    /// which judge a record's excitation themselves.
    pub fn of_loop(u: &[f64], y: &[f64]) -> Self {
        Self::detect(u, y).unwrap_or_else(|_| {
            let area: f64 = u
                .windows(2)
                .zip(y.windows(2))
                .map(|(du, dy)| 0.5 * (dy[0] + dy[1]) * (du[1] - du[0]))
                .sum();
            if area > 0.0 {
                LoopOrientation::Clockwise
            } else {
                LoopOrientation::CounterClockwise
            }
        })
    }

    /// The short name: `ccw` or `cw` (the command line's and the reports' spelling).
    pub fn short_name(self) -> &'static str {
        match self {
            LoopOrientation::CounterClockwise => "ccw",
            LoopOrientation::Clockwise => "cw",
        }
    }

    /// Parses `ccw` / `cw` (also `counter-clockwise`, `counter_clockwise`, `clockwise`).
    pub fn parse(text: &str) -> Result<Self> {
        match text.trim().to_ascii_lowercase().as_str() {
            "ccw" | "counter-clockwise" | "counter_clockwise" | "counterclockwise" => {
                Ok(LoopOrientation::CounterClockwise)
            }
            "cw" | "clockwise" => Ok(LoopOrientation::Clockwise),
            _ => Err(Error::invalid_option(
                "orientation",
                text,
                format!("orientation '{text}' is neither ccw nor cw"),
            )),
        }
    }

    /// The other orientation.
    pub fn reversed(self) -> Self {
        match self {
            LoopOrientation::CounterClockwise => LoopOrientation::Clockwise,
            LoopOrientation::Clockwise => LoopOrientation::CounterClockwise,
        }
    }

    /// +1 for counter-clockwise, −1 for clockwise.
    pub fn sign(self) -> f64 {
        match self {
            LoopOrientation::CounterClockwise => 1.0,
            LoopOrientation::Clockwise => -1.0,
        }
    }
}

/// A rate-independent operator dx/du = F(u, x, δ), y = h(u, x) (see the module doc).
pub trait InputOde: Sync {
    /// dx/du at input u and state x on a branch where the input moves in direction δ = ±1.
    /// A non-finite value marks a state where the model is not defined.
    fn slope(&self, u: f64, x: f64, direction: f64) -> f64;
    /// The output y = h(u, x).
    fn output(&self, u: f64, x: f64) -> f64;
    /// The state x₀ at the first input sample.
    fn initial_state(&self) -> f64;
    /// Typical size of the state: the absolute tolerance of the integration is 1e-10 of it.
    fn state_scale(&self) -> f64;
    /// The longest sub-step in u: an input scale over which the slope changes appreciably.
    fn max_substep(&self) -> f64;
    /// How far from the previous input the inverse searches before it clips.
    fn inversion_span(&self) -> f64;
    /// Where the inverse starts its first sample (the output at the first sample may not
    /// depend on the input at all, e.g. when y = x).
    fn anchor_input(&self) -> f64 {
        0.0
    }
}

/// The most parameters an [`InputOdeSensitivity`] may have (the tangents live in fixed arrays).
pub const MAX_SENSITIVITIES: usize = 8;

/// An [`InputOde`] with the partial derivatives of its equations with respect to the state x
/// and its parameters θ (in the order of the operator's `parameters()`), for
/// [`simulate_with_sensitivities`].
pub trait InputOdeSensitivity: InputOde {
    /// The number p of parameters θ (at most [`MAX_SENSITIVITIES`]).
    fn n_parameters(&self) -> usize;
    /// F = dx/du (the same value as [`InputOde::slope`]) and ∂F/∂x; writes ∂F/∂θ_j into
    /// `dtheta[j]`.
    fn slope_partials(&self, u: f64, x: f64, direction: f64, dtheta: &mut [f64]) -> (f64, f64);
    /// ∂h/∂x; writes ∂h/∂θ_j into `dtheta[j]`.
    fn output_partials(&self, u: f64, x: f64, dtheta: &mut [f64]) -> f64;
    /// Writes ∂x₀/∂θ_j into `dtheta[j]`.
    fn initial_state_partials(&self, dtheta: &mut [f64]);
}

/// Checks a signal: not empty, every sample finite.
pub fn check_signal(name: &str, v: &[f64]) -> Result<()> {
    if v.is_empty() {
        return Err(Error::InvalidData(format!(
            "the {name} signal is empty; give at least one sample"
        )));
    }
    match v.iter().position(|x| !x.is_finite()) {
        Some(index) => Err(Error::NonFinite {
            channel: name.into(),
            index,
            value: v[index],
        }),
        None => Ok(()),
    }
}

/// The state after the input moves from `u0` to `u1`, starting from state `x`
/// (Dormand–Prince 5(4) with error control; see the module doc).
pub fn advance<O: InputOde + ?Sized>(ode: &O, x: f64, u0: f64, u1: f64) -> Result<f64> {
    let mut budget = MAX_SUBSTEPS;
    advance_within(ode, x, u0, u1, TOLERANCE, &mut budget, &mut Plain)
}

/// How a sub-step is taken: the state alone ([`Plain`]) or with its tangents ([`Tangents`]).
trait StepRule<O: ?Sized> {
    /// One Dormand–Prince step of signed length `h` from (u, x): the 5th-order state and the
    /// magnitude of the error estimate.
    fn step(&mut self, ode: &O, u: f64, x: f64, h: f64, d: f64) -> (f64, f64);
    /// The step just taken is accepted.
    fn accept(&mut self);
}

/// The state alone.
struct Plain;

impl<O: InputOde + ?Sized> StepRule<O> for Plain {
    #[inline(always)]
    fn step(&mut self, ode: &O, u: f64, x: f64, h: f64, d: f64) -> (f64, f64) {
        dormand_prince(ode, u, x, h, d)
    }
    #[inline(always)]
    fn accept(&mut self) {}
}

/// [`advance`] with a budget of sub-steps, decreased by the sub-steps taken.
fn advance_within<O: InputOde + ?Sized, R: StepRule<O>>(
    ode: &O,
    x: f64,
    u0: f64,
    u1: f64,
    tolerance: f64,
    budget: &mut usize,
    rule: &mut R,
) -> Result<f64> {
    let span = u1 - u0;
    if span == 0.0 {
        return Ok(x);
    }
    let direction = span.signum();
    let h_max = ode.max_substep().abs().max(f64::MIN_POSITIVE);
    let atol = tolerance * ode.state_scale().abs().max(f64::MIN_POSITIVE);
    let (mut u, mut x) = (u0, x);
    let mut h = span.abs().min(h_max);
    while *budget > 0 {
        *budget -= 1;
        let remaining = (u1 - u).abs();
        if remaining <= 0.0 {
            return Ok(x);
        }
        let last = h >= remaining;
        let step = if last { remaining } else { h };
        let (x_new, err) = rule.step(ode, u, x, step * direction, direction);
        if !x_new.is_finite() || !err.is_finite() {
            if step <= 1e-14 * (u.abs() + h_max) {
                return Err(diverged(u, "the slope dx/du is not finite"));
            }
            h = step * 0.25;
            continue;
        }
        let tol = atol + tolerance * x.abs().max(x_new.abs());
        if err <= tol {
            u = if last { u1 } else { u + step * direction };
            x = x_new;
            rule.accept();
        }
        // 0.9·(tol/err)^{1/5} ≥ 5 whenever tol/err ≥ 5292: the power is only taken below
        // (6000 leaves a margin for its rounding; the factor is the same).
        let factor = if err * 6000.0 <= tol {
            5.0
        } else {
            (0.9 * (tol / err).powf(0.2)).clamp(0.2, 5.0)
        };
        h = (step * factor).min(h_max);
        if h <= 1e-15 * (u.abs() + h_max) {
            return Err(diverged(
                u,
                "the step size underflows (the slope is too steep)",
            ));
        }
    }
    Err(diverged(
        u,
        "too many sub-steps: the operator is too stiff for this input (sample the input \
         more finely or bound the parameters)",
    ))
}

fn diverged(u: f64, what: &str) -> Error {
    Error::Diverged {
        index: 0,
        reason: format!("integration in the input at u = {u}: {what}"),
    }
}

/// One Dormand–Prince 5(4) step of signed length `h`: the 5th-order state and the magnitude of
/// the embedded error estimate.
#[inline(always)]
fn dormand_prince<O: InputOde + ?Sized>(ode: &O, u: f64, x: f64, h: f64, d: f64) -> (f64, f64) {
    let f = |du: f64, xx: f64| ode.slope(u + du, xx, d);
    let k1 = f(0.0, x);
    let k2 = f(h / 5.0, x + h * k1 / 5.0);
    let k3 = f(0.3 * h, x + h * (3.0 / 40.0 * k1 + 9.0 / 40.0 * k2));
    let k4 = f(
        0.8 * h,
        x + h * (44.0 / 45.0 * k1 - 56.0 / 15.0 * k2 + 32.0 / 9.0 * k3),
    );
    let k5 = f(
        8.0 / 9.0 * h,
        x + h
            * (19372.0 / 6561.0 * k1 - 25360.0 / 2187.0 * k2 + 64448.0 / 6561.0 * k3
                - 212.0 / 729.0 * k4),
    );
    let k6 = f(
        h,
        x + h
            * (9017.0 / 3168.0 * k1 - 355.0 / 33.0 * k2
                + 46732.0 / 5247.0 * k3
                + 49.0 / 176.0 * k4
                - 5103.0 / 18656.0 * k5),
    );
    let x5 = x + h
        * (35.0 / 384.0 * k1 + 500.0 / 1113.0 * k3 + 125.0 / 192.0 * k4 - 2187.0 / 6784.0 * k5
            + 11.0 / 84.0 * k6);
    let k7 = f(h, x5);
    let err = h
        * (71.0 / 57600.0 * k1 - 71.0 / 16695.0 * k3 + 71.0 / 1920.0 * k4
            - 17253.0 / 339200.0 * k5
            + 22.0 / 525.0 * k6
            - 1.0 / 40.0 * k7);
    (x5, err.abs())
}

/// The states x_k along the input `u`, from the operator's initial state at u\[0\].
pub fn states<O: InputOde + ?Sized>(ode: &O, u: &[f64]) -> Result<Vec<f64>> {
    states_with_tolerance(ode, u, TOLERANCE)
}

/// [`states`] integrated to the relative error tolerance `tolerance` instead of
/// [`TOLERANCE`].
pub fn states_with_tolerance<O: InputOde + ?Sized>(
    ode: &O,
    u: &[f64],
    tolerance: f64,
) -> Result<Vec<f64>> {
    check_signal("input", u)?;
    let mut x = ode.initial_state();
    let mut out = Vec::with_capacity(u.len());
    out.push(x);
    // A record may take many sub-steps per sample, but not without limit: a stiff trial
    // point of a fit must fail quickly rather than take minutes.
    let mut budget = MAX_SUBSTEPS + 100 * u.len();
    for (k, w) in u.windows(2).enumerate() {
        x = advance_within(ode, x, w[0], w[1], tolerance, &mut budget, &mut Plain)
            .map_err(|e| at_sample(e, k + 1))?;
        out.push(x);
    }
    Ok(out)
}

/// The output y_k = h(u_k, x_k) along the input `u`.
pub fn simulate<O: InputOde + ?Sized>(ode: &O, u: &[f64]) -> Result<Vec<f64>> {
    simulate_with_tolerance(ode, u, TOLERANCE)
}

/// [`simulate`] integrated to the relative error tolerance `tolerance` instead of
/// [`TOLERANCE`].
pub fn simulate_with_tolerance<O: InputOde + ?Sized>(
    ode: &O,
    u: &[f64],
    tolerance: f64,
) -> Result<Vec<f64>> {
    let x = states_with_tolerance(ode, u, tolerance)?;
    Ok(u.iter().zip(&x).map(|(&u, &x)| ode.output(u, x)).collect())
}

/// The output ŷ_k and its sensitivities ∂ŷ_k/∂θ (p = [`InputOdeSensitivity::n_parameters`]
/// values) along the input `u`, handed to `each(k, ŷ_k, ∂ŷ_k/∂θ)` sample by sample (see the
/// module doc): nothing of the record's length is stored. `tolerance` is the integration's
/// ([`TOLERANCE`] for the operator's own path).
pub fn simulate_with_sensitivities<O: InputOdeSensitivity + ?Sized>(
    ode: &O,
    u: &[f64],
    tolerance: f64,
    mut each: impl FnMut(usize, f64, &[f64]),
) -> Result<()> {
    check_signal("input", u)?;
    let p = ode.n_parameters();
    if p > MAX_SENSITIVITIES {
        return Err(Error::invalid_option(
            "parameters",
            p,
            format!("at most {MAX_SENSITIVITIES} parameters carry sensitivities"),
        ));
    }
    let mut rule = Tangents {
        p,
        s: [0.0; MAX_SENSITIVITIES],
        pending: [0.0; MAX_SENSITIVITIES],
    };
    ode.initial_state_partials(&mut rule.s[..p]);
    let mut x = ode.initial_state();
    let mut dy = [0.0; MAX_SENSITIVITIES];
    let mut emit =
        |k: usize, x: f64, s: &[f64; MAX_SENSITIVITIES], dy: &mut [f64; MAX_SENSITIVITIES]| {
            let hx = ode.output_partials(u[k], x, &mut dy[..p]);
            for j in 0..p {
                dy[j] += hx * s[j];
            }
            each(k, ode.output(u[k], x), &dy[..p]);
        };
    emit(0, x, &rule.s, &mut dy);
    let mut budget = MAX_SUBSTEPS + 100 * u.len();
    for (k, w) in u.windows(2).enumerate() {
        x = advance_within(ode, x, w[0], w[1], tolerance, &mut budget, &mut rule)
            .map_err(|e| at_sample(e, k + 1))?;
        emit(k + 1, x, &rule.s, &mut dy);
    }
    Ok(())
}

/// The state with its tangents S = ∂x/∂θ (the `p` first entries).
struct Tangents {
    p: usize,
    /// S at the current point.
    s: [f64; MAX_SENSITIVITIES],
    /// S at the end of the step last taken, until it is accepted.
    pending: [f64; MAX_SENSITIVITIES],
}

impl<O: InputOdeSensitivity + ?Sized> StepRule<O> for Tangents {
    fn step(&mut self, ode: &O, u: f64, x: f64, h: f64, d: f64) -> (f64, f64) {
        // The stage states exactly as in `dormand_prince` (the same bits); beside each, its
        // tangent S_i = S + h·Σ a_ij·k'_j and k'_i = F_x(X_i)·S_i + F_θ(X_i).
        let mut k = [0.0; 6];
        let mut dk = [[0.0; MAX_SENSITIVITIES]; 6];
        let mut stage = |i: usize, du: f64, xi: f64, a: &[f64], k: &mut [f64; 6]| {
            let mut si = self.s;
            for (j, &aij) in a.iter().enumerate() {
                for l in 0..self.p {
                    si[l] += h * aij * dk[j][l];
                }
            }
            let (f, fx) = ode.slope_partials(u + du, xi, d, &mut dk[i][..self.p]);
            for l in 0..self.p {
                dk[i][l] += fx * si[l];
            }
            k[i] = f;
        };
        stage(0, 0.0, x, &[], &mut k);
        stage(1, h / 5.0, x + h * k[0] / 5.0, &[0.2], &mut k);
        let a2 = [3.0 / 40.0, 9.0 / 40.0];
        stage(
            2,
            0.3 * h,
            x + h * (a2[0] * k[0] + a2[1] * k[1]),
            &a2,
            &mut k,
        );
        let a3 = [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0];
        let x3 = x + h * (44.0 / 45.0 * k[0] - 56.0 / 15.0 * k[1] + 32.0 / 9.0 * k[2]);
        stage(3, 0.8 * h, x3, &a3, &mut k);
        let a4 = [
            19372.0 / 6561.0,
            -25360.0 / 2187.0,
            64448.0 / 6561.0,
            -212.0 / 729.0,
        ];
        let x4 = x + h
            * (19372.0 / 6561.0 * k[0] - 25360.0 / 2187.0 * k[1] + 64448.0 / 6561.0 * k[2]
                - 212.0 / 729.0 * k[3]);
        stage(4, 8.0 / 9.0 * h, x4, &a4, &mut k);
        let a5 = [
            9017.0 / 3168.0,
            -355.0 / 33.0,
            46732.0 / 5247.0,
            49.0 / 176.0,
            -5103.0 / 18656.0,
        ];
        let x5_stage = x + h
            * (9017.0 / 3168.0 * k[0] - 355.0 / 33.0 * k[1]
                + 46732.0 / 5247.0 * k[2]
                + 49.0 / 176.0 * k[3]
                - 5103.0 / 18656.0 * k[4]);
        stage(5, h, x5_stage, &a5, &mut k);
        let x5 = x + h
            * (35.0 / 384.0 * k[0] + 500.0 / 1113.0 * k[2] + 125.0 / 192.0 * k[3]
                - 2187.0 / 6784.0 * k[4]
                + 11.0 / 84.0 * k[5]);
        for (l, pending) in self.pending.iter_mut().enumerate().take(self.p) {
            *pending = self.s[l]
                + h * (35.0 / 384.0 * dk[0][l]
                    + 500.0 / 1113.0 * dk[2][l]
                    + 125.0 / 192.0 * dk[3][l]
                    - 2187.0 / 6784.0 * dk[4][l]
                    + 11.0 / 84.0 * dk[5][l]);
        }
        let k7 = ode.slope(u + h, x5, d);
        let err = h
            * (71.0 / 57600.0 * k[0] - 71.0 / 16695.0 * k[2] + 71.0 / 1920.0 * k[3]
                - 17253.0 / 339200.0 * k[4]
                + 22.0 / 525.0 * k[5]
                - 1.0 / 40.0 * k7);
        (x5, err.abs())
    }
    fn accept(&mut self) {
        self.s = self.pending;
    }
}

fn at_sample(e: Error, index: usize) -> Error {
    match e {
        Error::Diverged { reason, .. } => Error::Diverged { index, reason },
        other => other,
    }
}

/// The operator one sample at a time: the state x and the previous input (none before the
/// first sample, where x is the initial state x₀ whatever the input).
///
/// Sample k integrates x from u_{k−1} to u_k exactly as [`simulate`] does (the same
/// Dormand–Prince steps from the same end points, so the same bits) and gives h(u_k, x_k).
/// The one difference is the divergence guard: a stream allows each sample interval
/// 100 000 sub-steps, a batch shares 100 000 + 100 per sample over its record.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stream {
    /// (u_{k−1}, x_{k−1}) after the first sample.
    last: Option<(f64, f64)>,
}

impl Stream {
    /// y_k for u_k = `u` (`k` the sample's index, for the errors); the state moves on.
    pub fn step<O: InputOde + ?Sized>(&mut self, ode: &O, k: usize, u: f64) -> Result<f64> {
        let x = match self.last {
            None => ode.initial_state(),
            Some((u_prev, x_prev)) => {
                advance(ode, x_prev, u_prev, u).map_err(|e| at_sample(e, k))?
            }
        };
        self.last = Some((u, x));
        Ok(ode.output(u, x))
    }
}

/// The inverse one sample at a time (see the module doc): the previous command and state,
/// and the declared history its first command starts after, if any.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct InverseStream {
    /// (u_{k−1}, x_{k−1}) after the first sample.
    last: Option<(f64, f64)>,
    /// The history run before the first command (None: the first command meets x₀).
    history: Option<HistoryRun>,
}

/// A declared history as the inverse's first command runs it: the operator's memory reach
/// that places the turn ([`History::turn_at`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HistoryRun {
    /// The declared history, with the fit's saved turn.
    pub history: History,
    /// The operator's memory reach ([`History::reach`]).
    pub reach: f64,
}

impl HistoryRun {
    /// The state after the history before a first command `v`: x₀ at v, integrated to the
    /// turn u_turn = [`History::turn_at`]`(reach, v)` and back to v, the path
    /// v → u_turn → v a simulation of the saved model runs before a record starting at v
    /// ([`super::initial_state::simulate_from`]), with the same steps and so the same bits.
    pub fn state_at<O: InputOde + ?Sized>(&self, ode: &O, v: f64) -> Result<f64> {
        let turn = self.history.turn_at(self.reach, v);
        let at_turn = advance(ode, ode.initial_state(), v, turn)?;
        advance(ode, at_turn, turn, v)
    }

    /// Whether a first command `v` lies strictly on the record's side of the saved turn t
    /// (below a descending history's, above an ascending one's). Beyond it the turn moves
    /// with v ([`History::turn_at`]), the branch jumps there and a rate-independent family
    /// mirrors itself (the path v → t → v has the excursion |t − v| on both sides), so the
    /// first command's search keeps to this side; without a saved turn, everywhere.
    pub fn admits(&self, v: f64) -> bool {
        self.history
            .turn
            .is_none_or(|t| (t - v) * self.history.direction() > 0.0)
    }

    /// Where the first command's search starts: the family's anchor input when
    /// [`HistoryRun::admits`] it, else the saved turn stepped back towards the record by
    /// max(reach, 10⁻⁶·max(|t|, 1)).
    pub fn start<O: InputOde + ?Sized>(&self, ode: &O) -> f64 {
        let anchor = ode.anchor_input();
        match self.history.turn {
            Some(t) if !self.admits(anchor) => {
                t - self.history.direction() * self.reach.max(1e-6 * t.abs().max(1.0))
            }
            _ => anchor,
        }
    }
}

impl InverseStream {
    /// The inverse whose first command starts after `history`.
    pub fn after(history: HistoryRun) -> Self {
        Self {
            last: None,
            history: Some(history),
        }
    }

    /// The command for the reference r_k = `r`, what the operator makes of it, and whether
    /// r_k was out of reach (clipped); the state moves on.
    pub fn step<O: InputOde + ?Sized>(
        &mut self,
        ode: &O,
        k: usize,
        r: f64,
    ) -> Result<CompensatorStep> {
        let (u, x, predicted, clipped) = match self.last {
            // The first sample: the state is x₀ whatever the input, only h(u, x₀) can be
            // matched; after a declared history, the state the history leaves at u.
            None => match self.history {
                None => {
                    let x0 = ode.initial_state();
                    solve_sample(&|v| Ok((ode.output(v, x0), x0)), ode.anchor_input(), ode, r)?
                }
                Some(run) => {
                    let branch = |v: f64| -> Result<(f64, f64)> {
                        if !run.admits(v) {
                            return Err(Error::Unsupported(
                                "a first command beyond the history's turn".into(),
                            ));
                        }
                        let xv = run.state_at(ode, v)?;
                        Ok((ode.output(v, xv), xv))
                    };
                    solve_sample(&branch, run.start(ode), ode, r).map_err(|e| at_sample(e, k))?
                }
            },
            Some((u_prev, x_prev)) => {
                let branch = |v: f64| -> Result<(f64, f64)> {
                    let xv = advance(ode, x_prev, u_prev, v)?;
                    Ok((ode.output(v, xv), xv))
                };
                solve_sample(&branch, u_prev, ode, r).map_err(|e| at_sample(e, k))?
            }
        };
        self.last = Some((u, x));
        Ok(CompensatorStep {
            u,
            predicted,
            clipped,
        })
    }
}

/// The input that makes the operator follow `reference` (see the module doc), sample by
/// sample from the initial state ([`InverseStream`]); unreachable samples are clipped and
/// listed.
pub fn invert<O: InputOde + ?Sized>(ode: &O, reference: &[f64]) -> Result<Inversion> {
    check_signal("reference", reference)?;
    let mut stream = InverseStream::default();
    let n = reference.len();
    let (mut u, mut predicted, mut clipped) =
        (Vec::with_capacity(n), Vec::with_capacity(n), Vec::new());
    for (k, &r) in reference.iter().enumerate() {
        let step = stream.step(ode, k, r)?;
        u.push(step.u);
        predicted.push(step.predicted);
        if step.clipped {
            clipped.push(k);
        }
    }
    Ok(Inversion {
        u,
        predicted,
        clipped,
    })
}

/// The most doublings of the inverse's bracket search in one direction: from 1e-9 of the
/// inversion span, 2³⁰ · 10⁻⁹ > 1 reaches the span in 30; the cap binds only where
/// 10⁻⁹ · span rounds to 0 (a span below about 10⁻³¹⁵), whose search would never end.
pub(crate) const BRACKET_DOUBLINGS: usize = 30;

/// Finds v with y(v) = r near `start`: (v, state, output, clipped).
type Branch<'a> = dyn Fn(f64) -> Result<(f64, f64)> + 'a;

fn solve_sample<O: InputOde + ?Sized>(
    branch: &Branch<'_>,
    start: f64,
    ode: &O,
    r: f64,
) -> Result<(f64, f64, f64, bool)> {
    let (y0, x0) = branch(start)?;
    let g0 = y0 - r;
    let ytol = 1e-13 * (r.abs() + y0.abs()).max(f64::MIN_POSITIVE);
    if g0.abs() <= ytol {
        return Ok((start, x0, y0, false));
    }
    let span = ode.inversion_span().abs();
    let mut best = (start, x0, y0);
    // Search first where a small probe says the output moves towards r, then the other way
    // (an operator driven by −u has a decreasing branch).
    let probe = 1e-6 * ode.max_substep().abs();
    let rising = match branch(start + probe) {
        Ok((yp, _)) if yp < y0 => -1.0,
        _ => 1.0,
    };
    let first = -g0.signum() * rising;
    for direction in [first, -first] {
        let mut d = 1e-9 * span;
        let (mut a, mut ga) = (start, g0);
        for _ in 0..BRACKET_DOUBLINGS {
            if d > span {
                break;
            }
            let v = start + direction * d;
            let Ok((yv, xv)) = branch(v) else { break };
            if (yv - r).abs() < (best.2 - r).abs() {
                best = (v, xv, yv);
            }
            let gv = yv - r;
            if gv.abs() <= ytol {
                return Ok((v, xv, yv, false));
            }
            if gv.signum() != g0.signum() {
                let (v, xv, yv) = illinois(branch, (a, ga), (v, gv), r, ytol)?;
                return Ok((v, xv, yv, false));
            }
            (a, ga) = (v, gv);
            d *= 2.0;
        }
    }
    Ok((best.0, best.1, best.2, true))
}

/// The Illinois regula falsi on a bracket [a, b] with g(a)·g(b) < 0, g(v) = y(v) − r.
fn illinois(
    branch: &Branch<'_>,
    (mut a, mut ga): (f64, f64),
    (mut b, mut gb): (f64, f64),
    r: f64,
    ytol: f64,
) -> Result<(f64, f64, f64)> {
    let mut side = 0i8;
    let mut out = branch(b)?;
    let mut v = b;
    for _ in 0..200 {
        v = (a * gb - b * ga) / (gb - ga);
        if !v.is_finite() || v <= a.min(b) || v >= a.max(b) {
            v = 0.5 * (a + b);
        }
        out = branch(v)?;
        let gv = out.0 - r;
        if gv.abs() <= ytol || (b - a).abs() <= 4.0 * f64::EPSILON * v.abs().max(f64::MIN_POSITIVE)
        {
            break;
        }
        if gv.signum() == gb.signum() {
            (b, gb) = (v, gv);
            if side == 1 {
                ga *= 0.5;
            }
            side = 1;
        } else {
            (a, ga) = (v, gv);
            if side == -1 {
                gb *= 0.5;
            }
            side = -1;
        }
    }
    Ok((v, out.1, out.0))
}
