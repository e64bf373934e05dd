use hysid::estimate::cascade::CascadeStructure;
use hysid::estimate::switching::{classify, fit_with_switching_updates};
use hysid::estimate::{Control, OutputError};
use hysid::examples::CascadeExample;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let pert: f64 = args.get(1).map_or(0.01, |s| s.parse().unwrap());
    let ex = CascadeExample::number(1).unwrap();
    let gen = ex.generate(1, false).unwrap();
    let data = gen.id_data().unwrap();
    let s = CascadeStructure {
        form: ex.truth.hysteresis.form(),
        na: 2,
        nb: 2,
        delay: 1,
        switching: None,
    };
    let mut theta = ex.truth.params();
    for (i, t) in theta.iter_mut().enumerate() {
        *t *= 1.0 + pert * ((i as f64 + 1.0) * 1.3).sin();
    }
    println!("start {:?}", theta);
    let params = s.parameter_set(&theta, &data);
    let make = |sw| CascadeStructure {
        switching: sw,
        ..s.clone()
    };
    let est = OutputError::new();
    // plain with frozen h at truth
    let fit = est
        .estimate(
            &make(Some(classify(&data, 3.0))),
            &data,
            &params,
            &mut |r| {
                println!(
                    "  it {} cost {:.3e} lambda {:.2e} d {:.6}",
                    r.iteration, r.cost, r.lambda, r.theta[3]
                );
                Control::Continue
            },
        )
        .unwrap();
    println!(
        "frozen-true-h: {:?} cost {:.3e} {}",
        fit.parameters.values(),
        fit.report.cost,
        fit.report.termination
    );
    let sw = fit_with_switching_updates(&make, &data, &params, &est, 6, &mut |_| Control::Continue)
        .unwrap();
    println!(
        "fixed point: {:?} cost {:.3e} {} fits {} consistent {}",
        sw.fit.parameters.values(),
        sw.fit.report.cost,
        sw.fit.report.termination,
        sw.fits,
        sw.consistent
    );
}
