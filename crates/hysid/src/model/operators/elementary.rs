//! Elementary operators shared by the linear-in-weights families: the play and stop operators
//! (Krasnosel'skii & Pokrovskii 1989), the loop orientation, input checks and the monotone
//! per-sample solve used by the numerical inverses.

use super::Inversion;
use super::LoopOrientation;
use crate::{Error, Result};
use serde::{Deserialize, Serialize};

/// One step of the play (backlash) operator of half-width r:
/// z_k = max(u_k − r, min(u_k + r, z_{k−1})) (Krasnosel'skii & Pokrovskii 1989).
#[inline]
pub fn play_step(z: f64, u: f64, r: f64) -> f64 {
    (u - r).max((u + r).min(z))
}

/// The play operator F_r\[u\] from the state z₋₁ = 0: z₀ = max(u₀ − r, min(u₀ + r, 0)).
pub fn play(u: &[f64], r: f64) -> Vec<f64> {
    let mut z = 0.0;
    u.iter()
        .map(|&uk| {
            z = play_step(z, uk, r);
            z
        })
        .collect()
}

/// The stop operator E_r\[u\] = u − F_r\[u\]: the force of a spring whose end slips beyond ±r
/// (the elasto-plastic element of a Maxwell-slip model), from the same state 0.
pub fn stop(u: &[f64], r: f64) -> Vec<f64> {
    play(u, r).iter().zip(u).map(|(z, x)| x - z).collect()
}

/// Checks that a threshold grid is finite, positive and strictly increasing.
pub fn validate_thresholds(name: &str, r: &[f64]) -> Result<()> {
    for (i, &ri) in r.iter().enumerate() {
        if !ri.is_finite() || ri <= 0.0 {
            return Err(Error::InvalidParameter {
                name: format!("{name}{}", i + 1),
                value: ri,
                reason: "thresholds must be finite and > 0; give a positive grid".into(),
            });
        }
        if i > 0 && ri <= r[i - 1] {
            return Err(Error::InvalidParameter {
                name: format!("{name}{}", i + 1),
                value: ri,
                reason: format!(
                    "threshold grid is not strictly increasing ({name}{} = {}); sort it and remove duplicates",
                    i,
                    r[i - 1]
                ),
            });
        }
    }
    Ok(())
}

/// Checks that a signal is non-empty and finite.
pub(crate) fn check_signal(channel: &str, x: &[f64]) -> Result<()> {
    if x.is_empty() {
        return Err(Error::InvalidData(format!(
            "'{channel}' is empty; give at least one sample"
        )));
    }
    match x.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(Error::NonFinite {
            channel: channel.into(),
            index,
            value: x[index],
        }),
        None => Ok(()),
    }
}

/// Checks that a weight or parameter is finite.
pub(crate) fn check_finite(name: &str, value: f64) -> Result<()> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(Error::InvalidParameter {
            name: name.into(),
            value,
            reason: "must be finite".into(),
        })
    }
}

/// How a loop's orientation is mapped onto a family's core operator G.
///
/// * counter-clockwise, increasing (the output lags, as the play operator): Γ = G;
/// * clockwise, increasing (the output leads): Γ = G⁻¹ — the *inverse-operator
///   parameterisation*, G identified from y to u (exchanging the axes mirrors the loop and
///   reverses its orientation);
/// * a decreasing trend flips the output's sign: Γ = −G or Γ = −G⁻¹.
///
/// The inverse of Γ is then G⁻¹[±r] or G[±r] respectively. The Maxwell-slip elements
/// (stop operators) are the exception: their own loop is clockwise, so for them `inverse`
/// marks a counter-clockwise loop.
///
/// The user's `--orientation ccw|cw` (Python `orientation="ccw"|"cw"`) is the turning sense
/// in the (u, y) plane, u horizontal ([`LoopOrientation`]); the trend stays detected (the
/// sign of cov(u, y)). With a core G that is counter-clockwise: `ccw` is
/// `{"inverse": false, "decreasing": false}` (Γ = G) or, decreasing, `{"inverse": true,
/// "decreasing": true}` (Γ = −G⁻¹); `cw` is `{"inverse": true, "decreasing": false}`
/// (Γ = G⁻¹) or `{"inverse": false, "decreasing": true}` (Γ = −G): see
/// [`Orientation::for_loop`] and [`Orientation::loop_orientation`]. Model files keep storing
/// `{inverse, decreasing}`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Orientation {
    /// True when Γ = G⁻¹ (a clockwise loop with an increasing trend).
    pub inverse: bool,
    /// True when the output decreases with the input (Γ = −G or −G⁻¹).
    pub decreasing: bool,
}

