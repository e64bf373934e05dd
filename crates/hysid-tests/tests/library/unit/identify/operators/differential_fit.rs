//! Tests of `hysid::identify::operators::differential_fit` (the driver of the differential
//! fits): its decimation, and the accuracy bars of the four families on 20 000-sample records
//! with 40 dB output noise and a separate validation record — each family's own operator
//! (the fitted model validates within 0.1 point of the true parameters), and Bouc–Wen-type
//! loops with an asymmetry term the symmetric Bouc–Wen can only approximate (within 0.1 point
//! of the best the family can do, found once by the dense search at the end of this file).
//!
//! The records are those of `crates/hysid/examples/differential_records.rs` (the benchmark's).

use crate::unit::test_signals::{training_input, validation_input, with_noise};
use hysid::identify::operators::differential_fit::{decimate, LoopShape};
use hysid::identify::operators::{bouc_wen, dahl, duhem, jiles_atherton};
use hysid::model::operators::differential::{self, InputOde};
use hysid::model::operators::{
    BoucWen, Dahl, Duhem, HysteresisOperator, JilesAtherton, LoopOrientation,
};
use hysid::numerics::metrics::fit_percent;

const N: usize = 20_000;

/// A training and a validation record of `plant`: (u, y, v, y_v), noisy outputs.
type Records = (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>);

fn records(plant: &dyn Fn(&[f64]) -> Vec<f64>, amplitude: f64, seed: u64) -> Records {
    let u = training_input(N, amplitude);
    let v = validation_input(N, amplitude);
    let y = with_noise(&plant(&u), 40.0, seed);
    let yv = with_noise(&plant(&v), 40.0, seed + 100);
    (u, y, v, yv)
}

/// The fitted operator's validation fit % reaches the true operator's within 0.1 point.
fn reaches_the_truth(
    truth: &dyn HysteresisOperator,
    fitted: &dyn HysteresisOperator,
    (v, yv): (&[f64], &[f64]),
) {
    let best = fit_percent(yv, &truth.simulate(v).unwrap());
    let got = fit_percent(yv, &fitted.simulate(v).unwrap());
    eprintln!(
        "{}: validation fit {got:.4} % (true parameters {best:.4} %)",
        truth.family()
    );
    assert!(
        got >= best - 0.1,
        "{}: validation fit {got:.4} % vs {best:.4} % of the true parameters",
        truth.family()
    );
}

fn bouc_wen_truth() -> BoucWen {
    let mut m = BoucWen::new(0.8, 1.2, 2.0, 0.5, 1.0).unwrap();
    m.w0 = 0.05;
    m
}

fn duhem_truth() -> Duhem {
    let mut m = Duhem::new(3.0, 1.5, 0.2, 0.4).unwrap();
    m.y0 = -0.1;
    m
}

fn dahl_truth() -> Dahl {
    let mut m = Dahl::new(12.0, 2.0, 1.8).unwrap();
    m.f0 = 0.3;
    m.orientation = LoopOrientation::CounterClockwise;
    m
}

fn jiles_atherton_truth() -> JilesAtherton {
    let mut m = JilesAtherton::new(2.5e5, 8.0, 5.0, 0.3, 5e-6).unwrap();
    m.m0 = 1e4;
    m
}

/// Number of direction reversals of `u` (sign changes of the non-zero increments, however
/// small: the samples decimation must keep).
fn reversals(u: &[f64]) -> usize {
    let mut last = 0.0;
    let mut count = 0;
    for w in u.windows(2).filter(|w| w[1] != w[0]) {
        let d = (w[1] - w[0]).signum();
        if last != 0.0 && d != last {
            count += 1;
        }
        last = d;
    }
    count
}

#[test]
fn decimation_keeps_every_reversal_and_the_states_there() {
    let u = training_input(N, 1.5);
    let kept = decimate(&u, 1500);
    assert!(kept.len() < 2000, "{}", kept.len());
    assert_eq!((kept[0], kept[kept.len() - 1]), (0, N - 1));
    let ud: Vec<f64> = kept.iter().map(|&k| u[k]).collect();
    assert_eq!(reversals(&ud), reversals(&u));
    let m = bouc_wen_truth();
    let (full, thin) = (m.simulate(&u).unwrap(), m.simulate(&ud).unwrap());
    for (j, &k) in kept.iter().enumerate() {
        // Equal to the integration's tolerance, accumulated over the record.
        assert!(
            (full[k] - thin[j]).abs() < 1e-6,
            "{k}: {} vs {}",
            full[k],
            thin[j]
        );
    }
    // A short record is kept whole.
    assert_eq!(decimate(&u[..100], 1500), (0..100).collect::<Vec<_>>());
}

