use hysid::estimate::key_term::KeyTermSeparation;
use hysid::examples::CascadeExample;
use hysid::model::ColemanHodgdon;

fn main() {
    let n: u8 = std::env::args().nth(1).map_or(1, |s| s.parse().unwrap());
    let pert: f64 = std::env::args().nth(2).map_or(0.01, |s| s.parse().unwrap());
    let relax: f64 = std::env::args().nth(3).map_or(1.0, |s| s.parse().unwrap());
    let ex = CascadeExample::number(n).unwrap();
    let data = ex.generate(1, false).unwrap().id_data().unwrap();
    let h = &ex.truth.hysteresis;
    let init = if pert < 0.0 {
        ex.initial.clone()
    } else {
        ColemanHodgdon::from_params(
            h.form(),
            &h.params()
                .iter()
                .map(|p| p * (1.0 + pert))
                .collect::<Vec<_>>(),
        )
        .unwrap()
    };
    let l = &ex.truth.linear;
    let k = KeyTermSeparation::new(h.form(), l.na(), l.nb(), l.delay())
        .relaxation(relax)
        .max_iterations(200);
    let fit = k.estimate(&data, &init).unwrap();
    for (i, p) in fit.history.iter().enumerate().step_by(10) {
        println!(
            "{i}: {:?}",
            p.iter()
                .map(|v| (v * 1e4).round() / 1e4)
                .collect::<Vec<_>>()
        );
    }
    println!(
        "{} costs first {:?} last {:?}",
        fit.termination,
        &fit.costs[..3],
        fit.costs.last()
    );
}
