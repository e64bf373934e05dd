//! The processing a fit applied to its records, saved with the model so that `hysid simulate`
//! applies it again and reproduces the fit.
//!
//! * [`Prefilter`]: the pre-filter of the actuator's step 3 (J. Gunnar, E. Wernholt,
//!   G. Hovland, T. Brogårdh, "Nonlinear Grey-Box Identification of Linear Actuators
//!   Containing Hysteresis", ICRA 2006, §VI-B): optional mean removal, then a zero-phase
//!   Butterworth low-pass (`filtfilt`) of input and output alike. The model is fitted to, and
//!   simulated on, the filtered records.
//! * [`InverseDynamics`]: the preprocessing of the inverse-dynamics least squares of a rigid
//!   body (IDIM: A. Janot, M. Gautier, M. Brunot, "Data set and reference models of EMPS",
//!   2019; docs/models/rigid_body.md). From the measured position q the model *predicts* the
//!   drive signal
//!
//!   ```text
//!   û = (M q̈ + Fv q̇ + Fc sgn(q̇) + offset) / g
//!   ```
//!
//!   with q zero-phase Butterworth filtered, q̇ and q̈ by central differences, every signal
//!   decimated by the same factor (`decimate`, "parallel decimation") and `border` samples
//!   (at the original rate) dropped at each end.

use crate::numerics::sign0;
use crate::numerics::signal::{butter, decimate, filtfilt, gradient, remove_mean};
use crate::{Error, Result};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The pre-filter of a record (see the module docs): `remove_mean`, then, when `cutoff_hz`
/// is set, a zero-phase Butterworth low-pass of order `order`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Prefilter {
    /// Subtract the record's sample mean first.
    pub remove_mean: bool,
    /// Cut-off of the zero-phase Butterworth low-pass \[Hz\]; null: no low-pass.
    pub cutoff_hz: Option<f64>,
    /// Order of the Butterworth low-pass (applied forward and backward: twice the order in
    /// magnitude, zero phase).
    pub order: usize,
}

impl Prefilter {
    /// The filtered signal x sampled every `ts`: Butterworth with normalised cut-off
    /// Wn = 2·f_c·ts (1 = Nyquist), forward and backward.
    pub fn apply(&self, x: &[f64], ts: f64) -> Result<Vec<f64>> {
        let x = if self.remove_mean {
            remove_mean(x)
        } else {
            x.to_vec()
        };
        let Some(cutoff) = self.cutoff_hz else {
            return Ok(x);
        };
        let nyquist = 0.5 / ts;
        if !(cutoff > 0.0 && cutoff < nyquist) {
            return Err(Error::invalid_option(
                "cutoff_hz",
                cutoff,
                format!("the pre-filter cut-off must lie between 0 and the data's Nyquist frequency {nyquist} Hz"),
            ));
        }
        filtfilt(&butter(self.order, cutoff * 2.0 * ts)?, &x)
    }
}

/// The preprocessing of an inverse-dynamics fit (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct InverseDynamics {
    /// Cut-off of the zero-phase Butterworth filter of the position \[Hz\].
    pub cutoff_hz: f64,
    /// Its order.
    pub order: usize,
    /// Decimation factor of every signal (1: none).
    pub decimation: usize,
    /// Samples (at the original rate) dropped at each end, where the filters have transients.
    pub border: usize,
}

/// The rigid body's parameters as the regression uses them: M, Fv, Fc, offset and the drive
/// gain g.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigidBodyValues {
    /// Mass or inertia M.
    pub inertia: f64,
    /// Viscous friction Fv.
    pub fv: f64,
    /// Coulomb friction Fc.
    pub fc: f64,
    /// Constant force offset.
    pub offset: f64,
    /// Drive gain g (force = g·u).
    pub gain: f64,
}

impl InverseDynamics {
    /// Refuses a cut-off outside (0, Nyquist) and a record too short for the filters, the
    /// decimation and the borders (`parameters` to estimate).
    pub fn check(&self, samples: usize, ts: f64, parameters: usize) -> Result<()> {
        let nyquist = 0.5 / ts;
        if !(self.cutoff_hz > 0.0 && self.cutoff_hz < nyquist) {
            return Err(Error::invalid_option(
                "cutoff_hz",
                self.cutoff_hz,
                format!("the position filter's cut-off must lie between 0 and the data's Nyquist frequency {nyquist} Hz"),
            ));
        }
        // Saturating: border and decimation come from the user and may be huge.
        let needed = self
            .border
            .saturating_mul(2)
            .saturating_add(self.decimation.max(1).saturating_mul(20))
            .saturating_add(30);
        if samples < needed {
            return Err(Error::TooFewSamples {
                samples,
                parameters,
                needed,
            });
        }
        Ok(())
    }

    /// The filtered position and its first and second derivatives, at the original rate
    /// (call [`check`](Self::check) first).
    pub fn motion(&self, q: &[f64], ts: f64) -> Result<[Vec<f64>; 3]> {
        let nyquist = 0.5 / ts;
        let qf = filtfilt(&butter(self.order, self.cutoff_hz / nyquist)?, q)?;
        let qd = gradient(&qf, ts);
        let qdd = gradient(&qd, ts);
        Ok([qf, qd, qdd])
    }

    /// The regressor columns at the original rate: q̈, q̇, sgn(q̇) and, with `offset`, ones.
    pub fn columns(qd: &[f64], qdd: Vec<f64>, offset: bool) -> Vec<Vec<f64>> {
        let mut columns = vec![qdd, qd.to_vec(), qd.iter().map(|v| sign0(*v)).collect()];
        if offset {
            columns.push(vec![1.0; qd.len()]);
        }
        columns
    }

    /// A signal as the regression sees it: decimated, then `border / decimation` samples
    /// dropped at each end.
    pub fn reduce(&self, x: &[f64]) -> Result<Vec<f64>> {
        let r = self.decimation.max(1);
        let d = decimate(x, r)?;
        let cut = self.border / r;
        let rows = d.len().saturating_sub(2 * cut);
        Ok(d[cut..cut + rows].to_vec())
    }

    /// The predicted drive signal û (see the module docs) from the position `q` sampled every
    /// `ts`, and the reduced filtered position it is predicted at.
    pub fn predict(&self, p: &RigidBodyValues, q: &[f64], ts: f64) -> Result<(Vec<f64>, Vec<f64>)> {
        self.check(q.len(), ts, 4)?;
        let [qf, qd, qdd] = self.motion(q, ts)?;
        let columns = Self::columns(&qd, qdd, true);
        let reduced = columns
            .iter()
            .map(|c| self.reduce(c))
            .collect::<Result<Vec<_>>>()?;
        let theta = [p.inertia, p.fv, p.fc, p.offset];
        let u_hat = (0..reduced[0].len())
            .map(|i| (0..4).map(|j| reduced[j][i] * theta[j]).sum::<f64>() / p.gain)
            .collect();
        Ok((self.reduce(&qf)?, u_hat))
    }
}
