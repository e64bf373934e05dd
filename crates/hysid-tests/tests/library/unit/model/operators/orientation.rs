//! Tests of `hysid::model::operators::orientation`: the loop's turning sense from the area
//! between the branches, on records cut open, runs concatenated, both orientations, a
//! decreasing trend, noise and narrow loops (issue 38, item 1).

use hysid::model::operators::registry::OperatorModel;
use hysid::model::operators::{loop_evidence, play, LoopOrientation, Orientation};
use hysid::Error;
use rand::rngs::Xoshiro256PlusPlus;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal, Uniform};

fn uniform(rng: &mut Xoshiro256PlusPlus, lo: f64, hi: f64) -> f64 {
    Uniform::new(lo, hi).unwrap().sample(rng)
}

/// One run: random turning points in [c − a, c + a], joined by steps of about `step`.
fn run(rng: &mut Xoshiro256PlusPlus, c: f64, a: f64, turns: usize, step: f64) -> Vec<f64> {
    let mut u = vec![c + uniform(rng, -0.2, 0.2) * a];
    for k in 0..turns {
        // alternate up and down, each to a random level of the run's range
        let target = if k % 2 == 0 {
            c + uniform(rng, 0.6, 1.0) * a
        } else {
            c - uniform(rng, 0.6, 1.0) * a
        };
        let from = *u.last().unwrap();
        let n = ((target - from).abs() / step).ceil().max(1.0) as usize;
        u.extend((1..=n).map(|i| from + (target - from) * i as f64 / n as f64));
    }
    u
}

/// Several runs of `model`, each simulated from the model's own initial state with its own
/// range and offset, concatenated, then cut open at random points.
fn open_record(model: &OperatorModel, seed: u64) -> (Vec<f64>, Vec<f64>) {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let runs = 2 + (seed % 3) as usize;
    let (mut u, mut y) = (Vec::new(), Vec::new());
    let mut lengths = Vec::new();
    for r in 0..runs {
        // the first run sweeps most of the range (every example's loop opens there), the
        // others have their own range and offset
        let a = if r == 0 {
            0.92
        } else {
            uniform(&mut rng, 0.5, 0.85)
        };
        let c = uniform(&mut rng, -(0.95 - a), 0.95 - a);
        let turns = 3 + (uniform(&mut rng, 0.0, 4.0) as usize);
        let step = uniform(&mut rng, 0.01, 0.05);
        let ur = run(&mut rng, c, a, turns, step);
        // the example Jiles–Atherton takes H in A/m: its loop opens at hundreds of A/m (k = 400)
        let scale = if model.family().name() == "jiles-atherton" {
            400.0
        } else {
            1.0
        };
        let ur: Vec<f64> = ur.iter().map(|v| scale * v).collect();
        lengths.push(ur.len());
        let yr = model.as_operator().simulate(&ur).unwrap();
        u.extend(ur);
        y.extend(yr);
    }
    // an output offset of the whole record (a sensor's zero) and a small one per run: the
    // path integral of an open record then carries the offset times the net input travel
    let (ylo, yhi) = y
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let span = yhi - ylo;
    let offset = if seed.is_multiple_of(2) { 3.0 } else { -3.0 } * span;
    let mut k = 0;
    for len in lengths {
        let jitter = uniform(&mut rng, -0.02, 0.02) * span;
        for v in &mut y[k..k + len] {
            *v += offset + jitter;
        }
        k += len;
    }
    let n = u.len();
    let from = uniform(&mut rng, 0.0, 0.2 * n as f64) as usize;
    let to = n - uniform(&mut rng, 0.0, 0.2 * n as f64) as usize;
    (u[from..to].to_vec(), y[from..to].to_vec())
}

fn negated(x: &[f64]) -> Vec<f64> {
    x.iter().map(|v| -v).collect()
}

