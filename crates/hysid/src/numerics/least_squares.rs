//! Linear least squares with covariance and a rank check.
//!
//! Solves min ‖Φθ − y‖₂ by a Householder QR of the column-scaled regressor matrix
//! (scaling each column to unit norm makes the rank test independent of units). The
//! covariance is σ²(ΦᵀΦ)⁻¹ with σ² = ‖y − Φθ‖²/(N − p), the textbook estimate under white
//! equation errors (Ljung, System Identification, 2nd ed., §7.3).

use crate::{Error, Result};
use nalgebra::{DMatrix, DVector};

mod streamed;

/// Largest acceptable condition number of the column-scaled regressor matrix.
pub const MAX_CONDITION: f64 = 1e12;

/// The solution of a linear least-squares problem.
#[derive(Clone, Debug)]
pub struct LsSolution {
    /// The estimate θ̂.
    pub theta: DVector<f64>,
    /// Residual sum of squares ‖y − Φθ̂‖².
    pub residual_ss: f64,
    /// Number of equations N.
    pub n_equations: usize,
    /// Covariance σ²(ΦᵀΦ)⁻¹ with σ² = residual_ss/(N − p).
    pub covariance: DMatrix<f64>,
    /// Condition number of the column-scaled regressor matrix.
    pub condition_number: f64,
}

impl LsSolution {
    /// Standard deviations, the square roots of the covariance diagonal.
    pub fn std(&self) -> Vec<f64> {
        (0..self.theta.len())
            .map(|i| self.covariance[(i, i)].max(0.0).sqrt())
            .collect()
    }

    /// σ², the residual variance estimate.
    pub fn sigma2(&self) -> f64 {
        self.residual_ss / (self.n_equations - self.theta.len()).max(1) as f64
    }
}

/// Solves min ‖Φθ − y‖₂. `names` (one per column) make the error messages specific.
///
/// Errors with [`Error::TooFewSamples`] when N < p and [`Error::DependentRegressors`] when a
/// column is zero or the columns are (numerically) dependent, naming the columns involved.
///
/// ```
/// use nalgebra::DMatrix;
/// let phi = DMatrix::from_row_slice(3, 2, &[1.0, 0.0, 1.0, 1.0, 1.0, 2.0]);
/// let sol = hysid::numerics::least_squares(&phi, &[1.0, 3.0, 5.0], &["c", "k"]).unwrap();
/// assert!((sol.theta[0] - 1.0).abs() < 1e-12 && (sol.theta[1] - 2.0).abs() < 1e-12);
/// ```
pub fn least_squares(phi: &DMatrix<f64>, y: &[f64], names: &[&str]) -> Result<LsSolution> {
    let (n, p) = phi.shape();
    let ScaledQr {
        qr,
        r,
        scale,
        condition_number,
    } = factor(phi, names)?;
    let yv = DVector::from_column_slice(y);
    let qty = qr.q().transpose() * &yv;
    let theta_scaled = r
        .solve_upper_triangular(&qty)
        .ok_or_else(|| Error::Singular("triangular factor is singular".into()))?;
    let theta = DVector::from_iterator(p, theta_scaled.iter().zip(&scale).map(|(t, s)| t / s));
    let residual = &yv - phi * &theta;
    let residual_ss = residual.norm_squared();
    let r_inv = r
        .try_inverse()
        .ok_or_else(|| Error::Singular("triangular factor is singular".into()))?;
    let sigma2 = residual_ss / (n - p) as f64;
    let mut covariance = &r_inv * r_inv.transpose() * sigma2;
    for i in 0..p {
        for j in 0..p {
            covariance[(i, j)] /= scale[i] * scale[j];
        }
    }
    Ok(LsSolution {
        theta,
        residual_ss,
        n_equations: n,
        covariance,
        condition_number,
    })
}

/// θ̂ and the residual sum of squares ‖y − Φθ̂‖² of min ‖Φθ − y‖₂, for iterations that need
/// nothing else (no covariance), with the errors of [`least_squares`] and the same rank test
/// on the column-scaled triangular factor.
///
/// The factor comes from the Householder QR of the augmented matrix [Φ y] formed block of
/// rows by block of rows (see the `streamed` module): the record is read once, Qᵀy is the
/// factor's last column and ‖y − Φθ̂‖² its corner squared (Golub & Van Loan, *Matrix
/// Computations*, 4th ed., §5.3.3), instead of a column-by-column QR that sweeps the whole
/// matrix once per column, then Q's reflections applied to y and the residual formed anew.
/// The column scaling of [`least_squares`] (each column to unit norm) is applied to the
/// factor (‖Φeⱼ‖ = ‖Reⱼ‖, and R·diag(1/‖Φeⱼ‖) is the factor of the scaled Φ), so the rank
/// decision is the same. The estimate agrees with [`least_squares`]'s to rounding.
pub fn least_squares_estimate(
    phi: &DMatrix<f64>,
    y: &[f64],
    names: &[&str],
) -> Result<(DVector<f64>, f64)> {
    let (n, p) = phi.shape();
    enough_rows(n, p)?;
    let augmented = streamed::factor_augmented(phi, y);
    let r = DMatrix::from_fn(p, p, |i, j| if i <= j { augmented.at(i, j) } else { 0.0 });
    let scale: Vec<f64> = (0..p).map(|j| r.column(j).norm()).collect();
    let name = column_name(names);
    excited(&scale, &name)?;
    let scaled = unscaled_columns(r, &scale);
    condition_number(&scaled, &name)?;
    let qty = DVector::from_fn(p, |i, _| augmented.at(i, p));
    let theta_scaled = scaled
        .solve_upper_triangular(&qty)
        .ok_or_else(|| Error::Singular("triangular factor is singular".into()))?;
    let theta = DVector::from_iterator(p, theta_scaled.iter().zip(&scale).map(|(t, s)| t / s));
    let rho = augmented.at(p, p);
    Ok((theta, rho * rho))
}

