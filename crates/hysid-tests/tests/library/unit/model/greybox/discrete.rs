//! Tests of `hysid::model::greybox::discrete`.

use hysid::model::greybox::discrete::*;
use hysid::model::greybox::equation_model::EquationStateSpace;
use hysid::model::greybox::simulate::InputTrack;
use hysid::model::greybox::Simulation;

/// x[k+1] = a·x[k] + b·u[k] under u = 1 from x0: x[k] = aᵏx0 + b(1 − aᵏ)/(1 − a), so
/// ∂x[k]/∂a = k·aᵏ⁻¹x0 + b((1 − aᵏ) − k·aᵏ⁻¹(1 − a))/(1 − a)², ∂x[k]/∂b = (1 − aᵏ)/(1 − a)
/// and ∂x[k]/∂x0 = aᵏ.
#[test]
fn recursion_and_sensitivities_equal_the_closed_form() {
    let text = "[model]\ntime = \"discrete\"\nstates = [\"x\"]\ninputs = [\"u\"]\n\
        outputs = [\"y\"]\n[parameters]\na = 0.8\nb = 0.5\n[equations]\nx = \"a*x + b*u\"\n\
        [output]\ny = \"x\"\n";
    let model = EquationStateSpace::parse(text, "linear").unwrap();
    let (a, b, x0) = (0.8f64, 0.5, 2.0);
    let track = InputTrack::new(&[&[1.0; 30]], &Simulation::default()).unwrap();
    let mut checked = 0;
    let done = simulate_sensitivities(
        &model,
        &[a, b],
        &[x0],
        &track,
        0.1,
        &[0, 1],
        &[0],
        |k, x, s| {
            let kf = k as f64;
            let ak = a.powi(k as i32);
            let akm1 = if k == 0 { 0.0 } else { a.powi(k as i32 - 1) };
            let geometric = (1.0 - ak) / (1.0 - a);
            let expected = [
                ak * x0 + b * geometric,
                kf * akm1 * x0 + b * ((1.0 - ak) - kf * akm1 * (1.0 - a)) / (1.0 - a).powi(2),
                geometric,
                ak,
            ];
            let got = [x[0], s[0], s[1], s[2]];
            for (g, e) in got.iter().zip(expected) {
                assert!(
                    (g - e).abs() <= 1e-13 * e.abs().max(1.0),
                    "k = {k}: {got:?} against {expected:?}"
                );
            }
            checked += 1;
            std::ops::ControlFlow::Continue(())
        },
    )
    .unwrap();
    assert!(done);
    assert_eq!(checked, 30);
}