/// The path integral ∮ y du of the whole record (what the detector replaced).
fn path_area(u: &[f64], y: &[f64]) -> f64 {
    (1..u.len())
        .map(|k| 0.5 * (y[k] + y[k - 1]) * (u[k] - u[k - 1]))
        .sum()
}

/// Every family of the registry, records cut open at seeded random points with several runs
/// concatenated: the detected turning sense is the model's, in both orientations (the loop
/// mirrored, u → −u) and with a decreasing trend (y → −y); the linear-in-weights orientation
/// `{inverse, decreasing}` follows.
#[test]
fn every_family_open_records_both_orientations() {
    let mut checked = 0;
    let mut path_wrong = 0;
    for model in OperatorModel::examples().unwrap() {
        let name = model.family().name();
        let truth = model.loop_orientation();
        for seed in 0..8u64 {
            let (u, y) = open_record(&model, 1000 + seed);
            let cases = [
                ("as simulated", u.clone(), y.clone(), truth),
                ("mirrored", negated(&u), y.clone(), truth.reversed()),
                ("decreasing", u.clone(), negated(&y), truth.reversed()),
                ("both", negated(&u), negated(&y), truth),
            ];
            for (what, uc, yc, expected) in cases {
                let e = loop_evidence(&uc, &yc).unwrap_or_else(|err| {
                    panic!("{name}, seed {seed}, {what}: {err}");
                });
                assert_eq!(
                    e.orientation, expected,
                    "{name}, seed {seed}, {what}: {e:?}"
                );
                let o = Orientation::detect(&uc, &yc).unwrap();
                assert_eq!(o.loop_orientation(), expected, "{name} {seed} {what}");
                assert_eq!(
                    o.decreasing,
                    Orientation::trend(&uc, &yc).unwrap(),
                    "{name} {seed} {what}: the trend is cov(u, y)'s"
                );
                let by_path = if path_area(&uc, &yc) > 0.0 {
                    LoopOrientation::Clockwise
                } else {
                    LoopOrientation::CounterClockwise
                };
                path_wrong += usize::from(by_path != expected);
                checked += 1;
            }
        }
    }
    eprintln!("the path integral misreads {path_wrong} of {checked} records");
    assert_eq!(checked, 10 * 8 * 4);
    // the records are open enough that the old path integral gets many of them wrong
    assert!(path_wrong > checked / 10, "{path_wrong} of {checked}");
}

/// The same records with noise on both channels (1 % of the output's range on y, 0.2 % of
/// the input's on u).
#[test]
fn every_family_with_noise() {
    for model in OperatorModel::examples().unwrap() {
        let name = model.family().name();
        let truth = model.loop_orientation();
        for seed in 0..4u64 {
            let (u, y) = open_record(&model, 2000 + seed);
            let mut rng = Xoshiro256PlusPlus::seed_from_u64(3000 + seed);
            let span = |x: &[f64]| {
                x.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
                    - x.iter().cloned().fold(f64::INFINITY, f64::min)
            };
            let (nu, ny) = (
                Normal::new(0.0, 0.002 * span(&u)).unwrap(),
                Normal::new(0.0, 0.01 * span(&y)).unwrap(),
            );
            let un: Vec<f64> = u.iter().map(|v| v + nu.sample(&mut rng)).collect();
            let yn: Vec<f64> = y.iter().map(|v| v + ny.sample(&mut rng)).collect();
            let got = loop_evidence(&un, &yn)
                .unwrap_or_else(|e| panic!("{name}, seed {seed}: {e}"))
                .orientation;
            assert_eq!(got, truth, "{name}, seed {seed}");
            let got = loop_evidence(&negated(&un), &yn).unwrap().orientation;
            assert_eq!(got, truth.reversed(), "{name}, seed {seed}, mirrored");
        }
    }
}

