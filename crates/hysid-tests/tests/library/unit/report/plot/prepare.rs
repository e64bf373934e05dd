//! Tests of `hysid::report::plot::prepare`.

use hysid::report::plot::figure::Style;
use hysid::report::plot::prepare::*;

#[test]
fn decimation_keeps_extremes_in_order() {
    let run: Vec<(f64, f64)> = (0..100_000)
        .map(|i| (i as f64, ((i * 7919) % 1000) as f64))
        .collect();
    let d = decimate(&run, bucket_len(run.len(), Style::Line));
    assert!(d.len() <= 2_000 * 4 + 2);
    assert!(d.windows(2).all(|w| w[0].0 < w[1].0), "order preserved");
    let ymax = d.iter().map(|p| p.1).fold(f64::MIN, f64::max);
    let ymin = d.iter().map(|p| p.1).fold(f64::MAX, f64::min);
    assert_eq!((ymin, ymax), (0.0, 999.0));
    assert_eq!(d.first(), run.first());
    assert_eq!(d.last(), run.last());
}

#[test]
fn runs_break_at_non_finite() {
    let x = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0];
    let y = [1.0, f64::NAN, 2.0, 3.0, f64::INFINITY, 4.0];
    let runs = finite_runs(&x, &y);
    assert_eq!(
        runs,
        vec![
            vec![(0.0, 1.0)],
            vec![(2.0, 2.0), (3.0, 3.0)],
            vec![(5.0, 4.0)]
        ]
    );
}
