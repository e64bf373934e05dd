//! Tests of `hysid::identify::greybox::structure`.

use crate::unit::generic_path::GenericPath;
use hysid::data::IdData;
use hysid::identify::greybox::{GreyBox, InitialStates};
use hysid::identify::OutputErrorModel;
use hysid::model::greybox::equation_model::EquationStateSpace;
use hysid::model::greybox::models::BoucWen;
use hysid::model::greybox::{InputInterpolation, Integrator, Simulation, StateSpaceModel};
use hysid::numerics::signal::multisine;
use std::sync::Arc;

/// y and ∂y/∂θ of the sensitivity pass of `model` over `data`, row after row, every model
/// parameter that is not fixed and the three initial states free.
fn pass(model: Arc<dyn StateSpaceModel>, data: &IdData) -> Vec<f64> {
    let sim = Simulation {
        integrator: Integrator::Rk4 { substeps: 4 },
        interpolation: InputInterpolation::BandLimited,
    };
    let initial = InitialStates {
        values: vec![vec![1e-4, -2e-3, 5e-5]],
        estimated: vec![true; 3],
    };
    let gb = GreyBox::new(model, data, sim, initial).unwrap();
    let params = gb.parameters();
    let theta = params.values();
    let free: Vec<usize> = (0..theta.len()).filter(|&i| !params.get(i).fixed).collect();
    let mut rows = Vec::new();
    gb.simulate_sensitivities(&theta, data, 0, &free, &mut |_, y, dy| {
        rows.extend_from_slice(y);
        rows.extend_from_slice(dy);
        std::ops::ControlFlow::Continue(())
    })
    .expect("analytic sensitivities")
    .unwrap();
    rows
}

/// A model whose output is a state says so (constant output Jacobians, the input unread),
/// and the sensitivity pass then asks for the Jacobians once and does not interpolate the
/// input for the output: its rows equal, to the bit, those of the same model seen without
/// these answers (nor its fixed-size path), for the built-in Bouc–Wen model and its
/// equation file.
#[test]
fn an_output_that_is_a_state_is_differentiated_once_per_pass() {
    let u = multisine(1024, 1, 750.0, 5.0, 150.0, 50.0, 11).unwrap();
    let data = IdData::siso(1.0 / 750.0, "u", u, "y", vec![0.0; 1024]).unwrap();
    let file = EquationStateSpace::load(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../examples/equations/bouc_wen.toml"),
    )
    .unwrap();
    // A model of the program's lifetime, as the generic view borrows it.
    let file: &'static EquationStateSpace = Box::leak(Box::new(file));
    let models: [(&'static dyn StateSpaceModel, Arc<dyn StateSpaceModel>); 2] = [
        (&BoucWen, Arc::new(BoucWen)),
        (file, Arc::new(file.clone())),
    ];
    for (model, owned) in models {
        assert!(model.output_jacobians_are_constant() && !model.output_reads_input());
        let told = pass(Arc::new(GenericPath(model)), &data);
        let asked = pass(owned, &data);
        assert_eq!(told.len(), asked.len());
        for (i, (a, b)) in asked.iter().zip(&told).enumerate() {
            assert!(
                a.to_bits() == b.to_bits(),
                "{} element {i}: {a} vs {b}",
                model.kind()
            );
        }
    }
}
