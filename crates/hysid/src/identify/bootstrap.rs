//! Parametric bootstrap of an output-error estimate.
//!
//! # Why
//!
//! The standard deviations σ²(JᵀJ)⁻¹ of [`super::output_error`] rest on the criterion being
//! smooth and nearly quadratic around the estimate. Two cases in this project break that:
//!
//! * the threshold d of the piecewise-linear Coleman–Hodgdon model: the criterion jumps where
//!   d crosses a sample magnitude, so d behaves like a change point — its estimate converges
//!   faster than 1/√N and the curvature of the smooth part overstates its spread (as for the
//!   threshold of threshold-autoregressive models, where the bootstrap is the accepted tool);
//! * weakly identified linear blocks (a pole nearly cancelled by a zero, as in the project's
//!   Example 2), where the criterion has a long flat valley and the local curvature depends on
//!   where in the valley the estimate fell.
//!
//! # Method
//!
//! With the estimate θ̂, its simulated outputs ŷ and the residual standard deviation σ̂ of each
//! output, B replicate data sets y* = ŷ + e*, e* ~ N(0, σ̂²) white, are fitted again by the
//! caller's refit procedure; the standard deviation of each parameter over the replicates is
//! reported (Efron & Tibshirani, An Introduction to the Bootstrap, 1993, ch. 6). Replicates
//! run in parallel, each with its own seeded stream.

use crate::data::{Experiment, IdData};
use crate::numerics::signal::gaussian_noise;
use crate::{Error, Result};
use rayon::prelude::*;

/// The spread of an estimate over bootstrap replicates.
#[derive(Clone, Debug)]
pub struct Bootstrap {
    /// Standard deviation of every parameter over the successful replicates.
    pub std: Vec<f64>,
    /// The replicate estimates.
    pub replicates: Vec<Vec<f64>>,
    /// Replicates whose refit failed (left out of `std`).
    pub failed: usize,
}

/// Runs a parametric bootstrap (see the module docs).
///
/// `simulated[e][o]` is the estimate's output for experiment e, output o; `sigma[o]` the
/// residual standard deviation of output o. `refit` fits one replicate data set and returns
/// its parameter vector.
pub fn parametric_bootstrap(
    data: &IdData,
    simulated: &[Vec<Vec<f64>>],
    sigma: &[f64],
    replicates: usize,
    seed: u64,
    refit: &(dyn Fn(&IdData) -> Result<Vec<f64>> + Sync),
) -> Result<Bootstrap> {
    if replicates < 2 {
        return Err(Error::invalid_option(
            "replicates",
            replicates,
            format!("a bootstrap needs at least 2 replicates, got {replicates}"),
        ));
    }
    let outcomes: Vec<Option<Vec<f64>>> = (0..replicates)
        .into_par_iter()
        .map(|r| {
            let replicate = replicate_data(data, simulated, sigma, stream(seed, r)).ok()?;
            refit(&replicate)
                .ok()
                .filter(|p| p.iter().all(|v| v.is_finite()))
        })
        .collect();
    let ok: Vec<Vec<f64>> = outcomes.iter().flatten().cloned().collect();
    let failed = replicates - ok.len();
    if ok.len() < 2 {
        return Err(Error::Singular(format!(
            "the bootstrap failed: only {} of {replicates} replicates could be refitted",
            ok.len()
        )));
    }
    let p = ok[0].len();
    let n = ok.len() as f64;
    let std = (0..p)
        .map(|i| {
            let mean = ok.iter().map(|r| r[i]).sum::<f64>() / n;
            (ok.iter().map(|r| (r[i] - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
        })
        .collect();
    Ok(Bootstrap {
        std,
        replicates: ok,
        failed,
    })
}

/// One replicate: the simulated outputs plus fresh white Gaussian noise.
fn replicate_data(
    data: &IdData,
    simulated: &[Vec<Vec<f64>>],
    sigma: &[f64],
    seed: u64,
) -> Result<IdData> {
    let mut experiments = Vec::with_capacity(data.n_experiments());
    for (e, exp) in data.experiments().iter().enumerate() {
        let inputs = (0..data.input_channels().len())
            .map(|c| exp.input(c).to_vec())
            .collect();
        let mut outputs = Vec::with_capacity(sigma.len());
        for (o, s) in sigma.iter().enumerate() {
            let noise = gaussian_noise(exp.len(), *s, seed.wrapping_add((e * 1000 + o) as u64))?;
            outputs.push(
                simulated[e][o]
                    .iter()
                    .zip(&noise)
                    .map(|(y, n)| y + n)
                    .collect(),
            );
        }
        experiments.push(Experiment::new(exp.name(), inputs, outputs)?);
    }
    IdData::new(
        data.ts(),
        data.input_channels().to_vec(),
        data.output_channels().to_vec(),
        experiments,
    )
}

/// An independent stream per replicate.
fn stream(seed: u64, replicate: usize) -> u64 {
    seed.wrapping_mul(0x2545_F491_4F6C_DD1D)
        .wrapping_add(0x9E37_79B9 * (replicate as u64 + 1))
}