impl Orientation {
    /// Γ = G: counter-clockwise loop, increasing.
    pub const COUNTER_CLOCKWISE: Orientation = Orientation {
        inverse: false,
        decreasing: false,
    };
    /// Γ = G⁻¹: clockwise loop, increasing.
    pub const CLOCKWISE: Orientation = Orientation {
        inverse: true,
        decreasing: false,
    };

    /// Detects the orientation of a measured loop: the trend is the sign of cov(u, y) (as
    /// before); the turning sense is the area between the ascending and descending branches
    /// ([`LoopOrientation::detect`], module [`super::orientation`]): robust to open records,
    /// several runs, offsets and narrow loops, where the path integral ∮ y du of the whole
    /// record is not. Then Γ = G⁻¹ (`inverse`) exactly when the loop of ỹ = ±y (made
    /// increasing) is clockwise, i.e. `inverse = cw XOR decreasing`
    /// ([`Orientation::for_loop`]). An [`Error::UndeterminedOrientation`] when the record
    /// cannot tell.
    pub fn detect(u: &[f64], y: &[f64]) -> Result<Orientation> {
        let decreasing = Self::trend(u, y)?;
        Ok(Self::for_loop(LoopOrientation::detect(u, y)?, decreasing))
    }

    /// True when the output decreases with the input (cov(u, y) < 0); an error when the
    /// covariance is 0 or not finite.
    pub fn trend(u: &[f64], y: &[f64]) -> Result<bool> {
        let n = u.len().min(y.len()) as f64;
        let (mu, my) = (u.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
        let cov: f64 = u.iter().zip(y).map(|(a, b)| (a - mu) * (b - my)).sum();
        if cov == 0.0 || !cov.is_finite() {
            return Err(Error::NotExciting {
                channel: "u".into(),
                reason: "the output does not follow the input (zero covariance); \
                         check the columns"
                    .into(),
            });
        }
        Ok(cov < 0.0)
    }

    /// The orientation of a counter-clockwise core G for a loop of turning sense `turning`
    /// in the (u, y) plane and the trend `decreasing`: exchanging the axes (Γ = G⁻¹) and
    /// negating the output (Γ = −G) each reverse the turning sense, so
    /// `inverse = (turning == cw) XOR decreasing`: ccw ↦ {inverse: false, decreasing: false}
    /// or {inverse: true, decreasing: true}; cw ↦ {true, false} or {false, true}.
    pub fn for_loop(turning: LoopOrientation, decreasing: bool) -> Orientation {
        Orientation {
            inverse: (turning == LoopOrientation::Clockwise) != decreasing,
            decreasing,
        }
    }

    /// The turning sense in the (u, y) plane of Γ built on a counter-clockwise core G in
    /// this orientation (the inverse of [`Orientation::for_loop`]); for a clockwise core
    /// (the Maxwell-slip stops) it is the [`LoopOrientation::reversed`] one.
    pub fn loop_orientation(&self) -> LoopOrientation {
        if self.inverse == self.decreasing {
            LoopOrientation::CounterClockwise
        } else {
            LoopOrientation::Clockwise
        }
    }

    /// ±1: the output's sign.
    pub fn sign(&self) -> f64 {
        if self.decreasing {
            -1.0
        } else {
            1.0
        }
    }

    /// The pair (input of G, output of G) for data (u, y) in this orientation.
    pub fn core_data(&self, u: &[f64], y: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let s = self.sign();
        let ys: Vec<f64> = y.iter().map(|v| s * v).collect();
        if self.inverse {
            (ys, u.to_vec())
        } else {
            (u.to_vec(), ys)
        }
    }
}

/// A family's core operator G (counter-clockwise, increasing) and its inverse, one sample at a
/// time, from which [`Orientation`] builds Γ.
///
/// This is the family's streaming form: `forward_step` gives G\[u\]ₖ for the input uₖ and
/// advances the state to k + 1, `backward_step` the same for G⁻¹. Every oriented simulation
/// and inversion below is a loop over these steps, so a stream and a batch give the same bits.
/// A state is fixed in size once built; `horizon` is the number of samples a batch will feed
/// (None for a stream), which only a state whose memory grows with the input's history (the
/// Preisach staircase) uses, to hold all of it.
pub(crate) trait Core {
    /// The state of G (the play states, the kernel states, the Preisach memory).
    type Forward: Clone + std::fmt::Debug + Send;
    /// The state of G⁻¹, with what the inverse precomputes.
    type Backward: Clone + std::fmt::Debug + Send;

