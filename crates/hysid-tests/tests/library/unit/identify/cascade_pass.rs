//! Tests of `hysid::identify::cascade_pass`.

use hysid::experiments::voros::CascadeExample;
use hysid::identify::cascade_pass::*;
use hysid::model::coleman_hodgdon::simulate_switched;
use hysid::model::HysteresisCascade;
use hysid::Error;

/// The in-place simulation is bit-identical to the hysteresis simulation followed by the
/// linear block, with and without a frozen switching.
#[test]
fn simulation_matches_the_model_bit_for_bit() {
    for n in [1, 2] {
        let ex = CascadeExample::number(n).unwrap();
        let x = ex.generate(5, false).unwrap().x;
        let h: Vec<bool> = x
            .iter()
            .map(|v| v.abs() > 0.9 * ex.truth.hysteresis.d())
            .collect();
        for frozen in [None, Some(h.as_slice())] {
            let v = simulate_switched(&ex.truth.hysteresis, &x, 0.0, frozen);
            let expected = ex.truth.linear.simulate(&v);
            let mut y = vec![1.0; 3];
            simulate_into(&ex.truth, &x, frozen, &mut y);
            assert_eq!(y, expected, "example {n}");
        }
    }
}

/// The fixed-width passes are bit-identical to the generic ones for every instantiated
/// shape (ch4 and ch6, n ≤ 3, m ≤ 3, delays 1 and 3), with every parameter free or some,
/// with and without a frozen switching, and decline the shapes they do not cover (n = 4);
/// the sensitivity pass's ŷ is the simulation's.
#[test]
fn fixed_width_passes_equal_generic_passes() {
    use hysid::model::{ColemanHodgdon, LinearBlock};
    let ex = CascadeExample::example1();
    let x = ex.generate(7, false).unwrap().x;
    let h: Vec<bool> = x.iter().map(|v| v.abs() > 2.5).collect();
    let forms = [
        ColemanHodgdon::saturated(0.3, 1.0, 0.5, 3.0).unwrap(),
        ColemanHodgdon::general(0.25, 1.2, 0.15, 0.6, 0.1, 2.0).unwrap(),
    ];
    for ch in &forms {
        for na in 0..=4 {
            for nb in 1..=3 {
                for delay in [1, 3] {
                    let a = [-0.5, 0.2, -0.05, 0.01][..na].to_vec();
                    let b = [1.0, 0.4, -0.2][..nb].to_vec();
                    let cascade =
                        HysteresisCascade::new(ch.clone(), LinearBlock::new(a, b, delay).unwrap())
                            .unwrap();
                    let p = cascade.params().len();
                    // Every parameter free (rows written whole) and some (columns picked).
                    let all: Vec<usize> = (0..p).collect();
                    let some: Vec<usize> = (0..p).rev().step_by(2).collect();
                    for (free, frozen) in [(&all, None), (&some, None), (&some, Some(h.as_slice()))]
                    {
                        let mut generic = Vec::new();
                        let g = recursion_generic(&cascade, &x, frozen, free, |t, y, r| {
                            generic.push((t, y, r.to_vec()))
                        });
                        let mut fast = Vec::new();
                        let f = fixed::recursion(&cascade, &x, frozen, free, |t, y, r| {
                            fast.push((t, y, r.to_vec()))
                        });
                        let (mut ys, mut yf) = (Vec::new(), Vec::new());
                        simulate_generic(&cascade, &x, frozen, &mut ys);
                        // The pass's ŷ is the simulated output, bit for bit: the long-record
                        // fits take their residuals from it.
                        let pass_y: Vec<f64> = generic.iter().map(|row| row.1).collect();
                        assert!(pass_y == ys, "{na} {nb} {delay}");
                        let simulated = fixed::simulate(&cascade, &x, frozen, &mut yf);
                        if na == 4 {
                            assert_eq!(f, None);
                            assert_eq!(simulated, None);
                            continue;
                        }
                        assert_eq!(f, Some(g));
                        assert!(fast == generic, "{na} {nb} {delay}");
                        assert_eq!(simulated, Some(()));
                        assert!(yf == ys, "{na} {nb} {delay}");
                    }
                }
            }
        }
    }
}

/// The pipelined pass streams exactly the rows of the sequential one, in order, with every
/// parameter free and with some.
#[test]
fn pipelined_rows_equal_sequential_rows() {
    let ex = CascadeExample::example1().extended(PIPELINE_SAMPLES + 12_345);
    let x = ex.generate(2, false).unwrap().x;
    let all: Vec<usize> = (0..ex.truth.params().len()).collect();
    for free in [&all[..], &[0, 2, 3, 5]] {
        let mut sequential = Vec::new();
        recursion(&ex.truth, &x, None, free, |t, yhat, row| {
            sequential.push((t, yhat, row.to_vec()))
        });
        let mut piped = Vec::new();
        let failed = pipelined(&ex.truth, &x, None, free, &mut |block| {
            for (i, row) in block.rows.chunks_exact(block.width).enumerate() {
                piped.push((block.start + i, row[0], row[1..].to_vec()));
            }
        });
        assert_eq!(failed, None);
        assert_eq!(piped.len(), x.len());
        assert!(piped == sequential);
    }
}

/// A diverging simulation is reported at its first non-finite sample by both paths, whether
/// that sample lies among the first rows (which lack lags), inside a block or in a late one.
#[test]
fn divergence_is_reported() {
    let ex = CascadeExample::example1().extended(PIPELINE_SAMPLES + 10);
    let clean = ex.generate(2, false).unwrap().x;
    for at in [1, 700, PIPELINE_SAMPLES + 3] {
        let mut x = clean.clone();
        x[at] = f64::INFINITY;
        // ŷ follows x with the delay k = 1, so the first non-finite output is one later.
        let expected = recursion(&ex.truth, &x, None, &[0, 1], |_, _, _| {});
        assert_eq!(expected, Some(at + 1));
        let mut count = 0;
        let err = stream_sensitivities(&ex.truth, &x, None, &[0, 1], &mut |_, _, _| {
            count += 1;
            std::ops::ControlFlow::Continue(())
        });
        assert!(matches!(err, Err(Error::Diverged { index, .. }) if Some(index) == expected));
        assert_eq!(count, x.len());
    }
}
