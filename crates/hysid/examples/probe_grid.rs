use hysid::estimate::global::GlobalSearch;
use hysid::examples::CascadeExample;
use std::time::Instant;

fn main() {
    let n: u8 = std::env::args().nth(1).map_or(2, |s| s.parse().unwrap());
    let seed: u64 = std::env::args().nth(2).map_or(5, |s| s.parse().unwrap());
    let ex = CascadeExample::number(n).unwrap();
    let gen = ex.generate(seed, true).unwrap();
    let l = &ex.truth.linear;
    let g = GlobalSearch::new(ex.truth.hysteresis.form(), l.na(), l.nb(), l.delay());
    let t = Instant::now();
    let c = g.search(&gen.x, &gen.y).unwrap();
    println!("grid {:.3}s", t.elapsed().as_secs_f64());
    for k in c.iter() {
        println!(
            "{:?} eq {:.3e} oe {:.3e}",
            k.cascade.params(),
            k.equation_cost,
            k.output_cost
        );
    }
    let truth = ex.truth.hysteresis.clone();
    let e = g
        .evaluate(&gen.x, &gen.y, truth.alpha(), truth.d())
        .unwrap();
    println!(
        "at truth (alpha,d): {:?} eq {:.3e} oe {:.3e}",
        e.cascade.params(),
        e.equation_cost,
        e.output_cost
    );
}