    /// The orientation Γ is built with.
    fn orientation(&self) -> Orientation;
    /// G's initial state.
    fn forward_state(&self, horizon: Option<usize>) -> Self::Forward;
    /// G\[u\]ₖ for uₖ = `u`; the state moves on to k + 1.
    fn forward_step(&self, state: &mut Self::Forward, u: f64) -> f64;
    /// G⁻¹'s initial state (consistent with G's).
    fn backward_state(&self, horizon: Option<usize>) -> Self::Backward;
    /// G⁻¹\[v\]ₖ for vₖ = `v`, and whether vₖ lay beyond G's reach and was clipped.
    fn backward_step(&self, state: &mut Self::Backward, v: f64) -> (f64, bool);
    /// True once a stream's state of fixed capacity could not hold the input's history (its
    /// outputs are then no longer G's); never for a batch state.
    fn overflowed(
        &self,
        _forward: Option<&Self::Forward>,
        _backward: Option<&Self::Backward>,
    ) -> bool {
        false
    }
}

/// The state of Γ = ±G or ±G⁻¹ for a stream: G's state, or G⁻¹'s for the inverse-operator
/// parameterisation.
#[derive(Clone, Debug)]
pub(crate) enum OrientedState<C: Core> {
    /// Γ = ±G.
    Direct(C::Forward),
    /// Γ = ±G⁻¹.
    Inverse(C::Backward),
}

/// Γ's initial state.
pub(crate) fn oriented_state<C: Core>(
    core: &C,
    o: Orientation,
    horizon: Option<usize>,
) -> OrientedState<C> {
    if o.inverse {
        OrientedState::Inverse(core.backward_state(horizon))
    } else {
        OrientedState::Direct(core.forward_state(horizon))
    }
}

/// Γ\[u\]ₖ for uₖ = `u`, and whether uₖ lay outside the domain of G⁻¹ (only for Γ = ±G⁻¹).
pub(crate) fn oriented_step<C: Core>(
    core: &C,
    o: Orientation,
    state: &mut OrientedState<C>,
    u: f64,
) -> (f64, bool) {
    let s = o.sign();
    let (y, outside) = match state {
        OrientedState::Direct(forward) => (core.forward_step(forward, u), false),
        OrientedState::Inverse(backward) => core.backward_step(backward, u),
    };
    (s * y, outside)
}

/// The error for an input sample `u` at index `k` outside the domain of a clockwise Γ = ±G⁻¹.
pub(crate) fn outside_domain(k: usize, u: f64) -> Error {
    Error::InvalidData(format!(
        "input sample {k} = {u} lies outside the range this (clockwise) operator \
         can take; scale the input into the identification range"
    ))
}

/// Γ[u] for a core in an orientation; an input outside the domain of G⁻¹ is an error.
pub(crate) fn oriented_simulate<C: Core>(core: &C, u: &[f64]) -> Result<Vec<f64>> {
    check_signal("u", u)?;
    let o = core.orientation();
    let mut state = oriented_state(core, o, Some(u.len()));
    let mut y = Vec::with_capacity(u.len());
    for (k, &uk) in u.iter().enumerate() {
        match oriented_step(core, o, &mut state, uk) {
            (_, true) => return Err(outside_domain(k, uk)),
            (yk, false) => y.push(yk),
        }
    }
    Ok(y)
}

/// Γ[u] for a core in an orientation, inputs outside the domain of G⁻¹ mapped to the
/// saturation level (for fit reports on the estimation data); returns the number so mapped.
pub(crate) fn oriented_simulate_saturating<C: Core>(
    core: &C,
    o: Orientation,
    u: &[f64],
) -> (Vec<f64>, usize) {
    let mut state = oriented_state(core, o, Some(u.len()));
    let mut outside = 0;
    let y = u
        .iter()
        .map(|&uk| {
            let (yk, out) = oriented_step(core, o, &mut state, uk);
            outside += usize::from(out);
            yk
        })
        .collect();
    (y, outside)
}

/// The state of Γ⁻¹ for a stream: both G's and G⁻¹'s states (one computes the command, the
/// other what Γ makes of it), and for Γ = ±G⁻¹ the running scale of the clipping test.
#[derive(Clone, Debug)]
pub(crate) struct OrientedInverse<C: Core> {
    forward: C::Forward,
    backward: C::Backward,
    scale: f64,
}

impl<C: Core> OrientedInverse<C> {
    /// The states of G and G⁻¹ at their start.
    pub(crate) fn new(core: &C, horizon: Option<usize>) -> Self {
        Self {
            forward: core.forward_state(horizon),
            backward: core.backward_state(horizon),
            scale: 1.0,
        }
    }

