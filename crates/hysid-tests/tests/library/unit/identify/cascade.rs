//! Tests of `hysid::identify::cascade`.

use hysid::data::IdData;
use hysid::experiments::voros::CascadeExample;
use hysid::identify::cascade::*;
use hysid::identify::output_error::{OutputErrorModel, SensitivitySink};
use hysid::identify::switching::classify;
use hysid::model::ParameterSet;
use hysid::numerics::levenberg_marquardt::Control;
use hysid::Result;

/// The overlapped stages of a long record make the same fits as the sequential ones:
/// the same candidates and the same final estimate, bit for bit.
#[test]
fn overlapped_stages_equal_sequential_stages() {
    let ex = CascadeExample::example1();
    let data = ex.generate(6, true).unwrap().id_data().unwrap();
    let lin = &ex.truth.linear;
    let mut id =
        CascadeIdentification::new(ex.truth.hysteresis.form(), lin.na(), lin.nb(), lin.delay());
    id.window = 3_000;
    let window = id.window_data(&data).unwrap();
    assert!(data.n_samples() > window.n_samples());
    let (x, y) = (
        window.experiment(0).input(0),
        window.experiment(0).output(0),
    );
    let grid = id.grid.search(x, y).unwrap();
    let mut seen = (0, 0);
    let (kt_a, cand_a, fit_a) = id
        .search_then_fit(&data, &window, &grid, &mut |_| {
            seen.0 += 1;
            Control::Continue
        })
        .unwrap();
    let (kt_b, cand_b, fit_b) = id
        .search_and_fit_overlapped(&data, &window, &grid, &mut |_| {
            seen.1 += 1;
            Control::Continue
        })
        .unwrap();
    assert_eq!(kt_a.map(|k| k.history), kt_b.map(|k| k.history));
    let costs = |c: &[CandidateOutcome]| {
        c.iter()
            .map(|c| (c.cost, c.refined.clone()))
            .collect::<Vec<_>>()
    };
    assert_eq!(costs(&cand_a), costs(&cand_b));
    assert_eq!(fit_a.fit.parameters.values(), fit_b.fit.parameters.values());
    assert_eq!(fit_a.fit.report.cost, fit_b.fit.report.cost);
    assert_eq!(fit_a.fits, fit_b.fits);
    assert!(seen.0 > 0 && seen.1 >= seen.0, "{seen:?}");
}

/// The cascade with only the per-sample sensitivity stream (the estimator's fallback).
struct RowsOnly(CascadeStructure);

impl OutputErrorModel for RowsOnly {
    fn parameters(&self) -> ParameterSet {
        self.0.parameters()
    }
    fn n_outputs(&self) -> usize {
        1
    }
    fn simulate(&self, theta: &[f64], data: &IdData, exp: usize, y: &mut [Vec<f64>]) -> Result<()> {
        self.0.simulate(theta, data, exp, y)
    }
    fn simulate_sensitivities(
        &self,
        theta: &[f64],
        data: &IdData,
        exp: usize,
        free: &[usize],
        sink: &mut SensitivitySink<'_>,
    ) -> Option<Result<()>> {
        self.0.simulate_sensitivities(theta, data, exp, free, sink)
    }
}

/// The normal equations from the block stream equal those from the per-sample stream bit
/// for bit, on a short record and on one long enough to be pipelined, with leading samples
/// left out of the criterion.
#[test]
fn block_normal_equations_equal_row_normal_equations() {
    use hysid::identify::output_error::OutputErrorProblem;
    use hysid::numerics::levenberg_marquardt::LeastSquaresProblem;
    let ex = CascadeExample::example1();
    for len in [3_001, (1 << 16) + 1_234] {
        let data = ex
            .clone()
            .extended(len)
            .generate(4, true)
            .unwrap()
            .id_data()
            .unwrap();
        let structure = super::true_structure(&ex);
        let theta: Vec<f64> = ex.truth.params().iter().map(|v| v * 1.01).collect();
        let free = [0, 1, 3, 4, 6];
        for skip in [0, 9] {
            let rows_only = RowsOnly(structure.clone());
            let by_rows = OutputErrorProblem::new(&rows_only, &data, vec![1.0], skip).unwrap();
            let by_blocks = OutputErrorProblem::new(&structure, &data, vec![1.0], skip).unwrap();
            let a = by_rows.normal_equations(&theta, &free).unwrap().unwrap();
            let b = by_blocks.normal_equations(&theta, &free).unwrap().unwrap();
            assert_eq!(a.jtj, b.jtj, "{len} {skip}");
            assert_eq!(a.jtr, b.jtr, "{len} {skip}");
            assert_eq!(a.cost, b.cost, "{len} {skip}");
        }
    }
}

/// Streamed sensitivities agree with central differences of the simulation (switching
/// frozen, so the output is smooth in every parameter).
#[test]
fn sensitivities_match_finite_differences() {
    for n in [1, 2] {
        let ex = CascadeExample::number(n).unwrap();
        let gen = ex.generate(3, false).unwrap();
        let data = gen.id_data().unwrap();
        let lin = &ex.truth.linear;
        let mut theta = ex.truth.params();
        // Move off the truth so no term vanishes by accident.
        for (i, t) in theta.iter_mut().enumerate() {
            *t *= 1.0 + 0.03 * (i as f64 + 1.0).sin();
        }
        let structure = CascadeStructure {
            form: ex.truth.hysteresis.form(),
            na: lin.na(),
            nb: lin.nb(),
            delay: lin.delay(),
            switching: Some(classify(
                &data,
                theta[ex.truth.hysteresis.form().n_params() - 1],
            )),
        };
        let free: Vec<usize> = (0..theta.len()).collect();
        let p = free.len();
        let len = data.experiment(0).len();
        let mut analytic = vec![vec![0.0; p]; len];
        let mut yhat = vec![0.0; len];
        structure
            .simulate_sensitivities(&theta, &data, 0, &free, &mut |t, y, dy| {
                yhat[t] = y[0];
                analytic[t].copy_from_slice(dy);
                std::ops::ControlFlow::Continue(())
            })
            .unwrap()
            .unwrap();
        let mut y0 = vec![vec![0.0; len]];
        structure.simulate(&theta, &data, 0, &mut y0).unwrap();
        assert!(yhat.iter().zip(&y0[0]).all(|(a, b)| (a - b).abs() < 1e-12));
        for j in 0..p {
            let h = 1e-6 * theta[j].abs().max(1e-3);
            let mut hi = theta.clone();
            hi[j] += h;
            let mut lo = theta.clone();
            lo[j] -= h;
            let (mut yh, mut yl) = (vec![vec![0.0; len]], vec![vec![0.0; len]]);
            structure.simulate(&hi, &data, 0, &mut yh).unwrap();
            structure.simulate(&lo, &data, 0, &mut yl).unwrap();
            let scale = analytic.iter().map(|r| r[j].abs()).fold(0.0, f64::max);
            for t in 0..len {
                let fd = (yh[0][t] - yl[0][t]) / (2.0 * h);
                assert!(
                    (fd - analytic[t][j]).abs() < 1e-6 * scale.max(1.0),
                    "example {n} param {j} t {t}: {fd} vs {}",
                    analytic[t][j]
                );
            }
        }
    }
}
