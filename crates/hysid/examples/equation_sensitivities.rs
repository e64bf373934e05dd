//! One simulation of the Bouc–Wen oscillator on the benchmark's training record (40 960
//! samples, RK4 × 4, band-limited input), with the sensitivities to the six free parameters
//! or without, by the built-in model or by `examples/equations/bouc_wen.toml`: the unit of
//! work the fit repeats, for instruction counts
//! (`valgrind --tool=callgrind target/release/examples/equation_sensitivities file sens`).
//!
//! Usage: `equation_sensitivities built-in|file sens|plain [REPEATS]`.

use hysid::data::{CsvSpec, IdData};
use hysid::identify::greybox::{GreyBox, InitialStates};
use hysid::identify::OutputErrorModel;
use hysid::model::greybox::equation_model::EquationStateSpace;
use hysid::model::greybox::models::BoucWen;
use hysid::model::greybox::{InputInterpolation, Integrator, Simulation, StateSpaceModel};
use std::path::Path;
use std::sync::Arc;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let (which, what) = match (args.get(1), args.get(2)) {
        (Some(a), Some(b)) => (a.as_str(), b.as_str()),
        _ => return Err("usage: equation_sensitivities built-in|file sens|plain [REPEATS]".into()),
    };
    let repeats: usize = args.get(3).map_or(Ok(1), |r| r.parse())?;
    let root = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."));
    let spec = CsvSpec {
        inputs: vec!["u_N".into()],
        outputs: vec!["y_m".into()],
        time: None,
        ts: None,
        ..CsvSpec::default()
    };
    let data = IdData::from_csv(
        &root.join("data/bouc-wen/train_multisine_5periods.csv"),
        &spec,
    )?;
    let model: Arc<dyn StateSpaceModel> = match which {
        "built-in" => Arc::new(BoucWen),
        "file" => Arc::new(EquationStateSpace::load(
            &root.join("examples/equations/bouc_wen.toml"),
        )?),
        other => return Err(format!("unknown model '{other}'").into()),
    };
    let simulation = Simulation {
        integrator: Integrator::Rk4 { substeps: 4 },
        interpolation: InputInterpolation::BandLimited,
    };
    let gb = GreyBox::new(model, &data, simulation, InitialStates::at_rest(3, 1))?;
    let theta = gb.parameters().values();
    let free: Vec<usize> = (0..6).collect();
    let mut check = 0.0;
    for _ in 0..repeats {
        match what {
            "sens" => gb
                .simulate_sensitivities(&theta, &data, 0, &free, &mut |_, y, s| {
                    check += y[0] + s[0];
                    std::ops::ControlFlow::Continue(())
                })
                .ok_or("no sensitivities")??,
            "plain" => {
                let mut y = vec![vec![0.0; data.experiment(0).len()]];
                gb.simulate(&theta, &data, 0, &mut y)?;
                check += y[0].iter().sum::<f64>();
            }
            other => return Err(format!("unknown mode '{other}'").into()),
        }
    }
    println!("{which} {what}: checksum {check:e}");
    Ok(())
}
