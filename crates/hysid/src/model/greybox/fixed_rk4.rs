//! RK4 with forward sensitivities for a model whose state count N and sensitivity column
//! count Q are known at compile time.
//!
//! The generic path ([`super::simulate::simulate_sensitivities`]) integrates the augmented
//! state z = [x, S] as one slice of run-time length n + n·q, calling the model through a
//! trait object at every stage. For a small model such as the Bouc–Wen oscillator (n = 3,
//! q ≤ 10) the bookkeeping of that path (slice splits, zipped loops of three elements, the
//! model's constants recomputed per stage, the virtual call) costs more than the arithmetic.
//! Here x is `[f64; N]` and S is `[[f64; Q]; N]` (the same row-major n × q layout), the
//! right-hand side is a `FixedSensitivityRhs` known to the compiler, and the stage updates
//! are loops of constant length that it unrolls and vectorises.
//!
//! The stages and the update are the classical RK4 of [`crate::numerics::integrate::Rk4`],
//! with every element computed by the same operations in the same order (Rust does not
//! contract a·b + c into a fused multiply–add), so the two paths give the same numbers to the
//! last bit; `fixed_path_equals_the_generic_path` in the Bouc–Wen kernel checks this.
//!
//! Reference: W. Kutta, Z. Math. Phys. 46, 1901 (the stages); Hairer, Nørsett & Wanner,
//! *Solving Ordinary Differential Equations I*, 2nd ed., §I.14 (the sensitivities).

use super::simulate::{diverged, InputTrack};
use crate::Result;
use std::ops::ControlFlow;

/// Receives each sample k with x(t_k) and S(t_k) (row-major n × q); `Break` ends the
/// simulation there (its caller, which said so, knows the rest was not simulated).
pub type SampleSink<'a> = dyn FnMut(usize, &[f64], &[f64]) -> ControlFlow<()> + 'a;

/// One simulation with forward sensitivities, as [`super::simulate::simulate_sensitivities`]
/// asks a model's own fixed-size path for it
/// ([`StateSpaceModel::fixed_rk4_sensitivities`](super::StateSpaceModel::fixed_rk4_sensitivities)).
#[derive(Clone, Copy, Debug)]
pub struct Rk4Sensitivities<'a> {
    /// The parameter vector θ.
    pub theta: &'a [f64],
    /// The initial state x(t₀).
    pub x0: &'a [f64],
    /// S(t₀), row-major n × q: zero, with a one in the column of each estimated initial state.
    pub s0: &'a [f64],
    /// The input, tabulated at the half-step nodes of the sub-steps.
    pub input: &'a InputTrack,
    /// Sample time \[s\].
    pub ts: f64,
    /// RK4 sub-steps per sample (≥ 1).
    pub substeps: usize,
    /// The sensitivity columns of θ (indices into θ), first in S.
    pub params: &'a [usize],
    /// The sensitivity columns of the initial states (indices into x), after `params`.
    pub initial: &'a [usize],
}

impl Rk4Sensitivities<'_> {
    /// Number of sensitivity columns q.
    pub fn columns(&self) -> usize {
        self.params.len() + self.initial.len()
    }
}

/// ẋ = f(x, u) and Ṡ = (∂f/∂x)·S + ∂f/∂p for a model of N states and Q sensitivity columns,
/// its parameters bound when the kernel was built. `&mut self`: a kernel may evaluate into
/// buffers of its own (the equation-file tape's registers).
pub(crate) trait FixedSensitivityRhs<const N: usize, const Q: usize> {
    /// ẋ into `dx` and Ṡ into `ds` at state `x`, sensitivities `s` and input `u`.
    fn eval(
        &mut self,
        x: &[f64; N],
        u: &[f64],
        s: &[[f64; Q]; N],
        dx: &mut [f64; N],
        ds: &mut [[f64; Q]; N],
    );
}

/// The augmented state [x, S] of fixed size.
#[derive(Clone, Copy)]
struct Augmented<const N: usize, const Q: usize> {
    x: [f64; N],
    s: [[f64; Q]; N],
}

impl<const N: usize, const Q: usize> Augmented<N, Q> {
    const ZERO: Self = Self {
        x: [0.0; N],
        s: [[0.0; Q]; N],
    };

    /// `self = base + c·k`, element by element.
    #[inline(always)]
    fn set_axpy(&mut self, base: &Self, c: f64, k: &Self) {
        for i in 0..N {
            self.x[i] = base.x[i] + c * k.x[i];
            for j in 0..Q {
                self.s[i][j] = base.s[i][j] + c * k.s[i][j];
            }
        }
    }

