use hysid::estimate::cascade::{CascadeIdentification, CascadeStructure};
use hysid::estimate::switching::classify;
use hysid::estimate::{Control, OutputError};
use hysid::examples::CascadeExample;

fn main() {
    let seed: u64 = std::env::args().nth(1).map_or(14, |s| s.parse().unwrap());
    let ex = CascadeExample::number(2).unwrap();
    let data = ex.generate(seed, true).unwrap().id_data().unwrap();
    let id = CascadeIdentification::new(ex.truth.hysteresis.form(), 3, 3, 2);
    let fit = id.estimate(&data, &mut |_| Control::Continue).unwrap();
    let est = fit.model.params();
    println!(
        "fit cost {:.4} d {:.5}",
        fit.output_error.report.cost, est[5]
    );
    let s = CascadeStructure {
        form: ex.truth.hysteresis.form(),
        na: 3,
        nb: 3,
        delay: 2,
        switching: None,
    };
    for dd in [
        2.0 - 0.001,
        2.0,
        2.0 + 0.001,
        2.002,
        2.003,
        2.004,
        2.005,
        2.0055,
        est[5],
    ] {
        let mut p = s.parameter_set(&est, &data);
        let d = p.get_mut(5);
        d.value = dd;
        d.fixed = true;
        let st = CascadeStructure {
            switching: Some(classify(&data, dd)),
            ..s.clone()
        };
        let f = OutputError::new()
            .estimate(&st, &data, &p, &mut |_| Control::Continue)
            .unwrap();
        println!("d fixed {dd:.5}: cost {:.4}", f.report.cost);
    }
}