#[test]
fn loop_shape_sees_range_slope_and_orientation() {
    let u = training_input(2000, 1.5);
    let y = bouc_wen_truth().simulate(&u).unwrap();
    let shape = LoopShape::of(&u, &y);
    assert_eq!(shape.orientation, LoopOrientation::Clockwise);
    assert!(shape.slope > 0.8 && shape.width > 0.0, "{shape:?}");
    assert!((shape.half_span() - 0.5 * (shape.u_range.1 - shape.u_range.0)).abs() < 1e-15);
}

#[test]
fn bouc_wen_reaches_the_true_parameters_validation_fit() {
    let m = bouc_wen_truth();
    let (u, y, v, yv) = records(&|u| m.simulate(u).unwrap(), 1.5, 1);
    let fit = bouc_wen::fit(&u, &y, &Default::default()).unwrap();
    assert!(fit.termination.converged(), "{:?}", fit.termination);
    reaches_the_truth(&m, &fit.model, (&v, &yv));
}

#[test]
fn duhem_reaches_the_true_parameters_validation_fit() {
    let m = duhem_truth();
    let (u, y, v, yv) = records(&|u| m.simulate(u).unwrap(), 1.5, 2);
    let fit = duhem::fit(&u, &y, &Default::default()).unwrap();
    assert!(fit.termination.converged(), "{:?}", fit.termination);
    reaches_the_truth(&m, &fit.model, (&v, &yv));
}

#[test]
fn dahl_reaches_the_true_parameters_validation_fit() {
    let m = dahl_truth();
    let (u, y, v, yv) = records(&|u| m.simulate(u).unwrap(), 1.0, 3);
    let fit = dahl::fit(&u, &y, &Default::default()).unwrap();
    assert!(fit.termination.converged(), "{:?}", fit.termination);
    assert_eq!(fit.model.orientation, m.orientation);
    reaches_the_truth(&m, &fit.model, (&v, &yv));
}

#[test]
fn jiles_atherton_reaches_the_true_parameters_validation_fit() {
    let m = jiles_atherton_truth();
    let (u, y, v, yv) = records(&|u| m.simulate(u).unwrap(), 60.0, 4);
    let fit = jiles_atherton::fit(&u, &y, &Default::default()).unwrap();
    assert!(fit.termination.converged(), "{:?}", fit.termination);
    reaches_the_truth(&m, &fit.model, (&v, &yv));
}

/// Both orientations of each family, other shapes: a second set of truths (longer).
#[test]
#[ignore = "long (several seconds): run by `cargo test --release -- --ignored` and CI"]
fn every_family_reaches_the_truth_in_both_orientations() {
    for kw in [-0.7, 2.0] {
        let m = BoucWen::new(0.3, kw, 8.0, -3.0, 1.0).unwrap();
        let (u, y, v, yv) = records(&|u| m.simulate(u).unwrap(), 1.5, 11);
        let fit = bouc_wen::fit(&u, &y, &Default::default()).unwrap();
        reaches_the_truth(&m, &fit.model, (&v, &yv));
    }
    let m = Duhem::new(10.0, 0.5, -0.3, 2.0).unwrap();
    let (u, y, v, yv) = records(&|u| m.simulate(u).unwrap(), 1.0, 12);
    let fit = duhem::fit(&u, &y, &Default::default()).unwrap();
    reaches_the_truth(&m, &fit.model, (&v, &yv));
    let m = Dahl::new(40.0, 0.5, 1.0).unwrap();
    let (u, y, v, yv) = records(&|u| m.simulate(u).unwrap(), 1.0, 13);
    let fit = dahl::fit(&u, &y, &Default::default()).unwrap();
    reaches_the_truth(&m, &fit.model, (&v, &yv));
    let mut m = jiles_atherton_truth();
    m.orientation = LoopOrientation::Clockwise;
    let (u, y, v, yv) = records(&|u| m.simulate(u).unwrap(), 60.0, 14);
    let fit = jiles_atherton::fit(&u, &y, &Default::default()).unwrap();
    reaches_the_truth(&m, &fit.model, (&v, &yv));
}