    /// True once a stream's state of fixed capacity overflowed ([`Core::overflowed`]).
    pub(crate) fn overflowed(&self, core: &C) -> bool {
        core.overflowed(Some(&self.forward), Some(&self.backward))
    }

    /// One sample of Γ⁻¹ for the reference rₖ = `r`: (uₖ, Γ\[u\]ₖ, clipped).
    ///
    /// Γ = ±G: uₖ = G⁻¹\[±r\]ₖ (clipped where G⁻¹ clips) and Γ\[u\]ₖ = ±G\[u\]ₖ. Γ = ±G⁻¹:
    /// uₖ = G\[±r\]ₖ, always defined, and Γ\[u\]ₖ = ±G⁻¹\[u\]ₖ, which misses ρₖ = ±rₖ where
    /// ρ is not in G's range: the sample counts as clipped when |Γ\[u\]ₖ ∓ rₖ| > 1e-9·max(1,
    /// |ρ₀|, …, |ρₖ|) (the scale of the references so far, so that a stream decides as the
    /// batch does).
    pub(crate) fn step(&mut self, core: &C, r: f64) -> (f64, f64, bool) {
        let s = core.orientation().sign();
        let rho = s * r;
        if core.orientation().inverse {
            let u = core.forward_step(&mut self.forward, rho);
            let (y, _) = core.backward_step(&mut self.backward, u);
            self.scale = self.scale.max(rho.abs());
            (u, s * y, (y - rho).abs() > 1e-9 * self.scale)
        } else {
            let (u, clipped) = core.backward_step(&mut self.backward, rho);
            (u, s * core.forward_step(&mut self.forward, u), clipped)
        }
    }
}

/// Γ⁻¹[reference] for a core in an orientation, with Γ of the result and the clipped samples.
pub(crate) fn oriented_invert<C: Core>(core: &C, reference: &[f64]) -> Result<Inversion> {
    check_signal("reference", reference)?;
    let mut state = OrientedInverse::new(core, Some(reference.len()));
    let n = reference.len();
    let (mut u, mut predicted, mut clipped) =
        (Vec::with_capacity(n), Vec::with_capacity(n), Vec::new());
    for (k, &r) in reference.iter().enumerate() {
        let (uk, yk, clip) = state.step(core, r);
        u.push(uk);
        predicted.push(yk);
        if clip {
            clipped.push(k);
        }
    }
    Ok(Inversion {
        u,
        predicted,
        clipped,
    })
}

/// Where to look for the solution of a monotone branch equation f(u) = target: f is
/// non-decreasing, constant or linear outside [center − span, center + span], unbounded
/// below/above when the flags say so (saturating otherwise).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Branch {
    /// Centre of the bracket (usually the previous input).
    pub center: f64,
    /// Half-width beyond which f is linear or constant (> 0).
    pub span: f64,
    /// f → −∞ as u → −∞.
    pub unbounded_below: bool,
    /// f → +∞ as u → +∞.
    pub unbounded_above: bool,
}

