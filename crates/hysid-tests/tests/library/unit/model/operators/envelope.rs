//! Tests of `hysid::model::operators::envelope`: the static envelope against the Bernstein
//! form evaluated independently (de Casteljau), its monotonicity for any non-negative slope
//! values (seeded), its end tangents, and the PI operator carrying one.

use hysid::model::operators::*;
use rand::rngs::Xoshiro256PlusPlus;
use rand::SeedableRng;
use rand_distr::{Distribution, Uniform};

/// E(u) by de Casteljau's algorithm on the control values w·Pᵢ, Pᵢ = (c₀ + … + c_{i−1})/n
/// (the module documentation's integrated Bernstein form), with the end tangents outside.
fn de_casteljau(lo: f64, hi: f64, slopes: &[f64], u: f64) -> f64 {
    let (w, n) = (hi - lo, slopes.len());
    let mut p: Vec<f64> = (0..=n)
        .map(|i| w * slopes[..i].iter().sum::<f64>() / n as f64)
        .collect();
    let top = *p.last().unwrap();
    if u < lo {
        return slopes[0] * (u - lo);
    }
    if u > hi {
        return top + slopes[n - 1] * (u - hi);
    }
    let t = (u - lo) / w;
    for level in (1..=n).rev() {
        for i in 0..level {
            p[i] = (1.0 - t) * p[i] + t * p[i + 1];
        }
    }
    p[0]
}

#[test]
fn the_envelope_is_the_integrated_bernstein_form() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
    let slope = Uniform::new(0.0, 3.0).unwrap();
    for degree in 2..=5 {
        for _ in 0..20 {
            let slopes: Vec<f64> = (0..degree).map(|_| slope.sample(&mut rng)).collect();
            let (lo, hi) = (-40.0, 125.0);
            let e = Envelope::new(lo, hi, slopes.clone()).unwrap();
            let scale = slopes.iter().sum::<f64>() * (hi - lo);
            for k in 0..=400 {
                let u = lo - 30.0 + (hi - lo + 60.0) * k as f64 / 400.0;
                let (got, want) = (e.value(u), de_casteljau(lo, hi, &slopes, u));
                assert!(
                    (got - want).abs() <= 1e-12 * scale,
                    "degree {degree}, u = {u}: {got} vs {want}"
                );
            }
            // E(lo) = 0, E(hi) = w·(c₀ + … + c_d)/n exactly where the pieces meet
            assert_eq!(e.value(lo), 0.0);
            assert_eq!(e.value(hi), e.top());
            let top = (hi - lo) * slopes.iter().sum::<f64>() / degree as f64;
            assert!((e.top() - top).abs() <= 1e-12 * scale);
        }
    }
}

/// Non-negative slope values give a non-decreasing E on and beyond the range, with the
/// slope values c₀ and c_d as its slopes at the ends (a central difference).
#[test]
fn any_non_negative_slope_values_give_a_monotone_envelope() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(12);
    let slope = Uniform::new(0.0, 1.0).unwrap();
    for trial in 0..200 {
        let mut slopes: Vec<f64> = (0..3).map(|_| slope.sample(&mut rng)).collect();
        // some with a zero slope value (a flat end, a flat middle)
        if trial % 4 == 0 {
            slopes[trial % 3] = 0.0;
        }
        let e = Envelope::new(0.5, 2.5, slopes.clone()).unwrap();
        let mut previous = f64::NEG_INFINITY;
        for k in 0..=2000 {
            let u = -1.0 + 5.0 * k as f64 / 2000.0;
            let v = e.value(u);
            assert!(v >= previous - 1e-15, "trial {trial}: E falls at u = {u}");
            previous = v;
        }
        let h = 1e-6;
        let at = |u: f64| (e.value(u + h) - e.value(u - h)) / (2.0 * h);
        assert!((at(0.5) - slopes[0]).abs() < 1e-6, "trial {trial}: E'(lo)");
        assert!((at(2.5) - slopes[2]).abs() < 1e-6, "trial {trial}: E'(hi)");
        assert!((at(-0.5) - slopes[0]).abs() < 1e-9, "trial {trial}: below");
        assert!((at(3.5) - slopes[2]).abs() < 1e-9, "trial {trial}: above");
    }
}

#[test]
fn bad_envelopes_are_refused_and_a_file_round_trips() {
    assert!(Envelope::new(1.0, 1.0, vec![1.0, 1.0]).is_err());
    // a range so narrow that 1/w overflows
    assert!(Envelope::new(0.0, 1e-310, vec![1.0, 1.0]).is_err());
    assert!(Envelope::new(2.0, 1.0, vec![1.0, 1.0]).is_err());
    assert!(Envelope::new(0.0, f64::INFINITY, vec![1.0, 1.0]).is_err());
    assert!(Envelope::new(0.0, 1.0, vec![1.0]).is_err());
    let negative = Envelope::new(0.0, 1.0, vec![1.0, -0.1, 1.0]).unwrap_err();
    assert!(negative.to_string().contains("e1"), "{negative}");
    assert!(Envelope::new(0.0, 1.0, vec![1.0, f64::NAN]).is_err());
    let e = Envelope::new(-2.0, 3.0, vec![0.3, 1.2, 0.1]).unwrap();
    let json = serde_json::to_value(&e).unwrap();
    assert_eq!(
        json,
        serde_json::json!({"lo": -2.0, "hi": 3.0, "slopes": [0.3, 1.2, 0.1]}),
        "the file holds the range and the slope values only"
    );
    assert_eq!(serde_json::from_value::<Envelope>(json).unwrap(), e);
    let bad = serde_json::json!({"lo": 0.0, "hi": 1.0, "slopes": [1.0, -1.0]});
    assert!(serde_json::from_value::<Envelope>(bad).is_err());
}