/// A Bouc–Wen-type plant in the piezo form with an asymmetry term δ·u in the rate:
/// dw/du = 1 − (β·sign(du·w) + γ)|w| + δ·u, y = k_x·u + k_w·w, w(u\[0\]) = 0.
struct AsymmetricBoucWen {
    kx: f64,
    kw: f64,
    beta: f64,
    gamma: f64,
    delta: f64,
}

impl InputOde for AsymmetricBoucWen {
    fn slope(&self, u: f64, w: f64, d: f64) -> f64 {
        let s = if d * w >= 0.0 { 1.0 } else { -1.0 };
        1.0 - (self.beta * s + self.gamma) * w.abs() + self.delta * u
    }
    fn output(&self, u: f64, w: f64) -> f64 {
        self.kx * u + self.kw * w
    }
    fn initial_state(&self) -> f64 {
        0.0
    }
    fn state_scale(&self) -> f64 {
        1.0 / (self.beta + self.gamma)
    }
    fn max_substep(&self) -> f64 {
        0.25 / (self.beta + self.gamma)
    }
    fn inversion_span(&self) -> f64 {
        1e3
    }
}

/// The issue's case: a static piezo-form Bouc–Wen plant, n = 1, with a small asymmetry term.
fn issue_plant() -> AsymmetricBoucWen {
    AsymmetricBoucWen {
        kx: 1.0,
        kw: -0.6,
        beta: 2.0,
        gamma: 0.4,
        delta: 0.1,
    }
}

/// A stronger asymmetry (the benchmark's `bouc-wen-asym` record).
fn asymmetric_plant() -> AsymmetricBoucWen {
    AsymmetricBoucWen {
        delta: 0.5,
        ..issue_plant()
    }
}

/// The records of an asymmetric plant (seed 5, the benchmark's).
fn asymmetric_records(plant: &AsymmetricBoucWen) -> Records {
    records(&|u| differential::simulate(plant, u).unwrap(), 1.5, 5)
}

/// The best validation fit % of the symmetric Bouc–Wen (n = 1) on the issue's records: the
/// model of the lowest training criterion found by `dense_search_of_the_symmetric_fit`
/// below (run once with `-- --ignored --nocapture`; it printed 98.2891 % at the training
/// criterion 3.130585411, and 92.9742 % at 53.409852760 for the stronger asymmetry).
const ISSUE_BEST_VALIDATION: f64 = 98.2891;
/// The same on the stronger asymmetry's records.
const ASYMMETRIC_BEST_VALIDATION: f64 = 92.9742;

fn reaches_the_family_best(plant: &AsymmetricBoucWen, best: f64) {
    let (u, y, v, yv) = asymmetric_records(plant);
    let fit = bouc_wen::fit(&u, &y, &Default::default()).unwrap();
    assert!(fit.termination.converged(), "{:?}", fit.termination);
    let got = fit_percent(&yv, &fit.model.simulate(&v).unwrap());
    eprintln!("bouc-wen: validation fit {got:.4} % (dense-search best {best:.4} %)");
    assert!(
        got >= best - 0.1,
        "validation fit {got:.4} % vs best {best:.4} %"
    );
}

#[test]
fn bouc_wen_reaches_its_best_on_the_issues_asymmetric_loop() {
    reaches_the_family_best(&issue_plant(), ISSUE_BEST_VALIDATION);
}

#[test]
fn bouc_wen_reaches_its_best_on_a_strongly_asymmetric_loop() {
    reaches_the_family_best(&asymmetric_plant(), ASYMMETRIC_BEST_VALIDATION);
}

