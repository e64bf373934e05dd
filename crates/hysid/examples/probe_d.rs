use hysid::estimate::cascade::CascadeIdentification;
use hysid::estimate::Control;
use hysid::examples::CascadeExample;
use rayon::prelude::*;

fn main() {
    let n: u8 = std::env::args().nth(1).map_or(2, |s| s.parse().unwrap());
    let ex = CascadeExample::number(n).unwrap();
    let s = &ex.truth;
    let rows: Vec<String> = (1..=20u64).into_par_iter().map(|seed| {
        let data = ex.generate(seed, true).unwrap().id_data().unwrap();
        let id = CascadeIdentification::new(s.hysteresis.form(), s.linear.na(), s.linear.nb(), s.linear.delay()).initial(ex.initial.clone());
        let fit = id.estimate(&data, &mut |_| Control::Continue).unwrap();
        let t = &fit.threshold;
        format!("seed {seed:2}: err {:+.5} lo-d {:+.5} hi-d {:+.5} width {:.5} smooth {:.5} post {:.5} cost {:.3}", fit.model.hysteresis.d() - s.hysteresis.d(), t.lower - s.hysteresis.d(), t.upper - s.hysteresis.d(), t.upper - t.lower, t.smooth_std, t.std, fit.output_error.report.cost)
    }).collect();
    for r in rows {
        println!("{r}");
    }
}