/// A PI with an envelope is G = c + a₀u + E(u) + Σ aᵢF_{rᵢ}[u]: its output minus the same PI
/// without one is E(u) sample by sample; its inverse (the per-sample solve) gives the input
/// back in both orientations, also beyond the envelope's range; a file without an envelope
/// reads as before and one with it round-trips.
#[test]
fn a_pi_with_an_envelope_adds_it_and_inverts() {
    let u: Vec<f64> = (0..800)
        .map(|k| {
            let t = k as f64 / 800.0;
            1.6 * (1.0 - 0.6 * t) * (25.0 * t).sin() + 0.2 * (90.0 * t).sin()
        })
        .collect();
    let e = Envelope::new(-1.0, 1.0, vec![0.1, 0.8, 0.05]).unwrap();
    let make = |envelope, o| {
        PrandtlIshlinskii::with_static_envelope(
            0.2,
            vec![0.3, 0.2, 0.1],
            vec![0.1, 0.3, 0.6],
            0.05,
            o,
            envelope,
        )
        .unwrap()
    };
    let plain = make(None, Orientation::default());
    let with = make(Some(e.clone()), Orientation::default());
    let (y0, y1) = (plain.simulate(&u).unwrap(), with.simulate(&u).unwrap());
    for ((a, b), &x) in y0.iter().zip(&y1).zip(&u) {
        assert!((b - a - e.value(x)).abs() <= 1e-12, "{b} − {a} vs E({x})");
    }
    assert!(with.inverse_parameters().is_none(), "no PI-shaped inverse");
    let inverse = with.invert(&y1).unwrap();
    assert!(inverse.clipped.is_empty());
    for (got, want) in inverse.u.iter().zip(&u) {
        assert!((got - want).abs() <= 1e-9, "{got} vs {want}");
    }
    // clockwise: Γ = G⁻¹ takes G's outputs and gives the input back
    let cw = make(Some(e), Orientation::CLOCKWISE);
    let back = cw.simulate(&y1).unwrap();
    for (got, want) in back.iter().zip(&u) {
        assert!((got - want).abs() <= 1e-9, "clockwise: {got} vs {want}");
    }
    // files
    let plain_json = serde_json::to_value(&plain).unwrap();
    assert!(plain_json.get("envelope").is_none(), "no key without one");
    let json = serde_json::to_value(&with).unwrap();
    assert_eq!(
        serde_json::from_value::<PrandtlIshlinskii>(json).unwrap(),
        with
    );
    // the plays may all be zero when the envelope has a slope
    assert!(PrandtlIshlinskii::with_static_envelope(
        0.0,
        vec![0.0],
        vec![0.5],
        0.0,
        Orientation::default(),
        Some(Envelope::new(0.0, 1.0, vec![1.0, 1.0]).unwrap()),
    )
    .is_ok());
    assert!(
        PrandtlIshlinskii::new(0.0, vec![0.0], vec![0.5], 0.0, Orientation::default()).is_err()
    );
}

/// A PI whose final slope is zero above (saturating plays, an envelope flat at its top end)
/// is bounded there, and its inverse still reaches every output its envelope's range gives
/// (the bracket spans the envelope's range, `solve_reach`), clipping only beyond it.
#[test]
fn a_bounded_enveloped_pi_inverts_across_its_envelope() {
    let e = Envelope::new(-1.0, 1.0, vec![0.1, 0.8, 0.0]).unwrap();
    let op = PrandtlIshlinskii::with_static_envelope(
        0.0,
        vec![0.3, -0.3],
        vec![0.1, 0.3],
        0.0,
        Orientation::default(),
        Some(e),
    )
    .unwrap();
    assert_eq!(op.unbounded(), (true, false));
    let u = [0.0, 0.9, -0.2, 0.95, -0.9, 0.5];
    let y = op.simulate(&u).unwrap();
    let back = op.invert(&y).unwrap();
    assert!(back.clipped.is_empty(), "{:?}", back.clipped);
    for (got, want) in back.u.iter().zip(&u) {
        assert!((got - want).abs() <= 1e-9, "{got} vs {want}");
    }
    // above its saturation the reference is clipped, and said so
    let high = op.invert(&[y[0], y[3] + 1.0]).unwrap();
    assert_eq!(high.clipped, vec![1]);
}

/// A generalised PI's plays take no envelope: a model file with one is refused.
#[test]
fn a_generalised_pi_refuses_an_envelope_in_its_plays() {
    let example = GeneralizedPi::example().unwrap();
    let mut json = serde_json::to_value(&example).unwrap();
    json["pi"]["envelope"] = serde_json::json!({"lo": -1.0, "hi": 1.0, "slopes": [1.0, 1.0]});
    let raw = serde_json::json!({"family": "gpi", "operator": json});
    let err = serde_json::from_value::<OperatorModel>(raw).unwrap_err();
    assert!(err.to_string().contains("envelope"), "{err}");
}
