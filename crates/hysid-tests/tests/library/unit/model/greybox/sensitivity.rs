//! Tests of `hysid::model::greybox::sensitivity`.

use hysid::model::greybox::models::BoucWen;
use hysid::model::greybox::sensitivity::*;
use hysid::model::greybox::StateSpaceModel;

/// The Bouc–Wen model's fused sensitivity right-hand side equals the default one built
/// from its Jacobians, to the last bit, with ν = 1 (the special case) and ν = 1.3, for
/// every parameter column plus an initial-state column.
#[test]
fn fused_bouc_wen_sensitivities_equal_the_default() {
    let points = [
        ([1e-3, 0.05, 20.0], 30.0),
        ([-2e-3, -0.08, -35.0], -12.0),
        ([4e-4, 0.0, 0.0], 3.0),
    ];
    let params: Vec<usize> = (0..7).collect();
    let q = params.len() + 1;
    let s: Vec<f64> = (0..3 * q).map(|i| (i as f64 * 0.37).sin()).collect();
    for nu in [1.0, 1.3] {
        let mut theta = BoucWen.parameters().values();
        theta[6] = nu;
        for (x, u) in &points {
            let mut scratch = JacobianScratch::new(3, 7);
            let (mut dx, mut ds) = ([0.0; 3], vec![0.0; 3 * q]);
            let (mut dx_ref, mut ds_ref) = ([0.0; 3], vec![0.0; 3 * q]);
            assert!(BoucWen.rhs_sensitivities(
                0.0,
                x,
                &[*u],
                &theta,
                None,
                &params,
                &s,
                &mut scratch,
                &mut dx,
                &mut ds
            ));
            assert!(default_rhs_sensitivities(
                &BoucWen,
                0.0,
                x,
                &[*u],
                &theta,
                None,
                &params,
                &s,
                &mut scratch,
                &mut dx_ref,
                &mut ds_ref
            ));
            assert_eq!(dx, dx_ref, "ν = {nu}, x = {x:?}");
            assert_eq!(ds, ds_ref, "ν = {nu}, x = {x:?}");
        }
    }
}
