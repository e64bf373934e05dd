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
//! Reference: forward sensitivities of ODEs, Hairer, Nørsett & Wanner, *Solving Ordinary
//! Differential Equations I*, 2nd ed., §I.14.

use super::fixed_rk4::{self, FixedSensitivityRhs, Rk4Sensitivities, SampleSink};
use crate::Result;
use hysid_equations::BoundColumns;

/// The largest state count with a fixed-size path.
const MAX_STATES: usize = 4;
/// The largest sensitivity column count with a fixed-size path.
const MAX_COLUMNS: usize = 10;

/// f with its Jacobians from a bound tape, for N states and Q columns, the first `k` of
/// them parameter columns.
struct TapeKernel<const N: usize, const Q: usize> {
    tape: BoundColumns,
    /// f, ∂f/∂x (N×N), ∂f/∂θ\[params\] (N×k), as the tape writes them.
    out: Vec<f64>,
    /// Number of parameter columns (the rest, initial states, have no direct term).
    k: usize,
    /// Whether ∂fᵢ/∂xⱼ can be non-zero (false for an entry the bound tape knows is zero).
    coupled: [[bool; N]; N],
}

impl<const N: usize, const Q: usize> TapeKernel<N, Q> {
    fn new(tape: BoundColumns, k: usize) -> Self {
        let mut coupled = [[true; N]; N];
        for (i, row) in coupled.iter_mut().enumerate() {
            for (j, c) in row.iter_mut().enumerate() {
                *c = tape.constant(N + i * N + j) != Some(0.0);
            }
        }
        Self {
            tape,
            out: vec![0.0; N + N * N + N * k],
            k,
            coupled,
        }
    }
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
        self.tape.eval(0.0, x, u, &mut self.out);
        let (f, rest) = self.out.split_at(N);
        let (fx, direct) = rest.split_at(N * N);
        dx.copy_from_slice(f);
        let k = self.k;
        for (i, row) in ds.iter_mut().enumerate() {
            let (head, tail) = row.split_at_mut(k);
            head.copy_from_slice(&direct[i * k..(i + 1) * k]);
            tail.fill(0.0);
            for (j, s_j) in s.iter().enumerate() {
                if self.coupled[i][j] {
                    let a = fx[i * N + j];
                    for (d, &sj) in row.iter_mut().zip(s_j) {
                        *d += a * sj;
                    }
                }
            }
        }
    }
}

/// Runs the fixed-size path with the bound tape `tape` (which must not read t), None when
/// the run's sizes have none (more than [`MAX_STATES`] states or [`MAX_COLUMNS`] columns,
/// or no column).
pub(super) fn simulate(
    tape: BoundColumns,
    run: &Rk4Sensitivities<'_>,
    on_sample: &mut SampleSink<'_>,
) -> Option<Result<()>> {
    fn with<const N: usize, const Q: usize>(
        tape: BoundColumns,
        run: &Rk4Sensitivities<'_>,
        on_sample: &mut SampleSink<'_>,
    ) -> Option<Result<()>> {
        let mut kernel = TapeKernel::<N, Q>::new(tape, run.params.len());
        Some(fixed_rk4::simulate::<_, N, Q>(&mut kernel, run, on_sample))
    }
    fn columns<const N: usize>(
        tape: BoundColumns,
        run: &Rk4Sensitivities<'_>,
        on_sample: &mut SampleSink<'_>,
    ) -> Option<Result<()>> {
        const { assert!(MAX_COLUMNS == 10) };
        match run.columns() {
            1 => with::<N, 1>(tape, run, on_sample),
            2 => with::<N, 2>(tape, run, on_sample),
            3 => with::<N, 3>(tape, run, on_sample),
            4 => with::<N, 4>(tape, run, on_sample),
            5 => with::<N, 5>(tape, run, on_sample),
            6 => with::<N, 6>(tape, run, on_sample),
            7 => with::<N, 7>(tape, run, on_sample),
            8 => with::<N, 8>(tape, run, on_sample),
            9 => with::<N, 9>(tape, run, on_sample),
            10 => with::<N, 10>(tape, run, on_sample),
            _ => None,
        }
    }
    const { assert!(MAX_STATES == 4) };
    match run.x0.len() {
        1 => columns::<1>(tape, run, on_sample),
        2 => columns::<2>(tape, run, on_sample),
        3 => columns::<3>(tape, run, on_sample),
        4 => columns::<4>(tape, run, on_sample),
        _ => None,
    }
}
