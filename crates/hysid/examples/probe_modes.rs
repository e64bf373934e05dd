use hysid::estimate::cascade::{CascadeIdentification, CascadeStructure};
use hysid::estimate::switching::fit_with_switching_updates;
use hysid::estimate::{Control, OutputError};
use hysid::examples::CascadeExample;
use rayon::prelude::*;

fn main() {
    let ex = CascadeExample::number(2).unwrap();
    let rows: Vec<String> = (1..=20u64).into_par_iter().map(|seed| {
        let gen = ex.generate(seed, true).unwrap();
        let data = gen.id_data().unwrap();
        let s = CascadeStructure { form: ex.truth.hysteresis.form(), na: 3, nb: 3, delay: 2, switching: None };
        let make = |sw| CascadeStructure { switching: sw, ..s.clone() };
        let est = OutputError::new().max_iterations(500);
        let ft = fit_with_switching_updates(&make, &data, &s.parameter_set(&ex.truth.params(), &data), &est, 6, &mut |_| Control::Continue).unwrap();
        let id = CascadeIdentification::new(ex.truth.hysteresis.form(), 3, 3, 2).initial(ex.initial.clone());
        let fp = id.estimate(&data, &mut |_| Control::Continue).unwrap();
        format!("seed {seed}: from truth cost {:.3} b2 {:.3} | pipeline cost {:.3} b2 {:.3} std {:.3}", ft.fit.report.cost, ft.fit.parameters.values()[6], fp.output_error.report.cost, fp.model.params()[6], fp.output_error.std()[6])
    }).collect();
    for r in rows {
        println!("{r}");
    }
}
