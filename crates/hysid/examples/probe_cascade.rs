use hysid::estimate::cascade::CascadeIdentification;
use hysid::estimate::Control;
use hysid::examples::CascadeExample;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: u8 = args.get(1).map_or(1, |s| s.parse().unwrap());
    let noisy = args.get(2).is_some_and(|s| s == "noisy");
    let seed: u64 = args.get(3).map_or(1, |s| s.parse().unwrap());
    let ex = CascadeExample::number(n).unwrap();
    let gen = ex.generate(seed, noisy).unwrap();
    let data = gen.id_data().unwrap();
    let s = &ex.truth;
    let t = Instant::now();
    let id = CascadeIdentification::new(
        s.hysteresis.form(),
        s.linear.na(),
        s.linear.nb(),
        s.linear.delay(),
    )
    .initial(ex.initial.clone());
    let fit = id.estimate(&data, &mut |_| Control::Continue).unwrap();
    println!("elapsed {:.3}s", t.elapsed().as_secs_f64());
    let truth = s.params();
    let est = fit.model.params();
    let std = fit.output_error.std();
    for i in 0..truth.len() {
        println!(
            "{:>6} true {:>10.6} est {:>12.8} std {:>10.2e} z {:>6.2}",
            fit.output_error.parameters.get(i).name,
            truth[i],
            est[i],
            std[i],
            (est[i] - truth[i]) / std[i]
        );
    }
    println!(
        "term {} iters {} fit {:?}",
        fit.output_error.report.termination,
        fit.output_error.report.iterations,
        fit.output_error.fit_percent
    );
    if let Some(k) = &fit.key_term {
        println!(
            "kts: {} iters {} last {:?}",
            k.termination,
            k.history.len() - 1,
            k.history.last()
        );
    }
    for c in &fit.candidates {
        println!(
            "cand {} cost {:.3e} start {:?}",
            c.origin,
            c.cost,
            &c.start[..4]
        );
    }
}