/// The QR factorisation of the column-scaled Φ that passed the rank test, with what the
/// solvers need of it.
struct ScaledQr {
    qr: nalgebra::linalg::QR<f64, nalgebra::Dyn, nalgebra::Dyn>,
    /// The p × p triangular factor R.
    r: DMatrix<f64>,
    /// The column norms of Φ.
    scale: Vec<f64>,
    condition_number: f64,
}

/// Scales Φ's columns to unit norm and factors the result; errors as [`least_squares`]
/// documents.
fn factor(phi: &DMatrix<f64>, names: &[&str]) -> Result<ScaledQr> {
    let (n, p) = phi.shape();
    enough_rows(n, p)?;
    let name = column_name(names);
    let scale: Vec<f64> = (0..p).map(|j| phi.column(j).norm()).collect();
    excited(&scale, &name)?;
    let qr = unscaled_columns(phi.clone(), &scale).qr();
    let r = qr.r();
    let condition_number = condition_number(&r, &name)?;
    Ok(ScaledQr {
        qr,
        r,
        scale,
        condition_number,
    })
}

/// `m` with column j divided by `scale[j]`.
fn unscaled_columns(mut m: DMatrix<f64>, scale: &[f64]) -> DMatrix<f64> {
    for (j, s) in scale.iter().enumerate() {
        m.column_mut(j).unscale_mut(*s);
    }
    m
}

/// N ≥ p + 1 rows for p parameters, else [`Error::TooFewSamples`].
fn enough_rows(n: usize, p: usize) -> Result<()> {
    if n < p + 1 {
        return Err(Error::TooFewSamples {
            samples: n,
            parameters: p,
            needed: p + 1,
        });
    }
    Ok(())
}

/// The name of column j for messages: `names[j]`, else "column j+1".
fn column_name<'a>(names: &'a [&str]) -> impl Fn(usize) -> String + 'a {
    move |j| {
        names
            .get(j)
            .map_or_else(|| format!("column {}", j + 1), |s| s.to_string())
    }
}

/// [`Error::DependentRegressors`] naming the first column whose norm (in `scale`) is zero or
/// not finite.
fn excited(scale: &[f64], name: &dyn Fn(usize) -> String) -> Result<()> {
    match scale.iter().position(|&s| s == 0.0 || !s.is_finite()) {
        Some(j) => Err(Error::DependentRegressors {
            columns: format!("'{}'", name(j)),
            problem: "zero or not finite over the whole record".into(),
            condition_number: f64::INFINITY,
        }),
        None => Ok(()),
    }
}

/// The condition number of the column-scaled triangular factor `r` (by its singular
/// values), or [`Error::DependentRegressors`] naming the columns involved when it reaches
/// [`MAX_CONDITION`].
fn condition_number(r: &DMatrix<f64>, name: &dyn Fn(usize) -> String) -> Result<f64> {
    let svd = r.clone().svd(false, true);
    let smax = svd.singular_values.max();
    let smin = svd.singular_values.min();
    let condition_number = smax / smin;
    if condition_number.is_nan() || condition_number >= MAX_CONDITION {
        return Err(Error::DependentRegressors {
            columns: dependent_columns(&svd, name),
            problem: format!(
                "(nearly) linearly dependent (condition number {condition_number:.3e})"
            ),
            condition_number,
        });
    }
    Ok(condition_number)
}

/// Names the columns that dominate the right singular vector of the smallest singular value.
fn dependent_columns(
    svd: &nalgebra::SVD<f64, nalgebra::Dyn, nalgebra::Dyn>,
    name: &dyn Fn(usize) -> String,
) -> String {
    let Some(v_t) = svd.v_t.as_ref() else {
        return "(unknown)".into();
    };
    let k = svd.singular_values.imin();
    let row = v_t.row(k);
    let largest = row.amax();
    let involved: Vec<String> = (0..row.len())
        .filter(|&j| row[j].abs() > 0.2 * largest)
        .map(|j| format!("'{}'", name(j)))
        .collect();
    involved.join(", ")
}