/// The dense global search behind the constants above: the training criterion of the
/// symmetric Bouc–Wen (n = 1, w0 = 0) on a 80 × 60 grid of (β + γ, (β − γ)/(β + γ)) with
/// (k_x, k_w) by linear least squares, then a plain finite-difference Levenberg–Marquardt
/// of (k_x, k_w, β, γ, w0) from the 12 best grid points; prints the validation fit % of the
/// lowest criterion.
#[test]
#[ignore = "long (a minute): the one-off dense search behind ISSUE_BEST_VALIDATION"]
fn dense_search_of_the_symmetric_fit() {
    use hysid::identify::operators::differential_fit::linear_fit;
    use hysid::numerics::levenberg_marquardt::{minimize, LeastSquaresProblem, LmConfig};
    struct Problem<'a> {
        u: &'a [f64],
        y: &'a [f64],
    }
    fn model(t: &[f64]) -> hysid::Result<BoucWen> {
        let mut m = BoucWen::new(t[0], t[1], t[2], t[3], 1.0)?;
        m.w0 = t[4];
        Ok(m)
    }
    impl LeastSquaresProblem for Problem<'_> {
        fn n_params(&self) -> usize {
            5
        }
        fn n_residuals(&self) -> usize {
            self.y.len()
        }
        fn residuals(&self, t: &[f64], r: &mut [f64]) -> hysid::Result<()> {
            let yhat = model(t)?.simulate(self.u)?;
            for ((r, y), h) in r.iter_mut().zip(self.y).zip(&yhat) {
                *r = y - h;
            }
            Ok(())
        }
    }
    for (name, plant) in [("issue", issue_plant()), ("asymmetric", asymmetric_plant())] {
        let (u, y, v, yv) = asymmetric_records(&plant);
        let mut scored = Vec::new();
        for i in 0..80 {
            let s = 0.05 * 4000f64.powf(i as f64 / 79.0);
            for j in 0..60 {
                let ratio = j as f64 / 59.0; // (β − γ)/(β + γ) ∈ [0, 1]
                let (beta, gamma) = (0.5 * s * (1.0 + ratio), 0.5 * s * (1.0 - ratio));
                let Ok(m) = BoucWen::new(0.0, 1.0, beta, gamma, 1.0) else {
                    continue;
                };
                let w = differential::states(&m, &u).unwrap();
                if let Some((k, sse)) = linear_fit(&[&u, &w], &y) {
                    scored.push((sse, vec![k[0], k[1], beta, gamma, 0.0]));
                }
            }
        }
        scored.sort_by(|a, b| a.0.total_cmp(&b.0));
        let problem = Problem { u: &u, y: &y };
        let config = LmConfig {
            max_iterations: 300,
            improvement_tolerance: 1e-14,
            ..LmConfig::default()
        };
        let inf = f64::INFINITY;
        let (lower, upper) = ([-inf, -inf, 0.0, -inf, -inf], [inf; 5]);
        let best = scored
            .iter()
            .take(12)
            .filter_map(|(_, t)| {
                minimize(
                    &problem,
                    t,
                    &[0, 1, 2, 3, 4],
                    &lower,
                    &upper,
                    &config,
                    &mut |_| hysid::numerics::Control::Continue,
                )
                .ok()
            })
            .min_by(|a, b| a.cost.total_cmp(&b.cost))
            .unwrap();
        let m = model(&best.theta).unwrap();
        let driver = bouc_wen::fit(&u, &y, &Default::default()).unwrap();
        println!(
            "{name}: dense search cost {:.9} validation {:.4} % ({:?}); driver cost {:.9} \
             validation {:.4} %",
            best.cost,
            fit_percent(&yv, &m.simulate(&v).unwrap()),
            best.theta,
            driver.loss * y.len() as f64,
            fit_percent(&yv, &driver.model.simulate(&v).unwrap()),
        );
    }
}

#[test]
fn an_observer_that_stops_ends_the_fit_and_says_so() {
    use hysid::numerics::{Control, Observer, Termination};
    let m = bouc_wen_truth();
    let u = training_input(4000, 1.5);
    let y = m.simulate(&u).unwrap();
    let options = bouc_wen::BoucWenOptions {
        observer: Observer::new(|p| match p.phase {
            "iteration" => Control::Stop,
            _ => Control::Continue,
        }),
        ..Default::default()
    };
    let fit = bouc_wen::fit(&u, &y, &options).unwrap();
    assert_eq!(fit.termination, Termination::Stopped);
    assert!(!fit.termination.converged());
    // Stopped before the grid: the grid's best point, still a model.
    let options = bouc_wen::BoucWenOptions {
        observer: Observer::new(|p| match p.phase {
            "grid" | "start" => Control::Stop,
            _ => Control::Continue,
        }),
        ..Default::default()
    };
    let fit = bouc_wen::fit(&u, &y, &options).unwrap();
    assert_eq!(fit.termination, Termination::Stopped);
    assert!(fit.fit_percent.is_finite());
}

