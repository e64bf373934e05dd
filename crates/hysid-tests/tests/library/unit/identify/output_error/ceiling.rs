//! Tests of `hysid::identify::output_error::ceiling`: trial passes that stop once their
//! point is certain to be rejected.

use crate::greybox::{benchmark_simulation, synthetic_record, with_output};
use hysid::data::IdData;
use hysid::identify::greybox::{GreyBox, InitialStates};
use hysid::identify::output_error::OutputErrorProblem;
use hysid::identify::OutputErrorModel;
use hysid::model::greybox::models::BoucWen;
use hysid::numerics::levenberg_marquardt::{
    minimize, LeastSquaresProblem, LmConfig, LmReport, NormalEquations, Trial,
};
use hysid::numerics::Control;
use hysid::Result;
use std::sync::Arc;

/// The Bouc–Wen model (RK4, 4 sub-steps, band-limited input, at rest) and a record of 4 096
/// samples it simulated at its nominal parameters (`synthetic_record`), with a deterministic
/// error of a few µm added (the benchmark's noise level).
fn bouc_wen_record() -> (GreyBox, IdData) {
    let clean = synthetic_record(1, 3);
    let y: Vec<f64> = (clean.experiment(0).output(0).iter().enumerate())
        .map(|(k, v)| v + 7e-6 * ((k as f64 * 0.618_034).fract() - 0.5))
        .collect();
    let data = with_output(&clean, y);
    let at_rest = InitialStates::at_rest(3, 1);
    let gb = GreyBox::new(Arc::new(BoucWen), &data, benchmark_simulation(), at_rest).unwrap();
    (gb, data)
}

/// The free parameters: Bouc–Wen's six (ν fixed), the initial states at rest.
const FREE: [usize; 6] = [0, 1, 2, 3, 4, 5];

/// A trial point far from the minimum (the mass a fifth of its value): with a ceiling far
/// below its S, its pass stops early and returns a lower bound of S above the ceiling; with
/// a ceiling above its S it returns S itself, to the bit, as a pass without a ceiling does.
/// The pass stops only when speculating with split columns, which needs a second core.
#[test]
fn a_trial_pass_stops_once_it_passes_the_ceiling() {
    let (gb, data) = bouc_wen_record();
    let mut problem = OutputErrorProblem::new(&gb, &data, vec![1.0], 0).unwrap();
    problem.speculate(&FREE);
    let mut theta = gb.parameters().values();
    theta[0] *= 0.2;
    let mut r = Vec::new();
    let cost = problem.trial_cost(&theta, &mut r).unwrap();
    assert!(cost.is_finite() && cost > 0.0);
    let with = |ceiling: f64| {
        let trial = Trial {
            predicted: 0.5,
            ceiling,
        };
        problem
            .trial_cost_with(&theta, &mut Vec::new(), trial)
            .unwrap()
    };
    assert_eq!(with(2.0 * cost).to_bits(), cost.to_bits());
    let ceiling = 1e-3 * cost;
    let bound = with(ceiling);
    assert!(bound > ceiling, "bound {bound:e}, ceiling {ceiling:e}");
    assert!(bound <= cost, "bound {bound:e}, S {cost:e}");
    if rayon::current_num_threads() >= 2 {
        // Stopped within a few blocks of residuals, far from the record's end.
        assert!(bound < 0.5 * cost, "bound {bound:e}, S {cost:e}");
    }
}

/// The problem as an engine without ceilings sees it: every trial point's S in full.
struct WithoutCeiling<'p>(&'p OutputErrorProblem<'p>);

impl LeastSquaresProblem for WithoutCeiling<'_> {
    fn n_params(&self) -> usize {
        self.0.n_params()
    }
    fn n_residuals(&self) -> usize {
        self.0.n_residuals()
    }
    fn residuals(&self, theta: &[f64], r: &mut [f64]) -> Result<()> {
        self.0.residuals(theta, r)
    }
    fn residuals_and_cost(&self, theta: &[f64], r: &mut [f64]) -> Result<f64> {
        self.0.residuals_and_cost(theta, r)
    }
    fn trial_cost(&self, theta: &[f64], r: &mut Vec<f64>) -> Result<f64> {
        self.0.trial_cost(theta, r)
    }
    fn normal_equations(&self, theta: &[f64], free: &[usize]) -> Option<Result<NormalEquations>> {
        self.0.normal_equations(theta, free)
    }
    fn cost_floor(&self) -> f64 {
        self.0.cost_floor()
    }
    fn is_exact_fit(&self, cost: f64) -> bool {
        self.0.is_exact_fit(cost)
    }
}

/// Stopping trial passes at their ceiling changes nothing a fit computes: Bouc–Wen from
/// twice its parameters (whose first trial points are rejected) reaches the same iterates,
/// S, normal equations and counts, to the bit, with the ceilings and without them.
#[test]
fn ceilings_leave_the_fit_unchanged() {
    let (gb, data) = bouc_wen_record();
    let params = gb.parameters();
    let mut start = params.values();
    for i in FREE {
        start[i] *= 2.0;
    }
    let lower: Vec<f64> = params.iter().map(|p| p.min).collect();
    let upper: Vec<f64> = params.iter().map(|p| p.max).collect();
    let fit = |without: bool| -> LmReport {
        let mut problem = OutputErrorProblem::new(&gb, &data, vec![1.0], 0).unwrap();
        problem.speculate(&FREE);
        let config = LmConfig::default();
        let mut go_on = |_: &_| Control::Continue;
        match without {
            false => minimize(&problem, &start, &FREE, &lower, &upper, &config, &mut go_on),
            true => {
                let plain = WithoutCeiling(&problem);
                minimize(&plain, &start, &FREE, &lower, &upper, &config, &mut go_on)
            }
        }
        .unwrap()
    };
    let (stopped, whole) = (fit(false), fit(true));
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    // Some trial points were rejected: the engine asked for more than one per iteration.
    assert!(
        stopped.function_evaluations > stopped.iterations + 1,
        "{} evaluations in {} iterations",
        stopped.function_evaluations,
        stopped.iterations
    );
    assert_eq!(stopped.iterations, whole.iterations);
    assert_eq!(stopped.function_evaluations, whole.function_evaluations);
    assert_eq!(stopped.rejected_trials, whole.rejected_trials);
    assert_eq!(bits(&stopped.theta), bits(&whole.theta));
    assert_eq!(stopped.cost.to_bits(), whole.cost.to_bits());
    assert_eq!(bits(stopped.jtj.as_slice()), bits(whole.jtj.as_slice()));
    for (a, b) in stopped.history.iter().zip(&whole.history) {
        assert_eq!(bits(&a.theta), bits(&b.theta));
        assert_eq!(a.cost.to_bits(), b.cost.to_bits());
    }
}
