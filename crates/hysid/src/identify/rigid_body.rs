//! Inverse-dynamics least squares of a rigid body with friction (step 1 of Gunnar et al.
//! 2006; the IDIM method of the EMPS benchmark).
//!
//! # Model and regression
//!
//! ```text
//! g·u = M q̈ + Fv q̇ + Fc sgn(q̇) [+ offset]
//! ```
//!
//! is linear in (M, Fv, Fc[, offset]). From the measured position q and drive signal u:
//!
//! 1. q is low-pass filtered without phase shift: Butterworth of order 4 (default), cut-off
//!    100 Hz, MATLAB-compatible `filtfilt`;
//! 2. q̇ and q̈ by central differences (MATLAB `gradient`, applied twice);
//! 3. "parallel decimation": every column of the regressor matrix and the force g·u are
//!    decimated by the same factor (MATLAB `decimate`, 8th-order Chebyshev), which low-pass
//!    filters the force as it does the regressors;
//! 4. `border` samples (at the original rate) are dropped at each end, where the filters
//!    have transients;
//! 5. ordinary least squares with covariance σ²(WᵀW)⁻¹.
//!
//! The relative error is ‖g·u − Wθ̂‖/‖g·u‖ (in %). With decimation 10 and 50 border samples
//! this is the published preprocessing of the EMPS reference model (Janot, Gautier & Brunot
//! 2019).

use crate::model::record_filters::InverseDynamics;
use crate::numerics::least_squares::{least_squares, LsSolution};
use crate::{Error, Result};
use nalgebra::DMatrix;
use serde::Serialize;

/// Settings of the inverse-dynamics least squares.
#[derive(Clone, Debug)]
pub struct RigidBodyLs {
    /// Name of the inertia parameter (`M` for a mass, `Jt` for a total inertia).
    pub inertia_name: String,
    /// Drive gain g: force = g·u.
    pub gain: f64,
    /// Estimate a constant force offset.
    pub offset: bool,
    /// Cut-off of the position filter \[Hz\].
    pub cutoff_hz: f64,
    /// Order of the Butterworth position filter.
    pub filter_order: usize,
    /// Decimation factor of the regression (1: none).
    pub decimation: usize,
    /// Samples (original rate) dropped at each end.
    pub border: usize,
}

impl Default for RigidBodyLs {
    /// The paper's step 1: order-4 Butterworth at 100 Hz, no decimation, no offset, g = 1.
    fn default() -> Self {
        Self {
            inertia_name: "M".into(),
            gain: 1.0,
            offset: false,
            cutoff_hz: 100.0,
            filter_order: 4,
            decimation: 1,
            border: 0,
        }
    }
}

/// The estimate and its statistics.
#[derive(Clone, Debug, Serialize)]
pub struct RigidBodyEstimate {
    /// Parameter names (inertia, Fv, Fc[, offset]).
    pub names: Vec<String>,
    /// Estimates.
    pub values: Vec<f64>,
    /// Standard deviations.
    pub std: Vec<f64>,
    /// The covariance σ²(WᵀW)⁻¹ of the estimates, rows in the order of `names` (its
    /// diagonal the squared `std`; empty when not computed).
    pub covariance: Vec<Vec<f64>>,
    /// Relative standard deviations, 100·σ/|θ| [%].
    pub relative_std_percent: Vec<f64>,
    /// ‖g·u − Wθ̂‖/‖g·u‖ on the estimation record [%].
    pub relative_error_percent: f64,
    /// Condition number of the column-scaled regressor matrix (columns of unit norm): what
    /// the estimate's accuracy depends on.
    pub condition_number: f64,
    /// Condition number of the regressor matrix as it is, in physical units (the figure the
    /// EMPS reference reports, 25.99).
    pub condition_number_unscaled: f64,
    /// Equations in the regression.
    pub equations: usize,
}

impl RigidBodyLs {
    /// The published EMPS preprocessing: g = 35.15065188 N/V, offset, 100 Hz, order 4,
    /// decimation 10, 50 border samples.
    pub fn emps() -> Self {
        Self {
            inertia_name: "M".into(),
            gain: 35.150_651_88,
            offset: true,
            cutoff_hz: 100.0,
            filter_order: 4,
            decimation: 10,
            border: 50,
        }
    }

    /// Estimates the parameters from position `q` and drive signal `u` sampled every `ts`.
    pub fn estimate(&self, q: &[f64], u: &[f64], ts: f64) -> Result<RigidBodyEstimate> {
        let (w, force) = self.regression(q, u, ts)?;
        let names = self.names();
        let name_refs: Vec<&str> = names.iter().map(String::as_str).collect();
        let ls: LsSolution = least_squares(&w, &force, &name_refs)?;
        let values: Vec<f64> = ls.theta.iter().copied().collect();
        let std = ls.std();
        let covariance = (0..values.len())
            .map(|i| (0..values.len()).map(|j| ls.covariance[(i, j)]).collect())
            .collect();
        if let Some((name, value)) = names.iter().zip(&values).find(|(_, v)| !v.is_finite()) {
            return Err(Error::NonFiniteResult {
                key: name.clone(),
                value: *value,
            });
        }
        Ok(RigidBodyEstimate {
            relative_std_percent: values
                .iter()
                .zip(&std)
                .map(|(v, s)| 100.0 * s / v.abs())
                .collect(),
            relative_error_percent: relative_error(&w, &force, &values),
            condition_number: ls.condition_number,
            condition_number_unscaled: condition_number(&w),
            equations: force.len(),
            names,
            values,
            std,
            covariance,
        })
    }

