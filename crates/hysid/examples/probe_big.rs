use hysid::estimate::cascade::CascadeIdentification;
use hysid::estimate::Control;
use hysid::examples::CascadeExample;
use std::time::Instant;

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .map_or(1_000_000, |s| s.parse().unwrap());
    let ex = CascadeExample::example1().extended(n);
    let t = Instant::now();
    let data = ex.generate(1, true).unwrap().id_data().unwrap();
    println!("generate {:.3}", t.elapsed().as_secs_f64());
    let s = &ex.truth;
    let t = Instant::now();
    let id = CascadeIdentification::new(s.hysteresis.form(), 2, 2, 1);
    let fit = id
        .estimate(&data, &mut |r| {
            eprintln!(
                "  it {} cost {:.9e} lambda {:.2e} d {:.6}",
                r.iteration, r.cost, r.lambda, r.theta[3]
            );
            Control::Continue
        })
        .unwrap();
    println!(
        "identify {:.3} params {:?} iters {} term {}",
        t.elapsed().as_secs_f64(),
        fit.model.params(),
        fit.output_error.report.iterations,
        fit.output_error.report.termination
    );
}
