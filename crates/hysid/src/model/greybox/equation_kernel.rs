//! The fixed-size RK4 sensitivity path ([`super::fixed_rk4`]) for equation-file models
//! ([`super::equation_model`]).
//!
//! Per simulation, the tape of f, ∂f/∂x and the estimated columns of ∂f/∂θ is specialised to
//! the simulation's θ ([`hysid_equations::EquationModel::bind_columns`]: everything that
//! depends on θ alone computed once, the exact identities x·1 = x and pow(x, 1) = x applied,
//! products fused into superinstructions), then each RK4 stage runs that shorter tape from
//! (x, u) and forms
//!
//! ```text
//! Ṡ = (∂f/∂x)·S + [∂f/∂θ, 0]
//! ```
//!
//! on arrays of N states and Q columns known at compile time, skipping the entries of ∂f/∂x
//! that are zero for this θ. The sums run in the order of the generic path
//! ([`super::sensitivity::default_rhs_sensitivities`]), so the numbers are those of the
//! generic path (up to the sign of a zero), which `equation_path_equals_the_generic_path`
//! in the tests of [`super::equation_model`] checks to the bit.
//!
//! The tape's results come from the bound tape itself or from its native code
//! ([`super::native`]), which computes the same numbers (checked to the bit when it is
//! built); with native code a whole sample interval's sub-steps run in one call of it
//! (`hysid_substeps`, the stages and updates of [`super::fixed_rk4`] element by element),
//! the sample loop being the fixed-size one ([`fixed_rk4::simulate_by_samples`]).
//!
//! Reference: forward sensitivities of ODEs, Hairer, Nørsett & Wanner, *Solving Ordinary
//! Differential Equations I*, 2nd ed., §I.14.

use super::fixed_rk4::{self, FixedSensitivityRhs, Rk4Sensitivities, SampleSink};
use super::native::BoundNative;
use crate::Result;
use hysid_equations::BoundColumns;

/// The largest state count with a fixed-size path.
const MAX_STATES: usize = 4;
/// The largest sensitivity column count with a fixed-size path.
const MAX_COLUMNS: usize = 10;

/// Room for f, ∂f/∂x and ∂f/∂θ of the largest fixed-size case, rows of ∂f/∂θ padded to Q.
const OUT: usize = 64;
const _: () = assert!(MAX_STATES + MAX_STATES * MAX_STATES + MAX_STATES * MAX_COLUMNS <= OUT);

/// Where ẋ of a plain simulation is computed: the bound tape of f, or its native code
/// ([`super::native`]), which writes the same numbers.
enum Results {
    /// The tape interpreter: writes the entries that depend on (x, u) (the others were
    /// filled once, [`BoundColumns::fill_constants`]).
    Tape(BoundColumns),
    /// Native code writing every entry.
    Native(BoundNative),
}

impl Results {
    #[inline(always)]
    fn eval<const N: usize>(&mut self, x: &[f64; N], u: &[f64], out: &mut [f64]) {
        match self {
            Results::Tape(tape) => tape.eval_fixed(0.0, x, u, out),
            Results::Native(native) => native.eval(0.0, x, u, out),
        }
    }
}

/// Per entry ∂fᵢ/∂xⱼ (row-major), whether it can be non-zero: false where the bound tape
/// knows it is zero for its θ. A product by such an entry is left out of Ṡ.
pub(super) fn coupling(tape: &BoundColumns, n: usize) -> Vec<bool> {
    (0..n * n)
        .map(|e| tape.constant(n + e) != Some(0.0))
        .collect()
}

/// Where the kernel keeps result k of a column tape of n states and k columns: f, ∂f/∂x,
/// then the rows of ∂f/∂θ padded to the run's q columns.
fn column_positions(n: usize, k: usize, q: usize) -> Vec<usize> {
    let direct = n + n * n;
    (0..direct + n * k)
        .map(|r| {
            if r < direct {
                r
            } else {
                let (i, c) = ((r - direct) / k, (r - direct) % k);
                direct + i * q + c
            }
        })
        .collect()
}

