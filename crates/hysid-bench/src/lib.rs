//! Criterion benchmarks of `hysid` and `hysid-equations`, one file per subject in `benches/`
//! (`cargo bench -p hysid-bench --bench greybox`, …; `docs/performance.md` lists them with
//! their figures).
//!
//! They live in a crate of their own so that `cargo test` of the library crates does not
//! compile criterion and its dependencies. This library holds only what two of them share:
//! the streaming models of the real-time figures ([`stream_models`]), timed in the library
//! by `benches/stream.rs` and, exported as C, by `bench/export_steps.sh` (whose model files
//! `examples/stream_models.rs` writes).

use hysid::model::greybox::models;
use hysid::model::greybox::{InputInterpolation, Integrator, Simulation};
use hysid::model::operators::{OperatorModel, Orientation, PrandtlIshlinskii, Preisach};
use hysid::model::saved::FittedGreyBox;
use hysid::model::saved::FittedModel;

/// Samples of [`stream_input`] per period (the library bench's batch).
pub const STREAM_SAMPLES: usize = 10_000;

/// The sample time the streaming models step at: the Bouc–Wen benchmark's 750 Hz (the
/// operators are rate-independent and do not depend on it).
pub const STREAM_TS: f64 = 1.0 / 750.0;

/// Sample `k` of the streaming benches' input: a decaying oscillation with nested minor
/// loops, within ±2.5, periodic in `k` with period [`STREAM_SAMPLES`]. `bench/export_step_bench.c`
/// computes the same formula.
pub fn stream_input(k: usize) -> f64 {
    let t = (k % STREAM_SAMPLES) as f64 / STREAM_SAMPLES as f64;
    2.0 * (1.0 - 0.5 * t) * (40.0 * t).sin() + 0.3 * (370.0 * t).sin()
}

/// An operator as a fitted model (no standard deviations).
pub fn operator(model: OperatorModel) -> FittedModel {
    let n = model.as_operator().parameters().len();
    FittedModel::operator(model, vec![f64::NAN; n])
}

/// The streaming models, by name: the deployment issue's three reference models — a PI
/// operator with 20 play operators (`pi_20_plays`), a 20-level (210-cell) Preisach plane
/// (`preisach_20x20`), the Bouc–Wen grey-box oscillator with RK4, 4 sub-steps and a
/// zero-order hold (`bouc_wen_greybox_rk4_4`) — then every operator family's registry
/// example (`example_FAMILY`).
///
/// # Panics
///
/// If a model cannot be constructed (its parameters are constants that are valid).
pub fn stream_models() -> Vec<(String, FittedModel)> {
    let r: Vec<f64> = (1..=20).map(|i| 0.1 * i as f64).collect();
    let a: Vec<f64> = (0..20).map(|i| 0.05 + 0.01 * i as f64).collect();
    let pi = PrandtlIshlinskii::new(0.8, a, r, 0.0, Orientation::default()).unwrap();
    let w: Vec<f64> = (0..210).map(|k| 0.01 + 0.001 * (k % 13) as f64).collect();
    let preisach = Preisach::new(-2.5, 2.5, 20, w, 0.2, 0.0, Orientation::default()).unwrap();
    let bouc_wen = models::by_kind("bouc_wen").unwrap();
    let parameters = bouc_wen.parameters();
    let p = parameters.len();
    let grey_box = FittedModel::GreyBox(FittedGreyBox {
        kind: "bouc_wen".into(),
        parameters,
        std: vec![f64::NAN; p],
        simulation: Simulation {
            integrator: Integrator::Rk4 { substeps: 4 },
            interpolation: InputInterpolation::ZeroOrderHold,
        },
        initial_state: vec![0.0; bouc_wen.states().len()],
    });
    let mut out = vec![
        ("pi_20_plays".to_string(), operator(OperatorModel::Pi(pi))),
        (
            "preisach_20x20".to_string(),
            operator(OperatorModel::Preisach(preisach)),
        ),
        ("bouc_wen_greybox_rk4_4".to_string(), grey_box),
    ];
    for example in OperatorModel::examples().unwrap() {
        let name = format!("example_{}", example.family().name());
        out.push((name, operator(example)));
    }
    out
}