#[test]
fn a_flat_region_is_not_convergence() {
    use hysid::numerics::Termination;
    let t = Termination::FlatRegion { expected: 1e-3 };
    assert!(!t.converged());
    assert!(t.to_string().contains("flat region"), "{t}");
    let code = serde_json::to_value(&t).unwrap();
    assert_eq!(code["code"], "flat_region");
}

/// A local search that stalls in a valley (its criterion down by less than 0.1 % over 30
/// iterations, `STALL_WINDOW`) stops there instead of running to its iteration limit; the
/// refinement on the full record takes the best point on. On the vendored piezo record
/// Jiles–Atherton took 575 iterations before the rule and takes 201 now, to the same fit
/// (96.983 %); Bouc–Wen 1200 → 987 (98.6935 → 98.6934 %).
#[test]
fn a_stalled_local_search_stops_instead_of_grinding() {
    use crate::unit::test_signals::piezo_record;
    use hysid::identify::operators::{fit_operator, Family, FamilyOptions};
    let (u, y) = piezo_record();
    let fitted = fit_operator(Family::JilesAtherton, &u, &y, &FamilyOptions::default()).unwrap();
    println!(
        "jiles-atherton: {} iterations, fit {:.4} %",
        fitted.fit.iterations, fitted.fit.fit_percent
    );
    assert!(fitted.fit.iterations <= 300, "{}", fitted.fit.iterations);
    assert!(fitted.fit.fit_percent > 96.98, "{}", fitted.fit.fit_percent);
}

/// A fit run in units of unit size quotes a divergence's input in the record's units: the
/// integrator's "at u = u′" becomes u′·sᵤ; other errors pass unchanged.
#[test]
fn a_divergence_is_quoted_in_the_records_units() {
    use hysid::identify::operators::differential_fit::error_in_record_units;
    use hysid::Error;
    let e = Error::Diverged {
        index: 515,
        reason: "integration in the input at u = 1.25: too many sub-steps".into(),
    };
    let back = error_in_record_units(e, 64.0).to_string();
    assert!(back.contains("at u = 80: too many sub-steps"), "{back}");
    assert!(back.contains("515"), "{back}");
    let other = Error::Diverged {
        index: 3,
        reason: "the output is not finite".into(),
    };
    assert!(error_in_record_units(other, 64.0)
        .to_string()
        .contains("the output is not finite"));
}

/// A refinement that stalls in a valley (its criterion down by less than 10⁻⁶ over 30
/// iterations, `REFINE_STALL_DECREASE`) stops there, with no restart, reported as a flat
/// region. On the simulated magnet record of `fixtures/records` (170 set points, a loop 1 %
/// of the range wide) Jiles–Atherton took 603 iterations before the rule, ending at its
/// iteration limit with 95.599 %, and takes 348 now, for 95.573 %.
#[test]
#[ignore = "long (several seconds): run by `cargo test --release -- --ignored` and CI"]
fn a_stalled_refinement_stops_instead_of_grinding() {
    use hysid::identify::operators::{fit_operator, Family, FamilyOptions};
    use hysid::numerics::Termination;
    let (u, y) = crate::unit::test_signals::magnet_set_points();
    let fitted = fit_operator(Family::JilesAtherton, &u, &y, &FamilyOptions::default()).unwrap();
    println!(
        "jiles-atherton: {} iterations, fit {:.4} %, {:?}",
        fitted.fit.iterations, fitted.fit.fit_percent, fitted.fit.termination
    );
    assert!(fitted.fit.iterations <= 450, "{}", fitted.fit.iterations);
    assert!(fitted.fit.fit_percent > 95.5, "{}", fitted.fit.fit_percent);
    assert!(
        matches!(fitted.fit.termination, Termination::FlatRegion { .. }),
        "{:?}",
        fitted.fit.termination
    );
}
