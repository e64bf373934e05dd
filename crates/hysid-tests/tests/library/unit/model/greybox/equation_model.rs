//! Tests of `hysid::model::greybox::equation_model`.

use hysid::model::greybox::equation_model::*;
use hysid::model::greybox::{sensitivity, JacobianScratch, StateSpaceModel};
use hysid::Error;

const DECAY: &str = "[model]\nstates = [\"x\"]\ninputs = [\"u\"]\noutputs = [\"y\"]\n\
    [parameters]\na = { value = 2.0, lower = 0.0 }\n[initial]\nx = { value = 0.5, fixed = false }\n\
    [equations]\nx = \"-a*x + u\"\n[output]\ny = \"x\"\n";

#[test]
fn parameters_initial_states_and_jacobians_come_from_the_file() {
    let m = EquationStateSpace::parse(DECAY, "decay").unwrap();
    let p = m.parameters();
    assert_eq!(p.names(), ["a"]);
    assert_eq!((p.get(0).min, p.get(0).max), (0.0, f64::INFINITY));
    assert_eq!(m.initial_values(), [0.5]);
    assert_eq!(m.initial_estimated(), [true]);
    let (mut fx, mut ft) = ([0.0], [0.0]);
    assert!(m.rhs_jacobians(0.0, &[3.0], &[1.0], &[2.0], &mut fx, &mut ft));
    assert_eq!((fx[0], ft[0]), (-2.0, -3.0));
    let (mut hx, mut ht) = ([0.0], [0.0]);
    assert!(m.output_jacobians(&[3.0], &[1.0], &[2.0], &mut hx, &mut ht));
    assert_eq!((hx[0], ht[0]), (1.0, 0.0));
}

/// The fused sensitivity right-hand side equals the default one (f, then the Jacobians,
/// then the products) to the bit: for the free parameters (restricted tape), for other
/// column lists (full tape), with and without initial-state columns.
#[test]
fn fused_sensitivities_equal_the_default() {
    let text = include_str!("../../../../../../../examples/equations/bouc_wen.toml");
    let m = EquationStateSpace::parse(text, "bouc_wen.toml").unwrap();
    let free: Vec<usize> = (0..6).collect();
    assert_eq!(m.parameters().free_indices(), free);
    let points = [
        ([1e-3, 0.05, 20.0], 30.0),
        ([-2e-3, -0.08, -35.0], -12.0),
        ([4e-4, 0.0, 0.0], 3.0),
    ];
    let lists: [(&[usize], usize); 5] = [
        (&free, 6),
        (&free, 8),
        (&[6, 0, 3], 4),
        (&[0, 1, 2, 3, 4, 5, 6], 7),
        (&[], 2),
    ];
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    for nu in [1.0, 1.3] {
        let mut theta = m.parameters().values();
        theta[6] = nu;
        for (x, u) in &points {
            for (params, q) in lists {
                let s: Vec<f64> = (0..3 * q).map(|i| (i as f64 * 0.37).sin()).collect();
                let mut scratch = JacobianScratch::new(3, 7);
                let (mut dx, mut ds) = ([0.0; 3], vec![0.0; 3 * q]);
                assert!(m.rhs_sensitivities(
                    0.1,
                    x,
                    &[*u],
                    &theta,
                    None,
                    params,
                    &s,
                    &mut scratch,
                    &mut dx,
                    &mut ds
                ));
                let (mut dx0, mut ds0) = ([0.0; 3], vec![0.0; 3 * q]);
                assert!(sensitivity::default_rhs_sensitivities(
                    &m,
                    0.1,
                    x,
                    &[*u],
                    &theta,
                    None,
                    params,
                    &s,
                    &mut scratch,
                    &mut dx0,
                    &mut ds0
                ));
                assert_eq!(bits(&dx), bits(&dx0), "ν {nu}, {params:?}");
                assert_eq!(bits(&ds), bits(&ds0), "ν {nu}, {params:?}, q {q}");
            }
        }
    }
}

#[test]
fn language_errors_keep_their_line_and_column() {
    let bad = DECAY.replace("-a*x", "-aa*x");
    let e = EquationStateSpace::parse(&bad, "decay.toml").unwrap_err();
    let Error::Equations(located) = &e else {
        panic!("{e}")
    };
    assert_eq!((located.line, located.column), (10, 7));
    assert!(
        e.to_string()
            .starts_with("decay.toml: line 10, column 7: unknown name 'aa'"),
        "{e}"
    );
}

#[test]
fn discrete_time_files_give_next_states() {
    let text = DECAY.replace("[model]\n", "[model]\ntime = \"discrete\"\n");
    let m = EquationStateSpace::parse(&text, "d.toml").unwrap();
    assert!(m.discrete_time());
    assert!(!EquationStateSpace::parse(DECAY, "c.toml")
        .unwrap()
        .discrete_time());
    let mut next = [0.0];
    m.rhs(0.0, &[3.0], &[1.0], &[2.0], &mut next);
    assert_eq!(next[0], -5.0);
}