/// The largest |target − f| of a reached target: a larger one beyond a saturation level
/// counts as clipped, 1e-12·(1 + |target|) (the monotone solve's and the bounded Preisach and
/// KP solves'; the exported code's in double, `float`'s 16 ε in single).
pub(crate) fn clip_tolerance(target: f64) -> f64 {
    1e-12 * (1.0 + target.abs())
}

/// The most iterations of a bisection over m sorted points, ⌊log₂ m⌋ + 1 (0 for none): the
/// bounded Preisach and KP inverses' trial counts.
pub(crate) fn halvings(m: usize) -> usize {
    (usize::BITS - m.leading_zeros()) as usize
}

/// Solves f(u) = target for a continuous non-decreasing f (a hysteresis branch from the current
/// memory state) by bracketing and the Illinois variant of regula falsi, to machine precision.
/// Returns (u, clipped): a target beyond a saturation level is clipped to it.
pub fn solve_monotone(f: impl Fn(f64) -> f64, target: f64, branch: Branch) -> (f64, bool) {
    let span = if branch.span > 0.0 && branch.span.is_finite() {
        branch.span
    } else {
        1.0
    };
    let (mut lo, mut hi) = (branch.center - span, branch.center + span);
    let (mut flo, mut fhi) = (f(lo), f(hi));
    let tol = clip_tolerance(target);
    let mut step = span;
    while fhi < target {
        if !branch.unbounded_above || step > 1e30 {
            return (hi, target - fhi > tol);
        }
        (lo, flo) = (hi, fhi);
        step *= 2.0;
        hi += step;
        fhi = f(hi);
    }
    step = span;
    while flo > target {
        if !branch.unbounded_below || step > 1e30 {
            return (lo, flo - target > tol);
        }
        (hi, fhi) = (lo, flo);
        step *= 2.0;
        lo -= step;
        flo = f(lo);
    }
    (illinois(&f, target, (lo, flo), (hi, fhi)), false)
}

/// Illinois regula falsi on a bracket with f(lo) ≤ target ≤ f(hi).
fn illinois(f: &impl Fn(f64) -> f64, target: f64, a: (f64, f64), b: (f64, f64)) -> f64 {
    let ((mut lo, mut flo), (mut hi, mut fhi)) = ((a.0, a.1 - target), (b.0, b.1 - target));
    if flo == 0.0 {
        return lo;
    }
    if fhi == 0.0 {
        return hi;
    }
    let mut side = 0i8;
    for _ in 0..300 {
        if hi - lo <= 2.0 * f64::EPSILON * lo.abs().max(hi.abs()).max(1e-300) {
            break;
        }
        let mut m = (lo * fhi - hi * flo) / (fhi - flo);
        if !(m > lo && m < hi) {
            m = 0.5 * (lo + hi);
        }
        let fm = f(m) - target;
        if fm == 0.0 {
            return m;
        }
        if fm < 0.0 {
            (lo, flo) = (m, fm);
            if side == -1 {
                fhi *= 0.5;
            }
            side = -1;
        } else {
            (hi, fhi) = (m, fm);
            if side == 1 {
                flo *= 0.5;
            }
            side = 1;
        }
    }
    if (f(lo) - target).abs() <= (f(hi) - target).abs() {
        lo
    } else {
        hi
    }
}