/// f with its Jacobians from the bound tape, for N states and Q columns, the first k of
/// them parameter columns.
struct TapeKernel<const N: usize, const Q: usize> {
    tape: BoundColumns,
    /// f, ∂f/∂x (N×N), ∂f/∂θ\[params\] (N×Q: the k columns of the tape, then the zero direct
    /// terms of the initial-state columns), at [`column_positions`]: every index below is
    /// then known to be in bounds at compile time.
    out: [f64; OUT],
    /// Whether ∂fᵢ/∂xⱼ can be non-zero ([`coupling`]).
    coupled: [[bool; N]; N],
}

impl<const N: usize, const Q: usize> TapeKernel<N, Q> {
    fn new(mut tape: BoundColumns, k: usize) -> Self {
        let coupled = fixed_coupling(&tape);
        let positions = column_positions(N, k, Q);
        tape.place(|r| positions[r]);
        let mut out = [0.0; OUT];
        tape.fill_constants(&mut out);
        Self { tape, out, coupled }
    }
}

/// [`coupling`] as a fixed-size array.
fn fixed_coupling<const N: usize>(tape: &BoundColumns) -> [[bool; N]; N] {
    let flat = coupling(tape, N);
    std::array::from_fn(|i| std::array::from_fn(|j| flat[i * N + j]))
}

impl<const N: usize, const Q: usize> FixedSensitivityRhs<N, Q> for TapeKernel<N, Q> {
    #[inline(always)]
    fn eval(
        &mut self,
        x: &[f64; N],
        u: &[f64],
        s: &[[f64; Q]; N],
        dx: &mut [f64; N],
        ds: &mut [[f64; Q]; N],
    ) {
        // Time-free tapes only (checked by `simulate`'s caller), so t is not needed.
        self.tape.eval_fixed(0.0, x, u, &mut self.out);
        let out = &self.out;
        for (i, d) in dx.iter_mut().enumerate() {
            *d = out[i];
        }
        for (i, row) in ds.iter_mut().enumerate() {
            // The direct term (0 in the initial-state columns), then f_x·S in the order of
            // the generic path.
            for (c, d) in row.iter_mut().enumerate() {
                *d = out[N + N * N + i * Q + c];
            }
            for (j, s_j) in s.iter().enumerate() {
                if self.coupled[i][j] {
                    let a = out[N + i * N + j];
                    for (d, &sj) in row.iter_mut().zip(s_j) {
                        *d += a * sj;
                    }
                }
            }
        }
    }
}

/// ẋ alone from the bound tape of f (or its native code), for a simulation without
/// sensitivity columns (Q = 0).
struct RateKernel<const N: usize> {
    results: Results,
    /// ẋ as the tape writes it.
    out: [f64; N],
}

impl<const N: usize> FixedSensitivityRhs<N, 0> for RateKernel<N> {
    #[inline(always)]
    fn eval(
        &mut self,
        x: &[f64; N],
        u: &[f64],
        _s: &[[f64; 0]; N],
        dx: &mut [f64; N],
        _ds: &mut [[f64; 0]; N],
    ) {
        self.results.eval(x, u, &mut self.out);
        *dx = self.out;
    }
}

