//! The covariance matrix of a report (`uncertainty.covariance`, `docs/report.md` §1.4): over
//! the parameters with a standard deviation, in the model file's order, symmetric, its
//! diagonal the squared standard deviations, and — for an operator fitted by least squares —
//! equal to σ²(JᵀJ)⁻¹ of a finite-difference Jacobian computed here.

use hysid::data::IdData;
use hysid::identify::hysteresis::{HysteresisIdentification, InitialOutput};
use hysid::identify::operators::family::{fit_operator, Family, FamilyOptions};
use hysid::model::operators::{HysteresisOperator, Orientation, PrandtlIshlinskii};
use hysid::model::{ChForm, ColemanHodgdon};
use hysid::numerics::signal::gaussian_noise;
use hysid::numerics::Control;
use hysid::report::{self, CovarianceSummary, Report};
use nalgebra::DMatrix;

/// The report's covariance, checked to cover exactly the model's parameters with a standard
/// deviation (not fixed), symmetric, with σ² on its diagonal (relative 1e-12).
fn checked_covariance(report: &Report) -> CovarianceSummary {
    let c = report
        .uncertainty
        .as_ref()
        .and_then(|u| u.covariance.clone())
        .expect("the report holds uncertainty.covariance");
    let model = report.model.as_ref().unwrap();
    let with_std: Vec<(String, f64)> = model
        .parameters()
        .iter()
        .filter(|p| !p.fixed)
        .filter_map(|p| p.std.map(|s| (p.name.clone(), s)))
        .collect();
    let names: Vec<String> = with_std.iter().map(|(n, _)| n.clone()).collect();
    assert_eq!(c.parameters, names);
    assert_eq!(c.matrix.len(), names.len());
    for (i, (name, s)) in with_std.iter().enumerate() {
        assert_eq!(c.matrix[i].len(), names.len());
        let d = c.matrix[i][i];
        assert!(
            (d - s * s).abs() <= 1e-12 * s * s,
            "{name}: {d} vs σ² {}",
            s * s
        );
        for j in 0..names.len() {
            assert_eq!(c.matrix[i][j], c.matrix[j][i], "not symmetric at {i}, {j}");
        }
    }
    // The JSON round trip keeps it.
    let back: Report = serde_json::from_str(&report.to_json().unwrap()).unwrap();
    assert_eq!(back.uncertainty.unwrap().covariance.unwrap(), c);
    c
}

/// PI data with known weights on a given grid, seeded Gaussian noise of σ = 0.01.
fn pi_record() -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let r = vec![0.1, 0.3, 0.5];
    let truth = PrandtlIshlinskii::new(
        0.5,
        vec![0.4, 0.3, 0.2],
        r.clone(),
        0.2,
        Orientation::default(),
    )
    .unwrap();
    let n = 1500;
    let u: Vec<f64> = (0..n)
        .map(|k| {
            let t = k as f64 / n as f64;
            (1.0 - 0.6 * t) * (2.0 * std::f64::consts::PI * 5.0 * t).sin()
        })
        .collect();
    let noise = gaussian_noise(n, 0.01, 40).unwrap();
    let y: Vec<f64> = truth
        .simulate(&u)
        .unwrap()
        .iter()
        .zip(&noise)
        .map(|(a, e)| a + e)
        .collect();
    (u, y, r)
}

