//! Tests of `hysid::model::operators::initial_state`: declared histories and what a model
//! file saves of them.

use hysid::model::operators::initial_state::{self, HISTORY_SAMPLES};
use hysid::model::operators::{
    BoucWen, HysteresisOperator, InitialState, InitialStateUsed, OperatorModel, Orientation,
    PrandtlIshlinskii,
};
use hysid::model::saved::{FittedModel, ModelFile};

#[test]
fn names_parse_back_and_a_bad_one_is_refused() {
    for s in InitialState::ALL {
        assert_eq!(InitialState::parse(s.name()).unwrap(), s);
    }
    assert_eq!(
        InitialState::parse("Demagnetized").unwrap(),
        InitialState::Demagnetised
    );
    let e = InitialState::parse("saturated").unwrap_err().to_string();
    assert!(e.contains("saturated") && e.contains("descending"), "{e}");
    assert_eq!(InitialState::default(), InitialState::Estimate);
}

#[test]
fn a_descending_history_puts_every_play_on_its_upper_edge() {
    // Γ = a0·u + Σ a_i F_ri[u]: after a descent from above, F_ri[u0] = u0 + r_i.
    let pi = PrandtlIshlinskii::new(
        0.5,
        vec![1.0, 2.0],
        vec![0.25, 0.5],
        0.0,
        Orientation::default(),
    )
    .unwrap();
    let u = [0.1, 0.3, -0.4];
    let y = initial_state::simulate(&pi, Some(InitialStateUsed::Descending), &u).unwrap();
    assert!(
        (y[0] - (0.5 * 0.1 + 1.0 * 0.35 + 2.0 * 0.6)).abs() < 1e-12,
        "{y:?}"
    );
    let y = initial_state::simulate(&pi, Some(InitialStateUsed::Ascending), &u).unwrap();
    assert!(
        (y[0] - (0.5 * 0.1 + 1.0 * -0.15 + 2.0 * -0.4)).abs() < 1e-12,
        "{y:?}"
    );
    assert_eq!(
        initial_state::history(&pi, InitialStateUsed::Descending, &u).len(),
        HISTORY_SAMPLES
    );
}

#[test]
fn a_descending_bouc_wen_start_is_near_negative_saturation_at_the_minimum() {
    // From far above down to u0 the state runs along its lower bound: w → −w_max.
    let bw = BoucWen::new(0.5, 1.0, 3.0, 1.0, 1.0).unwrap();
    let u = [-1.0, -0.5, 1.0];
    let y = initial_state::simulate(&bw, Some(InitialStateUsed::Descending), &u).unwrap();
    let w0 = y[0] + 0.5; // y = k_x·u + k_w·w with k_x = 0.5, u₀ = −1, k_w = 1
    assert!(
        (w0 + bw.w_max()).abs() < 1e-6,
        "w0 = {w0}, w_max = {}",
        bw.w_max()
    );
    // Demagnetised and estimated states are the structure's own (w0 = 0 here).
    for s in [
        None,
        Some(InitialStateUsed::Demagnetised),
        Some(InitialStateUsed::Estimated),
    ] {
        assert_eq!(
            initial_state::simulate(&bw, s, &u).unwrap(),
            bw.simulate(&u).unwrap()
        );
    }
}

#[test]
fn a_model_file_saves_the_state_and_a_file_without_it_reads_as_before() {
    let bw = BoucWen::new(0.5, 1.0, 3.0, 1.0, 1.0).unwrap();
    let u = [-1.0, -0.5, 1.0, 0.2];
    let plain = FittedModel::operator(OperatorModel::BoucWen(bw.clone()), vec![f64::NAN; 7]);
    let file = plain.to_file();
    let text = serde_json::to_string(&file).unwrap();
    assert!(!text.contains("initial_state"), "{text}");
    let back = FittedModel::from_file(&serde_json::from_str::<ModelFile>(&text).unwrap()).unwrap();
    assert_eq!(
        back.simulate(&[&u], 1.0, None).unwrap()[0],
        bw.simulate(&u).unwrap()
    );

    let declared = plain.with_initial_state(Some(InitialStateUsed::Descending), None);
    let text = serde_json::to_string(&declared.to_file()).unwrap();
    assert!(text.contains("\"initial_state\":\"descending\""), "{text}");
    let back = FittedModel::from_file(&serde_json::from_str::<ModelFile>(&text).unwrap()).unwrap();
    let expected = initial_state::simulate(&bw, Some(InitialStateUsed::Descending), &u).unwrap();
    assert_eq!(back.simulate(&[&u], 1.0, None).unwrap()[0], expected);
    assert_ne!(expected, bw.simulate(&u).unwrap());
}
