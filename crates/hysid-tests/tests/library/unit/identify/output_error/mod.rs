//! Tests of `hysid::identify::output_error`.

mod ceiling;
mod gram;

use hysid::experiments::voros::CascadeExample;
use hysid::identify::output_error::OutputErrorProblem;
use hysid::numerics::levenberg_marquardt::LeastSquaresProblem;

/// The exact-fit test answers as `cost <= cost_floor()` does, also for costs next to the
/// floor, although it sums the record only when a cost comes near the floor's bound: with
/// weights, a skip and a zero first sample, and at the scale of tiny and of large outputs.
#[test]
fn exact_fit_test_is_the_cost_floor_comparison() {
    let ex = CascadeExample::example1();
    let data = ex.generate(3, true).unwrap().id_data().unwrap();
    let structure = super::true_structure(&ex);
    for (weight, skip) in [(1.0, 0), (3.5, 7), (1e-150, 2), (1e140, 0)] {
        let new = || OutputErrorProblem::new(&structure, &data, vec![weight], skip).unwrap();
        let floor = new().cost_floor();
        assert!(floor > 0.0 && floor.is_finite(), "floor {floor:e}");
        for cost in [
            0.0,
            floor.next_down(),
            floor,
            floor.next_up(),
            2.0 * floor,
            1e20 * floor,
            f64::MAX,
        ] {
            // A fresh problem each time: the test runs before anything summed the record.
            assert_eq!(
                new().is_exact_fit(cost),
                cost <= floor,
                "weight {weight:e}, skip {skip}, cost {cost:e}"
            );
        }
    }
}