    /// `self += (h/6)·(k₁ + 2k₂ + 2k₃ + k₄)`, the RK4 update of [`crate::numerics::integrate::rk4::increment`].
    #[inline(always)]
    fn add_rk4(&mut self, sixth: f64, k: &[Self; 4]) {
        let w = |a, b, c, d| crate::numerics::integrate::rk4::increment(sixth, a, b, c, d);
        for i in 0..N {
            self.x[i] += w(k[0].x[i], k[1].x[i], k[2].x[i], k[3].x[i]);
            for j in 0..Q {
                self.s[i][j] += w(k[0].s[i][j], k[1].s[i][j], k[2].s[i][j], k[3].s[i][j]);
            }
        }
    }

    fn is_finite(&self) -> bool {
        self.x
            .iter()
            .chain(self.s.as_flattened())
            .all(|v| v.is_finite())
    }
}

/// Simulates `run` with RK4 (its sub-steps per sample) from x0 with S(t₀) = s0 (row-major
/// N × Q), calling `on_sample(k, x(t_k), S(t_k))` at every sample. The input is read at the
/// half-step nodes of the track ([`InputTrack::nodes`]), which the caller has checked lie
/// on its grid (resolution 2·substeps).
pub(crate) fn simulate<K, const N: usize, const Q: usize>(
    kernel: &mut K,
    run: &Rk4Sensitivities<'_>,
    on_sample: &mut SampleSink<'_>,
) -> Result<()>
where
    K: FixedSensitivityRhs<N, Q>,
{
    #[cfg(target_arch = "x86_64")]
    if crate::numerics::cpu::has_avx() && !PORTABLE.with(std::cell::Cell::get) {
        // SAFETY: the processor has AVX, the only requirement of `simulate_avx`.
        return unsafe { simulate_avx::<K, N, Q>(kernel, run, on_sample) };
    }
    simulate_body::<K, N, Q>(kernel, run, on_sample)
}

thread_local! {
    /// Set by [`with_portable_loop`]: this thread runs the portable loop even with AVX.
    static PORTABLE: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Runs `f` with this thread's fixed-size simulations on the portable loop, not its AVX
/// twin: reached by the white-box tests, which compare the two to the bit.
#[doc(hidden)]
pub fn with_portable_loop<R>(f: impl FnOnce() -> R) -> R {
    PORTABLE.with(|p| p.set(true));
    let r = f();
    PORTABLE.with(|p| p.set(false));
    r
}

/// [`simulate_body`] compiled for AVX: element-wise stage updates and products, no sum that
/// crosses lanes, no fused multiply–add, so the portable loop's bits (the rule of
/// `docs/architecture.md`, "Vector instructions"; `avx_loop_equals_the_portable_loop` in the
/// tests).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
fn simulate_avx<K, const N: usize, const Q: usize>(
    kernel: &mut K,
    run: &Rk4Sensitivities<'_>,
    on_sample: &mut SampleSink<'_>,
) -> Result<()>
where
    K: FixedSensitivityRhs<N, Q>,
{
    simulate_body::<K, N, Q>(kernel, run, on_sample)
}

/// The loop of [`simulate`]: per sample, m RK4 sub-steps through the kernel's stages.
#[inline(always)]
fn simulate_body<K, const N: usize, const Q: usize>(
    kernel: &mut K,
    run: &Rk4Sensitivities<'_>,
    on_sample: &mut SampleSink<'_>,
) -> Result<()>
where
    K: FixedSensitivityRhs<N, Q>,
{
    let (m, h) = substep(run);
    let mut substeps = Substeps {
        kernel,
        m,
        h,
        half: 0.5 * h,
        sixth: h / 6.0,
        channels: run.input.n_channels(),
        k: [Augmented::<N, Q>::ZERO; 4],
        stage: Augmented::<N, Q>::ZERO,
    };
    sample_loop(run, on_sample, &mut substeps)
}

/// The sub-steps per sample m (at least one) and the sub-step h = Ts/m of `run`.
pub(crate) fn substep(run: &Rk4Sensitivities<'_>) -> (usize, f64) {
    let m = run.substeps.max(1);
    (m, run.ts / m as f64)
}

/// Moves z = [x, S] over one sample interval, the input given at its 2m + 1 half-step
/// nodes (node-major).
trait Advance<const N: usize, const Q: usize> {
    fn advance(&mut self, nodes: &[f64], z: &mut Augmented<N, Q>);
}

/// The m classical RK4 sub-steps of a sample interval through a kernel's stages.
struct Substeps<'k, K, const N: usize, const Q: usize> {
    kernel: &'k mut K,
    m: usize,
    h: f64,
    half: f64,
    sixth: f64,
    channels: usize,
    k: [Augmented<N, Q>; 4],
    stage: Augmented<N, Q>,
}