/// A magnet-like record: a saturating static curve over ±165 (A), a loop 1 % of the output
/// range wide (plays of 0.8 A), a few hundred quasi-static set points over several runs with
/// their own ranges, an output offset per run, noise on both channels.
fn narrow_record(seed: u64) -> (Vec<f64>, Vec<f64>) {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut u = Vec::new();
    for (c, a, turns) in [(0.0, 165.0, 4), (20.0, 60.0, 6), (-30.0, 120.0, 5)] {
        u.extend(run(&mut rng, c, a, turns, 9.0));
    }
    assert!((150..=600).contains(&u.len()), "{}", u.len());
    let r = 0.8;
    let loop_part: Vec<f64> = play(&u, r).iter().zip(&u).map(|(p, x)| p - x).collect();
    let (nu, ny) = (
        Normal::new(0.0, 0.02).unwrap(),
        Normal::new(0.0, 0.1).unwrap(),
    );
    let third = u.len() / 3;
    let y: Vec<f64> = u
        .iter()
        .zip(&loop_part)
        .enumerate()
        // half-width 1.25·0.8 = 1 on an output range of about 200: 1 %
        .map(|(k, (x, l))| {
            100.0 * (x / 50.0).tanh() + 1.25 * l + 0.5 * (k / third) as f64 + ny.sample(&mut rng)
        })
        .collect();
    let u: Vec<f64> = u.iter().map(|x| x + nu.sample(&mut rng)).collect();
    (u, y)
}

#[test]
fn narrow_loop_on_a_wide_range() {
    for seed in 0..5 {
        let (u, y) = narrow_record(40 + seed);
        let e = loop_evidence(&u, &y).unwrap();
        assert_eq!(e.orientation, LoopOrientation::CounterClockwise, "{e:?}");
        assert_eq!(
            Orientation::detect(&u, &y).unwrap(),
            Orientation::COUNTER_CLOCKWISE
        );
        assert_eq!(
            loop_evidence(&negated(&u), &y).unwrap().orientation,
            LoopOrientation::Clockwise
        );
        let o = Orientation::detect(&u, &negated(&y)).unwrap();
        assert!(o.decreasing && o.loop_orientation() == LoopOrientation::Clockwise);
        // the whole path's integral reads this record the wrong way round
        if seed == 0 {
            assert!(
                path_area(&u, &y) > 0.0,
                "the path integral says clockwise here"
            );
        }
    }
}

/// A quasi-static magnet record as a laboratory takes it: standardised (three unrecorded
/// cycles to 165 A), two major loops of 15 set points a ramp (11 A apart), minor loops of 6
/// whose returns to 0 A are not recorded, then random set points; a strongly saturating
/// static curve (tanh over 60 A, or a cubic) in units far from 1 with an offset, and a loop
/// of three plays 0.3 … 2 A wide (about 1 % of the ranges).
fn set_point_record(seed: u64, saturation: f64, scale: f64, step: f64) -> (Vec<f64>, Vec<f64>) {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let ramp = |u: &mut Vec<(f64, bool)>, from: f64, to: f64, n: usize, kept: bool| {
        u.extend((1..=n).map(|k| (from + (to - from) * k as f64 / n as f64, kept)));
    };
    let mut u = vec![(0.0, false)];
    for _ in 0..3 {
        ramp(&mut u, 0.0, 165.0, 10, false);
        ramp(&mut u, 165.0, 0.0, 10, false);
    }
    for _ in 0..2 {
        ramp(&mut u, 0.0, 165.0, 15, true);
        ramp(&mut u, 165.0, 0.0, 15, true);
    }
    for (top, bottom) in [(120.0, 40.0), (80.0, 20.0), (150.0, 100.0)] {
        ramp(&mut u, 0.0, top, 6, true);
        ramp(&mut u, top, bottom, 6, true);
        ramp(&mut u, bottom, 0.0, 3, false);
    }
    while u.iter().filter(|p| p.1).count() < 190 {
        u.push((uniform(&mut rng, 0.0, 165.0), true));
    }
    // the set points on a raster of `step` (0: as they come)
    let current: Vec<f64> = u
        .iter()
        .map(|p| {
            if step > 0.0 {
                (p.0 / step).round() * step
            } else {
                p.0
            }
        })
        .collect();
    let plays: Vec<Vec<f64>> = [0.3, 0.8, 2.0].iter().map(|&r| play(&current, r)).collect();
    let field: Vec<f64> = (0..current.len())
        .map(|k| {
            let x = 0.3 * plays[0][k] + 0.5 * plays[1][k] + 0.2 * plays[2][k];
            let b = if saturation > 0.0 {
                (x / saturation).tanh() / (165.0 / saturation).tanh()
            } else {
                x / 165.0 - 0.15 * (x / 165.0).powi(3)
            };
            scale * (0.05 + 1.2 * b + 0.002 * current[k])
        })
        .collect();
    let kept = |v: &[f64]| -> Vec<f64> {
        v.iter()
            .zip(&u)
            .filter(|(_, p)| p.1)
            .map(|(x, _)| *x)
            .collect()
    };
    (kept(&current), kept(&field))
}