/// Runs the fixed-size path with the bound tape `tape` (which must not read t), or the
/// `native` sensitivity code of the same tape when given; None when the run's
/// sizes have none (more than [`MAX_STATES`] states or [`MAX_COLUMNS`] columns, or no
/// column and no native code: see [`simulate_rates`]). Without columns, the native
/// sub-steps of x alone run: one call per sample, not one per stage.
pub(super) fn simulate(
    tape: BoundColumns,
    native: Option<BoundNative>,
    run: &Rk4Sensitivities<'_>,
    on_sample: &mut SampleSink<'_>,
) -> Option<Result<()>> {
    fn with<const N: usize, const Q: usize>(
        tape: BoundColumns,
        native: Option<BoundNative>,
        run: &Rk4Sensitivities<'_>,
        on_sample: &mut SampleSink<'_>,
    ) -> Option<Result<()>> {
        Some(match native {
            // The sub-steps of a sample in one call of the native code, which sums Ṡ as
            // `TapeKernel` does, with the same coupling flags.
            Some(native) => {
                let coupled = coupling(&tape, N);
                let (m, h) = fixed_rk4::substep(run);
                fixed_rk4::simulate_by_samples::<N, Q>(run, on_sample, |nodes, x, s| {
                    native.substeps(nodes, &coupled, m, h, x, s)
                })
            }
            None => {
                let mut kernel = TapeKernel::<N, Q>::new(tape, run.params.len());
                fixed_rk4::simulate::<_, N, Q>(&mut kernel, run, on_sample)
            }
        })
    }
    fn columns<const N: usize>(
        tape: BoundColumns,
        native: Option<BoundNative>,
        run: &Rk4Sensitivities<'_>,
        on_sample: &mut SampleSink<'_>,
    ) -> Option<Result<()>> {
        const { assert!(MAX_COLUMNS == 10) };
        match run.columns() {
            // A plain simulation: the native sub-steps alone (the tape's is `simulate_rates`).
            0 if native.is_some() => with::<N, 0>(tape, native, run, on_sample),
            1 => with::<N, 1>(tape, native, run, on_sample),
            2 => with::<N, 2>(tape, native, run, on_sample),
            3 => with::<N, 3>(tape, native, run, on_sample),
            4 => with::<N, 4>(tape, native, run, on_sample),
            5 => with::<N, 5>(tape, native, run, on_sample),
            6 => with::<N, 6>(tape, native, run, on_sample),
            7 => with::<N, 7>(tape, native, run, on_sample),
            8 => with::<N, 8>(tape, native, run, on_sample),
            9 => with::<N, 9>(tape, native, run, on_sample),
            10 => with::<N, 10>(tape, native, run, on_sample),
            _ => None,
        }
    }
    const { assert!(MAX_STATES == 4) };
    match run.x0.len() {
        1 => columns::<1>(tape, native, run, on_sample),
        2 => columns::<2>(tape, native, run, on_sample),
        3 => columns::<3>(tape, native, run, on_sample),
        4 => columns::<4>(tape, native, run, on_sample),
        _ => None,
    }
}

/// Whether the fixed-size path takes a run of `states` states and `columns` columns.
pub(super) fn has_fixed_path(states: usize, columns: usize) -> bool {
    (1..=MAX_STATES).contains(&states) && columns <= MAX_COLUMNS
}

/// Runs the fixed-size path without sensitivities (a plain simulation) with the bound tape
/// of f `tape` (which must not read t), or its `native` code writing ẋ at 0..n; None for
/// more than [`MAX_STATES`] states.
pub(super) fn simulate_rates(
    tape: BoundColumns,
    native: Option<BoundNative>,
    run: &Rk4Sensitivities<'_>,
    on_sample: &mut SampleSink<'_>,
) -> Option<Result<()>> {
    fn with<const N: usize>(
        tape: BoundColumns,
        native: Option<BoundNative>,
        run: &Rk4Sensitivities<'_>,
        on_sample: &mut SampleSink<'_>,
    ) -> Option<Result<()>> {
        let mut out = [0.0; N];
        tape.fill_constants(&mut out);
        // `fill_constants` and `eval` write positions below N only (the layout of f).
        let results = match native {
            Some(native) => Results::Native(native),
            None => Results::Tape(tape),
        };
        let mut kernel = RateKernel::<N> { results, out };
        Some(fixed_rk4::simulate::<_, N, 0>(&mut kernel, run, on_sample))
    }
    match run.x0.len() {
        1 => with::<1>(tape, native, run, on_sample),
        2 => with::<2>(tape, native, run, on_sample),
        3 => with::<3>(tape, native, run, on_sample),
        4 => with::<4>(tape, native, run, on_sample),
        _ => None,
    }
}
