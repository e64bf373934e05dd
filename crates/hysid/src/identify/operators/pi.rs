//! Identification of a Prandtl–Ishlinskii operator by non-negative least squares.
//!
//! y = c + a₀u + Σᵢ aᵢ F_{rᵢ}\[u\] is linear in (a₀, a₁ … aₙ, c) once the thresholds are fixed
//! on a grid over the input range (default rᵢ = i·(max u − min u)/(2(n+1))): each play output
//! is one pass over the data, the (n + 2)² normal equations are accumulated once, and the
//! weights are the NNLS solution (aᵢ ≥ 0 keeps the operator monotone and its analytic inverse
//! valid; c is free). Standard deviations: σ²(ΦᵀΦ)⁻¹ restricted to the free set, σ² = RSS/(N − p);
//! a weight held at 0 has none. The count n can also be chosen by validation
//! ([`PiOptions::select`]).
//!
//! A clockwise loop is fitted in the inverse parameterisation (u = G\[y\], thresholds over the
//! output range) and Γ = G⁻¹ (Kuhnen 2003); the reported weights are then those of G.
//!
//! Reference: K. Kuhnen, "Modeling, identification and compensation of complex hysteretic
//! nonlinearities: a modified Prandtl–Ishlinskii approach", European Journal of Control 9
//! (2003) 407–418.

use super::linear_support::{
    check_data, finish, orientation, solve_weights, threshold_grid, GramAccumulator,
};
use super::OperatorFit;
use crate::model::operators::{play, validate_thresholds, Orientation, PrandtlIshlinskii};
use crate::numerics::metrics;
use crate::{Error, Result};
use std::time::Instant;

/// Options of the PI identification.
#[derive(Clone, Debug, PartialEq)]
pub struct PiOptions {
    /// Number of thresholds n of the default grid (10).
    pub thresholds: usize,
    /// An explicit threshold grid (strictly increasing, > 0) instead of the default one.
    pub grid: Option<Vec<f64>>,
    /// The orientation; detected from the data when None.
    pub orientation: Option<Orientation>,
    /// Candidate counts to choose n from by validation: each is fitted on the first 70 % of the
    /// data and the one with the best fit % on the last 30 % is refitted on all of it.
    pub select: Option<Vec<usize>>,
}

impl Default for PiOptions {
    fn default() -> Self {
        Self {
            thresholds: 10,
            grid: None,
            orientation: None,
            select: None,
        }
    }
}

/// Fits a PI operator to input `u` and output `y`.
pub fn fit(u: &[f64], y: &[f64], options: &PiOptions) -> Result<OperatorFit<PrandtlIshlinskii>> {
    if let Some(candidates) = &options.select {
        return fit_selected(u, y, options, candidates);
    }
    let start = Instant::now();
    let o = orientation(u, y, options.orientation)?;
    let (x, v) = o.core_data(u, y);
    let grid = match &options.grid {
        Some(g) => g.clone(),
        None => threshold_grid(&x, options.thresholds)?,
    };
    validate_thresholds("r", &grid)?;
    check_data(u, y, grid.len() + 2)?;
    let mut columns = Vec::with_capacity(grid.len() + 2);
    columns.push(x.clone());
    columns.extend(grid.iter().map(|&r| play(&x, r)));
    columns.push(vec![1.0; x.len()]);
    let (g, b, yy, n) = GramAccumulator::from_columns(&columns, &v);
    let mut unconstrained = vec![false; columns.len()];
    unconstrained[columns.len() - 1] = true;
    let sol = solve_weights(&g, &b, yy, n, &unconstrained, None)?;
    let m = grid.len();
    let model = PrandtlIshlinskii::new(sol.x[0], sol.x[1..=m].to_vec(), grid, sol.x[m + 1], o)
        .map_err(|e| Error::NotExciting {
            channel: "u".into(),
            reason: format!("no monotone PI operator fits these data ({e})"),
        })?;
    let mut std = sol.std[..=m].to_vec();
    std.extend(std::iter::repeat_n(None, m));
    std.push(sol.std[m + 1]);
    Ok(finish(
        model,
        o,
        u,
        y,
        std,
        sol.iterations,
        1,
        sol.converged,
        start,
    ))
}