/// Sparse set points on a curved static curve: the chords between set points differ by more
/// than the loop is wide, which reads as noise or as pairs that disagree unless the static
/// curve is taken out first (module doc of `orientation`); both orientations, in tesla and
/// in millitesla, set points on a coarse raster, and the first 170 rows alone (a record's
/// training part).
#[test]
fn sparse_set_points_on_a_curved_static_curve() {
    for (seed, saturation, scale, step) in [
        (1, 60.0, 1.0, 0.0),
        (2, 90.0, 1000.0, 0.0),
        (3, 0.0, 1.0, 0.0),
        (4, 45.0, 1e-3, 0.0),
        // set points on a 20 A raster: 9 distinct currents, fewer than the spline's 10
        // coefficients with all its knots
        (5, 60.0, 1.0, 20.0),
    ] {
        let (u, y) = set_point_record(seed, saturation, scale, step);
        for (u, y) in [(&u[..], &y[..]), (&u[..170], &y[..170])] {
            let what = format!(
                "seed {seed}, saturation {saturation}, scale {scale}, raster {step}, {} rows",
                u.len()
            );
            let e = loop_evidence(u, y).unwrap_or_else(|e| panic!("{what}: {e}"));
            assert_eq!(
                e.orientation,
                LoopOrientation::CounterClockwise,
                "{what}: {e:?}"
            );
            assert!(e.confidence >= 5.0, "{what}: {e:?}");
            let mirrored = loop_evidence(&negated(u), y).unwrap_or_else(|e| panic!("{what}: {e}"));
            assert_eq!(mirrored.orientation, LoopOrientation::Clockwise, "{what}");
            let o = Orientation::detect(u, &negated(y)).unwrap();
            assert!(
                o.decreasing && o.loop_orientation() == LoopOrientation::Clockwise,
                "{what}"
            );
        }
    }
}

fn undetermined(u: &[f64], y: &[f64]) -> String {
    match loop_evidence(u, y) {
        Err(e @ Error::UndeterminedOrientation { .. }) => {
            let text = e.to_string();
            assert!(text.contains("--orientation ccw|cw"), "{text}");
            assert!(!text.contains('\n'), "one line: {text}");
            text
        }
        other => panic!("expected UndeterminedOrientation, got {other:?}"),
    }
}

/// A record too short to tell, one that never reverses, and one whose loop is noise: a
/// one-line error that names the flag.
#[test]
fn too_short_or_noise_is_a_one_line_error() {
    undetermined(&[0.0, 1.0, 0.5], &[0.0, 1.0, 0.6]);
    let ramp: Vec<f64> = (0..100).map(|k| k as f64).collect();
    let text = undetermined(&ramp, &ramp);
    assert!(text.contains("no reversal"), "{text}");
    let u: Vec<f64> = (0..400).map(|k| (k as f64 * 0.05).sin()).collect();
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
    let noise = Normal::new(0.0, 1.0).unwrap();
    let y: Vec<f64> = u.iter().map(|x| x + noise.sample(&mut rng)).collect();
    undetermined(&u, &y);
    // the linear-in-weights detection gives the same error
    assert!(matches!(
        Orientation::detect(&u, &y),
        Err(Error::UndeterminedOrientation { .. })
    ));
}

