use hysid::estimate::cascade::CascadeIdentification;
use hysid::estimate::Control;
use hysid::examples::CascadeExample;
use rayon::prelude::*;

fn main() {
    let n: u8 = std::env::args().nth(1).map_or(1, |s| s.parse().unwrap());
    let ex = CascadeExample::number(n).unwrap();
    let s = &ex.truth;
    let truth = s.params();
    let res: Vec<(Vec<f64>, Vec<f64>, f64)> = (1..=20u64)
        .into_par_iter()
        .map(|seed| {
            let data = ex.generate(seed, true).unwrap().id_data().unwrap();
            let id = CascadeIdentification::new(
                s.hysteresis.form(),
                s.linear.na(),
                s.linear.nb(),
                s.linear.delay(),
            )
            .initial(ex.initial.clone());
            let mut id = id;
            if let Ok(b) = std::env::var("BOOT") {
                id.uncertainty = hysid::estimate::Uncertainty::Bootstrap(b.parse().unwrap());
            }
            id.bootstrap_seed = seed;
            let fit = id.estimate(&data, &mut |_| Control::Continue).unwrap();
            (fit.model.params(), fit.std(), fit.elapsed_s)
        })
        .collect();
    let p = truth.len();
    let mut inside = 0;
    let mut total = 0;
    for i in 0..p {
        let est: Vec<f64> = res.iter().map(|r| r.0[i]).collect();
        let mean = est.iter().sum::<f64>() / 20.0;
        let spread = (est.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / 19.0).sqrt();
        let mstd = res.iter().map(|r| r.1[i]).sum::<f64>() / 20.0;
        let ins = res
            .iter()
            .filter(|r| (r.0[i] - truth[i]).abs() <= 3.0 * r.1[i])
            .count();
        inside += ins;
        total += 20;
        println!("param {i}: true {:.4} mean {:.5} bias/spread {:.2} spread {:.3e} mean std {:.3e} ratio {:.2} inside3 {}/20", truth[i], mean, (mean-truth[i])/spread, spread, mstd, mstd/spread, ins);
    }
    println!(
        "inside {inside}/{total}; time mean {:.3}",
        res.iter().map(|r| r.2).sum::<f64>() / 20.0
    );
}