/// Chooses the number of thresholds by validation on the last 30 % of the data.
fn fit_selected(
    u: &[f64],
    y: &[f64],
    options: &PiOptions,
    candidates: &[usize],
) -> Result<OperatorFit<PrandtlIshlinskii>> {
    let split = u.len() * 7 / 10;
    let mut best: Option<(f64, usize)> = None;
    for &n in candidates {
        let opts = PiOptions {
            thresholds: n,
            select: None,
            grid: None,
            ..options.clone()
        };
        let Ok(f) = fit(&u[..split], &y[..split], &opts) else {
            continue;
        };
        let Ok(sim) = crate::model::operators::HysteresisOperator::simulate(&f.model, u) else {
            continue;
        };
        let score = metrics::fit_percent(&y[split..], &sim[split..]);
        if best.is_none_or(|(s, _)| score > s) {
            best = Some((score, n));
        }
    }
    let (_, n) = best.ok_or_else(|| {
        Error::invalid_option(
            "threshold_counts",
            "none",
            "no candidate threshold count could be fitted; give counts >= 1".into(),
        )
    })?;
    fit(
        u,
        y,
        &PiOptions {
            thresholds: n,
            select: None,
            grid: None,
            ..options.clone()
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::operators::HysteresisOperator;
    use rand::rngs::Xoshiro256PlusPlus;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};

    /// A decaying oscillation with nested minor loops.
    pub(crate) fn input(n: usize) -> Vec<f64> {
        (0..n)
            .map(|k| {
                let t = k as f64 / n as f64;
                2.0 + 3.0 * (1.0 - 0.8 * t) * (37.0 * t).sin() + 0.6 * (151.0 * t).sin()
            })
            .collect()
    }

    fn truth(u: &[f64], o: Orientation) -> PrandtlIshlinskii {
        let grid = threshold_grid(u, 6).unwrap();
        PrandtlIshlinskii::new(0.9, vec![0.5, 0.0, 0.3, 0.25, 0.0, 0.1], grid, 0.4, o).unwrap()
    }

    #[test]
    fn recovers_weights_both_orientations() {
        let u = input(4000);
        for o in [Orientation::COUNTER_CLOCKWISE, Orientation::CLOCKWISE] {
            let t = truth(&u, o);
            let y = t.simulate(&u).unwrap();
            let opts = PiOptions {
                grid: Some(t.thresholds().to_vec()),
                ..PiOptions::default()
            };
            let f = fit(&u, &y, &opts).unwrap();
            assert_eq!(f.model.orientation(), o);
            let rel = |a: f64, b: f64| (a - b).abs() / b.abs().max(1.0);
            assert!(
                rel(f.model.a0(), t.a0()) < 1e-6,
                "{o:?} a0 {}",
                f.model.a0()
            );
            for (a, b) in f.model.weights().iter().zip(t.weights()) {
                assert!(rel(*a, *b) < 1e-6, "{o:?} {a} vs {b}");
            }
            assert!(rel(f.model.offset(), t.offset()) < 1e-6);
            assert!(f.fit_percent > 99.9999, "{}", f.fit_percent);
            // thresholds are fixed: no σ
            assert!(f.std[7..13].iter().all(Option::is_none) && f.std[0].is_some());
        }
    }

    #[test]
    fn default_grid_recovers_its_own_model() {
        let u = input(3000);
        let grid = threshold_grid(&u, 10).unwrap();
        let t = PrandtlIshlinskii::new(
            0.5,
            (0..10).map(|i| 0.1 + 0.05 * i as f64).collect(),
            grid,
            -1.0,
            Orientation::default(),
        )
        .unwrap();
        let y = t.simulate(&u).unwrap();
        let f = fit(&u, &y, &PiOptions::default()).unwrap();
        for (a, b) in f.model.weights().iter().zip(t.weights()) {
            assert!((a - b).abs() < 1e-6 * b, "{a} vs {b}");
        }
        assert_eq!(f.termination, crate::numerics::Termination::ZeroResidual);
        let sel = fit(
            &u,
            &y,
            &PiOptions {
                select: Some(vec![3, 10, 20]),
                ..PiOptions::default()
            },
        )
        .unwrap();
        assert_eq!(sel.model.weights().len(), 10);
    }

    #[test]
    fn noisy_weights_within_three_sigma() {
        let u = input(4000);
        let t = truth(&u, Orientation::COUNTER_CLOCKWISE);
        let clean = t.simulate(&u).unwrap();
        let noise_std = metrics::std_dev(&clean) / 100.0; // SNR 40 dB
        let (mut inside, mut total) = (0, 0);
        for seed in 0..8u64 {
            let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
            let normal = Normal::new(0.0, noise_std).unwrap();
            let y: Vec<f64> = clean.iter().map(|v| v + normal.sample(&mut rng)).collect();
            let opts = PiOptions {
                grid: Some(t.thresholds().to_vec()),
                orientation: Some(Orientation::COUNTER_CLOCKWISE),
                ..PiOptions::default()
            };
            let f = fit(&u, &y, &opts).unwrap();
            let truth_values = [t.a0()].into_iter().chain(t.weights().iter().copied());
            for (i, tv) in truth_values.enumerate() {
                let est = f.parameters.get(i).value;
                // a weight at the bound (no σ) counts as inside when it is within noise of 0
                let ok = match f.std[i] {
                    Some(s) => (est - tv).abs() <= 3.0 * s,
                    None => tv.abs() <= 3.0 * noise_std,
                };
                inside += ok as usize;
                total += 1;
            }
        }
        assert!(inside * 10 >= total * 9, "{inside}/{total}");
    }

    #[test]
    fn bad_data_are_refused() {
        let u = input(500);
        let y = u.clone();
        let o = PiOptions::default();
        assert!(fit(&u[..5], &y[..5], &o).is_err());
        let mut bad = y.clone();
        bad[7] = f64::NAN;
        assert!(fit(&u, &bad, &o)
            .unwrap_err()
            .to_string()
            .contains("sample 7"));
        let ramp: Vec<f64> = (0..500).map(|k| k as f64).collect();
        assert!(fit(&ramp, &ramp, &o)
            .unwrap_err()
            .to_string()
            .contains("reversal"));
        let grid = PiOptions {
            grid: Some(vec![0.5, 0.2]),
            ..o.clone()
        };
        assert!(fit(&u, &y, &grid)
            .unwrap_err()
            .to_string()
            .contains("increasing"));
        assert!(fit(&u, &y[..400], &o).is_err());
    }
}