#[test]
fn names_and_mapping() {
    use LoopOrientation::*;
    assert_eq!(LoopOrientation::parse("ccw").unwrap(), CounterClockwise);
    assert_eq!(LoopOrientation::parse("CW").unwrap(), Clockwise);
    assert!(LoopOrientation::parse("up").is_err());
    assert_eq!(CounterClockwise.short_name(), "ccw");
    for turning in [CounterClockwise, Clockwise] {
        for decreasing in [false, true] {
            let o = Orientation::for_loop(turning, decreasing);
            assert_eq!(o.decreasing, decreasing);
            assert_eq!(o.loop_orientation(), turning);
        }
    }
    assert_eq!(
        Orientation::for_loop(CounterClockwise, false),
        Orientation::COUNTER_CLOCKWISE
    );
    assert_eq!(
        Orientation::for_loop(Clockwise, false),
        Orientation::CLOCKWISE
    );
}

/// The PI fit of an open magnet-like record (narrow loop, saturation, several runs, noise)
/// with the detected orientation against the one the whole path's integral gave before:
/// the latter fits the inverse and collapses towards a straight line. (Without a static
/// envelope: the question is the plays' orientation, not the static curve's.)
#[test]
fn pi_fit_of_an_open_record_detected_against_path_integral() {
    use hysid::identify::operators::{
        fit_operator, EnvelopeChoice, Family, FamilyOptions, OrientationSource,
    };
    let (u, y) = narrow_record(40);
    let plays_only = FamilyOptions {
        envelope: EnvelopeChoice::None,
        ..FamilyOptions::default()
    };
    let detected = fit_operator(Family::Pi, &u, &y, &plays_only).unwrap();
    let used = detected.orientation.unwrap();
    assert_eq!(used.orientation, LoopOrientation::CounterClockwise);
    assert_eq!(used.source, OrientationSource::Detected);
    // before: trend from cov(u, y), turning sense from ∮ y du
    let old = Orientation {
        inverse: path_area(&u, &y) > 0.0,
        decreasing: false,
    };
    assert!(old.inverse, "the path integral reads this record clockwise");
    let before = fit_operator(
        Family::Pi,
        &u,
        &y,
        &FamilyOptions {
            orientation: Some(old),
            ..plays_only.clone()
        },
    )
    .unwrap();
    let n = u.len() as f64;
    let (mu, my) = (u.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let slope = u
        .iter()
        .zip(&y)
        .map(|(a, b)| (a - mu) * (b - my))
        .sum::<f64>()
        / u.iter().map(|a| (a - mu).powi(2)).sum::<f64>();
    let line: Vec<f64> = u.iter().map(|a| my + slope * (a - mu)).collect();
    let line_fit = hysid::numerics::metrics::fit_percent(&y, &line);
    eprintln!(
        "PI on the open narrow-loop record ({} samples): detected {:.2} %, path integral {:.2} %, \
         straight line {line_fit:.2} %",
        u.len(),
        detected.fit.fit_percent,
        before.fit.fit_percent
    );
    assert!(detected.fit.fit_percent > before.fit.fit_percent);
    // a given orientation is honoured
    let given = fit_operator(
        Family::Pi,
        &u,
        &y,
        &FamilyOptions {
            loop_orientation: Some(LoopOrientation::Clockwise),
            ..FamilyOptions::default()
        },
    )
    .unwrap();
    let used = given.orientation.unwrap();
    assert_eq!(used.orientation, LoopOrientation::Clockwise);
    assert_eq!(used.source, OrientationSource::Given);
}