/// The PI fit's covariance is σ²(JᵀJ)⁻¹, J the central-difference Jacobian of the fitted
/// operator's output with respect to (a0, w₁, w₂, w₃, c) and σ² = RSS/(N − 5): the output is
/// linear in them, so the difference is exact up to rounding (relative 1e-6 asked).
#[test]
fn pi_covariance_is_the_least_squares_covariance() {
    let (u, y, r) = pi_record();
    let options = FamilyOptions {
        threshold_grid: Some(r.clone()),
        orientation: Some(Orientation::default()),
        ..FamilyOptions::default()
    };
    let fitted = fit_operator(Family::Pi, &u, &y, &options).unwrap();
    let data = IdData::siso(1.0, "u", u.clone(), "y", y.clone()).unwrap();
    let simulated = report::operator_simulation(&fitted, &data).unwrap();
    let report = report::operator_report(&fitted, &data, &simulated, vec!["pi".into()]).unwrap();
    let c = checked_covariance(&report);
    assert_eq!(c.parameters, ["a0", "a1", "a2", "a3", "c"]);
    let v = fitted.fit.parameters.values();
    let (a0, w, off) = (v[0], v[1..4].to_vec(), v[7]);
    let output = |a0: f64, w: &[f64], off: f64| {
        PrandtlIshlinskii::new(a0, w.to_vec(), r.clone(), off, Orientation::default())
            .unwrap()
            .simulate(&u)
            .unwrap()
    };
    let h = 1e-4;
    let mut columns = Vec::new();
    for k in 0..5 {
        let shifted = |s: f64| {
            let mut wk = w.clone();
            match k {
                0 => output(a0 + s, &wk, off),
                4 => output(a0, &wk, off + s),
                _ => {
                    wk[k - 1] += s;
                    output(a0, &wk, off)
                }
            }
        };
        let (up, down) = (shifted(h), shifted(-h));
        columns.push(
            up.iter()
                .zip(&down)
                .map(|(a, b)| (a - b) / (2.0 * h))
                .collect::<Vec<_>>(),
        );
    }
    let n = u.len();
    let j = DMatrix::from_fn(n, 5, |i, k| columns[k][i]);
    let yhat = output(a0, &w, off);
    let rss: f64 = y.iter().zip(&yhat).map(|(a, b)| (a - b).powi(2)).sum();
    let numerical = (j.transpose() * &j).try_inverse().unwrap() * (rss / (n - 5) as f64);
    for a in 0..5 {
        for b in 0..5 {
            let scale = (numerical[(a, a)] * numerical[(b, b)]).sqrt();
            assert!(
                (c.matrix[a][b] - numerical[(a, b)]).abs() <= 1e-6 * scale,
                "({a}, {b}): report {} vs numerical {}",
                c.matrix[a][b],
                numerical[(a, b)]
            );
        }
    }
}

/// A Bouc–Wen fit (a search) and the Coleman–Hodgdon hysteresis alone (whose d has a
/// truncated-normal σ, not the asymptotic one) both carry a covariance with σ² on its
/// diagonal, positive semi-definite (eigenvalues ≥ −1e-12 of the largest).
#[test]
fn searched_fits_carry_a_consistent_covariance() {
    let h = ColemanHodgdon::saturated(0.3, 1.0, 0.5, 3.0).unwrap();
    let n = 1200;
    let x: Vec<f64> = (0..n)
        .map(|k| {
            let t = k as f64 / n as f64;
            8.0 * (1.0 - 0.5 * t) * (2.0 * std::f64::consts::PI * 4.0 * t).sin()
        })
        .collect();
    let noise = gaussian_noise(n, 0.02, 41).unwrap();
    let y: Vec<f64> = h
        .simulate(&x, 0.0)
        .unwrap()
        .iter()
        .zip(&noise)
        .map(|(a, e)| a + e)
        .collect();
    let data = IdData::siso(1.0, "x", x.clone(), "y", y.clone()).unwrap();
    let fit = HysteresisIdentification::new(ChForm::Saturated4)
        .estimate(&data, &mut |_| Control::Continue)
        .unwrap();
    let reports = [
        report::hysteresis_report(&fit, &data, vec!["ch4".into()], InitialOutput::Measured)
            .unwrap(),
        {
            let options = FamilyOptions::default();
            let fitted = fit_operator(Family::BoucWen, &x, &y, &options).unwrap();
            let simulated = report::operator_simulation(&fitted, &data).unwrap();
            report::operator_report(&fitted, &data, &simulated, vec!["bw".into()]).unwrap()
        },
    ];
    for report in &reports {
        let c = checked_covariance(report);
        assert!(
            c.parameters.len() >= 2,
            "{}: {:?}",
            report.command,
            c.parameters
        );
        let p = c.parameters.len();
        let m = DMatrix::from_fn(p, p, |i, j| c.matrix[i][j]);
        let eig = m.symmetric_eigenvalues();
        let top = eig.max();
        assert!(
            eig.min() >= -1e-12 * top,
            "{}: eigenvalues {eig}",
            report.command
        );
    }
}