impl<K, const N: usize, const Q: usize> Advance<N, Q> for Substeps<'_, K, N, Q>
where
    K: FixedSensitivityRhs<N, Q>,
{
    // Inlined into the AVX twin, whose instructions it then uses.
    #[inline(always)]
    fn advance(&mut self, nodes: &[f64], z: &mut Augmented<N, Q>) {
        let (h, half, sixth, channels) = (self.h, self.half, self.sixth, self.channels);
        let span = |i: usize| i * channels..(i + 1) * channels;
        let stage = &mut self.stage;
        for j in 0..self.m {
            // Sub-step j reads nodes 2j (start), 2j + 1 (middle) and 2j + 2 (end).
            let (start, middle, end) = (
                &nodes[span(2 * j)],
                &nodes[span(2 * j + 1)],
                &nodes[span(2 * j + 2)],
            );
            let [k1, k2, k3, k4] = &mut self.k;
            self.kernel.eval(&z.x, start, &z.s, &mut k1.x, &mut k1.s);
            stage.set_axpy(z, half, k1);
            self.kernel
                .eval(&stage.x, middle, &stage.s, &mut k2.x, &mut k2.s);
            stage.set_axpy(z, half, k2);
            self.kernel
                .eval(&stage.x, middle, &stage.s, &mut k3.x, &mut k3.s);
            stage.set_axpy(z, h, k3);
            self.kernel
                .eval(&stage.x, end, &stage.s, &mut k4.x, &mut k4.s);
            z.add_rk4(sixth, &self.k);
        }
    }
}

/// A sample interval advanced by a function of (nodes, x, S row-major).
struct BySample<F>(F);

impl<F, const N: usize, const Q: usize> Advance<N, Q> for BySample<F>
where
    F: FnMut(&[f64], &mut [f64; N], &mut [f64]),
{
    #[inline(always)]
    fn advance(&mut self, nodes: &[f64], z: &mut Augmented<N, Q>) {
        (self.0)(nodes, &mut z.x, z.s.as_flattened_mut())
    }
}

/// Simulates `run` as [`simulate`] does, with `advance(nodes, x, S)` moving x and S
/// (row-major N × Q) over one sample interval from the input at its 2m + 1 half-step
/// nodes: compiled code that runs the sub-steps of [`simulate`]'s kernel loop itself
/// (equation files' native code, `hysid_substeps`), and must give its numbers.
pub(crate) fn simulate_by_samples<const N: usize, const Q: usize>(
    run: &Rk4Sensitivities<'_>,
    on_sample: &mut SampleSink<'_>,
    advance: impl FnMut(&[f64], &mut [f64; N], &mut [f64]),
) -> Result<()> {
    sample_loop::<_, N, Q>(run, on_sample, &mut BySample(advance))
}

/// The sample loop: from x0 and S(t₀) = s0, at every sample the divergence check and
/// `on_sample(k, x(t_k), S(t_k))` (which may end the loop), then `advance` over the interval
/// to the next sample, the input read at the interval's half-step nodes
/// ([`InputTrack::nodes`], which the caller has checked lie on its grid: resolution
/// 2·substeps).
#[inline(always)]
fn sample_loop<A, const N: usize, const Q: usize>(
    run: &Rk4Sensitivities<'_>,
    on_sample: &mut SampleSink<'_>,
    advance: &mut A,
) -> Result<()>
where
    A: Advance<N, Q>,
{
    let input = run.input;
    let mut z = Augmented::<N, Q>::ZERO;
    z.x.copy_from_slice(run.x0);
    z.s.as_flattened_mut().copy_from_slice(run.s0);
    let (m, _) = substep(run);
    let mut nodes = vec![0.0; (2 * m + 1) * input.n_channels()];
    let n_samples = input.len();
    for sample in 0..n_samples {
        if !z.is_finite() {
            return Err(diverged(sample));
        }
        if on_sample(sample, &z.x, z.s.as_flattened()).is_break() || sample + 1 == n_samples {
            break;
        }
        input.nodes(sample, &mut nodes);
        advance.advance(&nodes, &mut z);
    }
    Ok(())
}