    /// The relative error [%] of `estimate` on another record (validation).
    pub fn relative_error(
        &self,
        estimate: &RigidBodyEstimate,
        q: &[f64],
        u: &[f64],
        ts: f64,
    ) -> Result<f64> {
        let (w, force) = self.regression(q, u, ts)?;
        Ok(relative_error(&w, &force, &estimate.values))
    }

    /// The preprocessing of the regression, saved with the model so that it predicts the
    /// drive signal as the fit did.
    pub fn preprocessing(&self) -> InverseDynamics {
        InverseDynamics {
            cutoff_hz: self.cutoff_hz,
            order: self.filter_order,
            decimation: self.decimation,
            border: self.border,
        }
    }

    fn names(&self) -> Vec<String> {
        let mut names = vec![self.inertia_name.clone(), "Fv".into(), "Fc".into()];
        if self.offset {
            names.push("offset".into());
        }
        names
    }

    /// The decimated, trimmed regressor matrix W and force g·u.
    fn regression(&self, q: &[f64], u: &[f64], ts: f64) -> Result<(DMatrix<f64>, Vec<f64>)> {
        if q.len() != u.len() {
            return Err(Error::InvalidData(format!(
                "position has {} samples, input {}",
                q.len(),
                u.len()
            )));
        }
        if !(self.gain.is_normal() && self.gain.abs() <= 1e9) {
            return Err(Error::InvalidParameter {
                name: "gain".into(),
                value: self.gain,
                reason: "the drive gain must be finite, non-zero and at most 1e9 in magnitude"
                    .into(),
            });
        }
        // Positions that do not vary at double precision have derivatives of rounding
        // noise: the regression would "fit" that noise.
        if !crate::data::varies(q) {
            return Err(Error::NotExciting {
                channel: "position".into(),
                reason: "it does not vary at double precision, so there is no motion to explain; check the position column".into(),
            });
        }
        let preprocessing = self.preprocessing();
        preprocessing.check(q.len(), ts, self.names().len())?;
        let [_, qd, qdd] = preprocessing.motion(q, ts)?;
        self.check_direction(&qd)?;
        let columns = InverseDynamics::columns(&qd, qdd, self.offset);
        let force: Vec<f64> = u.iter().map(|v| self.gain * v).collect();
        if force.iter().all(|f| *f == 0.0) {
            return Err(Error::NotExciting {
                channel: "g·u".into(),
                reason: format!(
                    "the force is zero everywhere (gain {}), there is nothing to explain; check the input column and the gain",
                    self.gain
                ),
            });
        }
        let reduced: Vec<Vec<f64>> = columns
            .iter()
            .map(|c| preprocessing.reduce(c))
            .collect::<Result<_>>()?;
        let force = preprocessing.reduce(&force)?;
        let w = DMatrix::from_fn(force.len(), reduced.len(), |i, j| reduced[j][i]);
        // A sample near the floating-point limit (1e308) overflows g·u, the filter or the
        // derivatives: the regression would be NaN.
        if let Some(k) = force.iter().position(|f| !f.is_finite()) {
            return Err(Error::InvalidData(format!(
                "the force g·u overflows at regression row {k}; scale the input or the gain down"
            )));
        }
        if w.iter().any(|v| !v.is_finite()) {
            return Err(Error::InvalidData(
                "the filtered position or its derivatives overflow (a sample near the \
                 floating-point limit?); scale the position data down"
                    .into(),
            ));
        }
        Ok((w, force))
    }

    /// Coulomb friction is only separable from a constant force when the motion reverses.
    fn check_direction(&self, qd: &[f64]) -> Result<()> {
        let inner = &qd[self.border.min(qd.len())..qd.len().saturating_sub(self.border)];
        let (pos, neg) = (
            inner.iter().any(|v| *v > 0.0),
            inner.iter().any(|v| *v < 0.0),
        );
        if !(pos && neg) {
            return Err(Error::NotExciting {
                channel: "position".into(),
                reason: "the velocity never changes sign, so Coulomb friction cannot be told apart from a constant force; move in both directions".into(),
            });
        }
        Ok(())
    }
}

/// σmax/σmin of `w`.
fn condition_number(w: &DMatrix<f64>) -> f64 {
    let sv = w.singular_values();
    let (max, min) = sv
        .iter()
        .fold((0.0f64, f64::INFINITY), |(a, b), s| (a.max(*s), b.min(*s)));
    max / min
}

/// 100·‖f − Wθ‖/‖f‖.
fn relative_error(w: &DMatrix<f64>, force: &[f64], theta: &[f64]) -> f64 {
    let fitted = w * nalgebra::DVector::from_column_slice(theta);
    let err: f64 = force
        .iter()
        .zip(fitted.iter())
        .map(|(a, b)| (a - b).powi(2))
        .sum();
    let norm: f64 = force.iter().map(|a| a * a).sum();
    100.0 * (err / norm).sqrt()
}
