use hysid::estimate::cascade::CascadeStructure;
use hysid::estimate::switching::fit_with_switching_updates;
use hysid::estimate::{Control, OutputError};
use hysid::examples::CascadeExample;

fn main() {
    let seed: u64 = std::env::args().nth(1).map_or(5, |s| s.parse().unwrap());
    let ex = CascadeExample::number(2).unwrap();
    let gen = ex.generate(seed, true).unwrap();
    let data = gen.id_data().unwrap();
    let s = CascadeStructure {
        form: ex.truth.hysteresis.form(),
        na: 3,
        nb: 3,
        delay: 2,
        switching: None,
    };
    let truth = ex.truth.params();
    let y = ex.truth.simulate(&gen.x).unwrap().y;
    let c: f64 = y.iter().zip(&gen.y).map(|(a, b)| (a - b).powi(2)).sum();
    println!("cost at truth {c:.4e} noise std {:.4e}", gen.noise_std);
    let make = |sw| CascadeStructure {
        switching: sw,
        ..s.clone()
    };
    let est = OutputError::new().max_iterations(500);
    let params = s.parameter_set(&truth, &data);
    let sw = fit_with_switching_updates(&make, &data, &params, &est, 6, &mut |_| Control::Continue)
        .unwrap();
    let g = hysid::estimate::global::GlobalSearch::new(ex.truth.hysteresis.form(), 3, 3, 2);
    let mut starts: Vec<Vec<f64>> = g
        .search(&gen.x, &gen.y)
        .unwrap()
        .iter()
        .map(|c| c.cascade.params())
        .collect();
    starts.push(
        g.evaluate(&gen.x, &gen.y, 0.4, 2.0)
            .unwrap()
            .cascade
            .params(),
    );
    for st in starts {
        let mut st = st.clone();
        let params0 = s.parameter_set(&st, &data);
        st[0] = st[0].min(params0.get(0).max);
        let params0 = s.parameter_set(&st, &data);
        match fit_with_switching_updates(&make, &data, &params0, &est, 0, &mut |_| {
            Control::Continue
        }) {
            Ok(f) => println!(
                "start a={:?} -> cost {:.4e} it {} alpha {:.4} lin {:?}",
                &st[6..],
                f.fit.report.cost,
                f.fit.report.iterations,
                f.fit.parameters.values()[0],
                &f.fit.parameters.values()[6..]
            ),
            Err(e) => println!("err {e}"),
        }
    }
    println!(
        "from truth: {:?} cost {:.4e} {} it {} fit {:?}",
        sw.fit.parameters.values(),
        sw.fit.report.cost,
        sw.fit.report.termination,
        sw.fit.report.iterations,
        sw.fit.fit_percent
    );
}
#[allow(dead_code)]
fn unused() {}
