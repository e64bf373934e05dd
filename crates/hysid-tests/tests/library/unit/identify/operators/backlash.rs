//! Tests of `hysid::identify::operators::backlash`.

use hysid::identify::operators::backlash::*;
use hysid::model::operators::HysteresisOperator;
use hysid::model::operators::{Backlash, Orientation};
use hysid::numerics::metrics;
use rand::rngs::Xoshiro256PlusPlus;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};

fn input(n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| {
            let t = k as f64 / n as f64;
            3.0 * (1.0 - 0.7 * t) * (29.0 * t).sin() + 0.8 * (113.0 * t).sin()
        })
        .collect()
}

#[test]
fn recovers_parameters_both_orientations() {
    let u = input(3000);
    for o in [Orientation::COUNTER_CLOCKWISE, Orientation::CLOCKWISE] {
        let t = Backlash::new(1.7, 0.437, -0.3, o).unwrap();
        let y = t.simulate(&u).unwrap();
        let f = fit(&u, &y, &BacklashOptions::default()).unwrap();
        assert_eq!(f.model.orientation(), o);
        assert!((f.model.gain() - 1.7).abs() < 1e-6, "{o:?} {:?}", f.model);
        assert!(
            (f.model.half_width() - 0.437).abs() < 1e-6,
            "{o:?} {:?}",
            f.model
        );
        assert!((f.model.offset() + 0.3).abs() < 1e-6, "{o:?} {:?}", f.model);
        assert!(
            f.termination.converged()
                || f.termination == hysid::numerics::Termination::ZeroResidual
        );
    }
}

#[test]
fn noisy_parameters_within_three_sigma() {
    let u = input(3000);
    let t = Backlash::new(1.7, 0.437, -0.3, Orientation::COUNTER_CLOCKWISE).unwrap();
    let clean = t.simulate(&u).unwrap();
    let sd = metrics::std_dev(&clean) / 100.0;
    let (mut inside, mut total) = (0, 0);
    for seed in 0..6u64 {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(100 + seed);
        let normal = Normal::new(0.0, sd).unwrap();
        let y: Vec<f64> = clean.iter().map(|v| v + normal.sample(&mut rng)).collect();
        let f = fit(&u, &y, &BacklashOptions::default()).unwrap();
        for (i, tv) in [1.7, 0.437, -0.3].into_iter().enumerate() {
            let s = f.std[i].unwrap();
            inside += ((f.parameters.get(i).value - tv).abs() <= 3.0 * s) as usize;
            total += 1;
        }
    }
    assert!(inside * 10 >= total * 9, "{inside}/{total}");
}

#[test]
fn too_few_reversals_are_refused() {
    let u: Vec<f64> = (0..100).map(|k| (k as f64 * 0.03).sin()).collect();
    let y = u.clone();
    let e = fit(&u, &y, &BacklashOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("reversal"), "{e}");
}
