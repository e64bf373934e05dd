//! The models exported by the tests and what the library says they do.

use hysid::export::ExportOptions;
use hysid::model::coleman_hodgdon::InitialOutput;
use hysid::model::compensate::compensate;
use hysid::model::operators::{MaxwellSlip, OperatorModel, Orientation, Preisach};
use hysid::model::saved::{Columns, FittedModel, ModelFile};
use hysid::model::saved::{FittedCascade, FittedHysteresis, FittedOperatorCascade};
use hysid::model::{ColemanHodgdon, HysteresisCascade, LinearBlock, OperatorCascade};
use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};

/// The bar: max |generated − library| ÷ (max − min of the library's signal).
pub const BAR: f64 = 1e-12;

/// One export to check.
#[derive(Clone)]
pub struct Case {
    /// The export name (also the label in the table).
    pub name: String,
    /// The model file.
    pub file: ModelFile,
    /// The export options.
    pub options: ExportOptions,
    /// The step's input signal.
    pub input: Vec<f64>,
    /// What the library gives for it.
    pub expected: Vec<f64>,
    /// For a compensator: the library's `Compensator::clipped` after the same references.
    pub clipped: Option<usize>,
}

/// A seeded input with nested minor loops over about ±1, `n` samples.
pub fn signal(n: usize, seed: u64) -> Vec<f64> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let tau = std::f64::consts::TAU;
    (0..n)
        .map(|k| {
            let t = k as f64;
            let envelope = 0.6 + 0.4 * (tau * t / 1700.0).cos();
            0.85 * envelope * (tau * t / 500.0).sin()
                + 0.12 * (tau * t / 37.0).sin()
                + 0.01 * rng.random_range(-1.0..1.0)
        })
        .collect()
}

/// The operator with its orientation flipped to the clockwise, decreasing one (for the
/// families whose structure has an `orientation` of that form).
fn flipped(op: &OperatorModel) -> Option<OperatorModel> {
    let mut structure = op.structure().ok()?;
    let o = structure.get_mut("orientation")?.as_object_mut()?;
    o.get("inverse")?;
    o.insert("inverse".into(), true.into());
    o.insert("decreasing".into(), true.into());
    OperatorModel::from_structure(op.family().name(), &structure).ok()
}

fn file_of(model: &FittedModel) -> ModelFile {
    model.to_file()
}

/// The model's forward case and, where it has an inverse, its compensator's case (fed the
/// reference `preview` samples ahead: the linear block's delay of an operator cascade).
fn cases_of(label: &str, model: &FittedModel, input: &[f64]) -> Vec<Case> {
    let preview = match model {
        FittedModel::OperatorCascade(FittedOperatorCascade { model, .. }) => model.linear.delay(),
        _ => 0,
    };
    let file = file_of(model);
    let simulated = model
        .simulate(&[input], 1e-3, input.first().copied())
        .unwrap_or_else(|e| panic!("{label}: the library's simulate failed: {e}"));
    let y = simulated[0].clone();
    let mut out = vec![Case {
        clipped: None,
        name: format!("{label}_forward"),
        file: file.clone(),
        options: ExportOptions {
            sample_time: Some(1e-3),
            ..ExportOptions::default()
        },
        input: input.to_vec(),
        expected: y.clone(),
    }];
    if let Ok(comp) = compensate(model, &y) {
        let shifted = |r: &[f64]| -> Vec<f64> {
            (0..r.len())
                .map(|s| r[(s + preview).min(r.len() - 1)])
                .collect()
        };
        let inverse = |name: String, input: Vec<f64>, expected: Vec<f64>| Case {
            name,
            file: file.clone(),
            options: ExportOptions {
                inverse: true,
                sample_time: Some(1e-3),
                ..ExportOptions::default()
            },
            clipped: Some(library_clipped(model, &input)),
            input,
            expected,
        };
        out.push(inverse(format!("{label}_inverse"), shifted(&y), comp.u));
        // A reference beyond the reachable range (2.5 times the output, and a jump every 97
        // samples), where the compensators clip: the command and the clipped count.
        let beyond: Vec<f64> = y
            .iter()
            .enumerate()
            .map(|(s, v)| 2.5 * v + if s % 97 == 50 { 3.0 } else { 0.0 })
            .collect();
        if let Ok(comp) = compensate(model, &beyond) {
            out.push(inverse(format!("{label}_beyond"), shifted(&beyond), comp.u));
        }
    }
    out
}

/// The library's streaming compensator's `clipped()` after the references `input` (already
/// read ahead by its preview).
fn library_clipped(model: &FittedModel, input: &[f64]) -> usize {
    let mut comp = model.compensator(1e-3).expect("a compensator");
    for r in input {
        comp.step(*r).expect("the library's compensator step");
    }
    comp.clipped()
}

/// A stable, minimum-phase linear block with a delay.
pub fn block() -> LinearBlock {
    LinearBlock::new(vec![-0.6, 0.08], vec![1.0, 0.4], 1).expect("a valid block")
}

/// A Coleman–Hodgdon hysteresis (ch6) whose rate limit the test signal respects.
fn hysteresis() -> ColemanHodgdon {
    ColemanHodgdon::general(2.0, 1.0, 0.3, 0.4, 0.1, 0.5).expect("a valid hysteresis")
}

/// The model kinds besides the operators: operator cascades (one per family), the
/// Coleman–Hodgdon hysteresis (from 0, and from the measured output given at export) and
/// its cascade.
fn kinds(u: &[f64]) -> Vec<Case> {
    use rayon::prelude::*;
    let examples = OperatorModel::examples().expect("the registry's examples");
    let cascades: Vec<Vec<Case>> = examples
        .into_par_iter()
        .map(|op| {
            let label = format!("cascade_{}", op.family().name().replace('-', "_"));
            let cascade = OperatorCascade::new(op, block()).expect("a cascade");
            let n = cascade.parameters().len();
            let model = FittedModel::OperatorCascade(FittedOperatorCascade {
                model: cascade,
                std: vec![f64::NAN; n],
            });
            cases_of(&label, &model, u)
        })
        .collect();
    let mut out: Vec<Case> = cascades.into_iter().flatten().collect();
    // Maxwell-slip without a linear spring saturates: the PI inverse is the per-sample solve.
    let saturating = MaxwellSlip::new(
        0.0,
        vec![1.0, 0.5],
        vec![0.1, 0.4],
        0.0,
        Orientation::default(),
    )
    .expect("a valid Maxwell-slip operator");
    let model = FittedModel::operator(saturating.clone().into(), vec![f64::NAN; 6]);
    out.extend(cases_of("maxwell_slip_saturating", &model, u));
    // A Preisach plane without its linear term saturates too, and so does a cascade with the
    // saturating Maxwell-slip operator: their references beyond reach clip. (A PI operator
    // never saturates: its plays follow the input, every reference is reachable.)
    let weights = vec![0.1, 0.2, 0.05, 0.3, 0.1, 0.15];
    let preisach = Preisach::new(-1.0, 1.0, 3, weights, 0.0, 0.0, Orientation::default())
        .expect("a valid Preisach operator");
    let op = OperatorModel::from(preisach);
    let n = op.as_operator().parameters().len();
    let model = FittedModel::operator(op, vec![f64::NAN; n]);
    out.extend(cases_of("preisach_saturating", &model, u));
    let cascade = OperatorCascade::new(saturating.into(), block()).expect("a cascade");
    let n = cascade.parameters().len();
    let model = FittedModel::OperatorCascade(FittedOperatorCascade {
        model: cascade,
        std: vec![f64::NAN; n],
    });
    out.extend(cases_of("cascade_maxwell_slip_saturating", &model, u));
    let ch = hysteresis();
    let n = ch.params().len();
    for (label, initial) in [
        ("ch", InitialOutput::Zero),
        ("ch_measured", InitialOutput::Measured),
    ] {
        let model = FittedModel::Hysteresis(FittedHysteresis {
            model: ch.clone(),
            initial,
            std: vec![f64::NAN; n],
        });
        let mut cases = cases_of(label, &model, u);
        if initial == InitialOutput::Measured {
            // The forward step starts from the measured y(0) given at export (`--y0`), the
            // value `simulate` was given (the record's first sample, in `cases_of`).
            for case in cases.iter_mut().filter(|c| !c.options.inverse) {
                case.options.initial_output = u.first().copied();
            }
        }
        out.extend(cases);
    }
    let cascade = HysteresisCascade::new(ch, block()).expect("a cascade");
    let n = cascade.params().len();
    out.extend(cases_of(
        "ch_cascade",
        &FittedModel::Cascade(FittedCascade {
            model: cascade,
            std: vec![f64::NAN; n],
        }),
        u,
    ));
    out
}

/// Every case: each family of the registry (its example, and its clockwise-decreasing form
/// where it has one), forward and inverse; then the other kinds; then the grey-box and
/// equation-file models ([`crate::greybox`]).
pub fn all() -> Vec<Case> {
    // Made once per test binary (its library runs are most of a fast export test's time):
    // the tests that read it run in parallel, and each takes its own copy.
    static ALL: std::sync::OnceLock<Vec<Case>> = std::sync::OnceLock::new();
    ALL.get_or_init(|| {
        let mut out = all_on(&signal(3000, 27));
        out.extend(crate::greybox::cases());
        out
    })
    .clone()
}

/// The cases of the registry's first example, the PI operator (`pi_forward`, `pi_inverse`,
/// `pi_beyond`), as [`all`] makes them.
pub fn pi() -> Vec<Case> {
    let op = OperatorModel::examples().expect("examples").remove(0);
    let n = op.as_operator().parameters().len();
    cases_of(
        "pi",
        &FittedModel::operator(op, vec![f64::NAN; n]),
        &signal(3000, 27),
    )
}

/// The models the instruction bars are stated for (`tools/arm/run.py`), forward and
/// inverse: a PI operator of 10 plays (`size_pi_10_plays`) and a 20 × 20 Preisach plane with
/// its linear term (`size_preisach_20`), each of the shape a fit of a piezo record gives —
/// thresholds spread over the range, weights falling with the threshold; a Preisach density
/// largest near the diagonal, falling with the loop's width α − β and off its centre.
pub fn sized() -> Vec<Case> {
    use hysid::model::operators::PrandtlIshlinskii as Pi;
    let u = signal(3000, 27);
    let thresholds: Vec<f64> = (1..=10).map(|i| 0.09 * i as f64).collect();
    let weights: Vec<f64> = (0..10).map(|i| 0.4 / (1.0 + i as f64)).collect();
    let pi = Pi::new(0.3, weights, thresholds, 0.05, Orientation::default()).expect("a PI");
    let n = 20;
    let h = 2.0 / n as f64;
    let mut density = Vec::new();
    for i in 0..n {
        for j in 0..=i {
            let (alpha, beta) = (-1.0 + (i as f64 + 0.5) * h, -1.0 + (j as f64 + 0.5) * h);
            let width = alpha - beta;
            let centre = 0.5 * (alpha + beta);
            density.push(0.02 * (-width / 0.6).exp() * (-centre * centre / 0.5).exp());
        }
    }
    let preisach =
        Preisach::new(-1.0, 1.0, n, density, 0.2, 0.0, Orientation::default()).expect("Preisach");
    let mut out = Vec::new();
    for (label, op) in [
        ("size_pi_10_plays", OperatorModel::from(pi)),
        ("size_preisach_20", OperatorModel::from(preisach)),
    ] {
        let n = op.as_operator().parameters().len();
        out.extend(cases_of(
            label,
            &FittedModel::operator(op, vec![f64::NAN; n]),
            &u,
        ));
    }
    out
}

/// The operator `op` after a declared descending and an ascending history with the turn a fit
/// on `u` saves (`history_turn`): the forward step runs the history at its first sample, the
/// compensators of the families whose memory wipes out take its priming reference and a
/// differential family's first command runs the history on each trial, as the library does.
/// (Jiles–Atherton's example, whose memory reach is 10⁴ times the signal's span, is left
/// out: its history alone takes the library seconds.)
fn after_histories(label: &str, op: &OperatorModel, u: &[f64]) -> Vec<Case> {
    use hysid::model::operators::initial_state::History;
    use hysid::model::operators::InitialStateUsed;
    if op.family().name() == "jiles-atherton" {
        return Vec::new();
    }
    let n = op.as_operator().parameters().len();
    [InitialStateUsed::Descending, InitialStateUsed::Ascending]
        .iter()
        .flat_map(|&state| {
            let turn = state.turning_input(op.as_operator(), u);
            let model = FittedModel::operator(op.clone(), vec![f64::NAN; n])
                .with_initial_state(Some(state), turn);
            let history = History::of(Some(state), turn);
            assert!(op.history_reaches_the_inverse(history), "{label}");
            cases_of(&format!("{label}_{}", state.name()), &model, u)
        })
        .collect()
}

/// The cases of [`all`] but the grey-box ones, on the forward input `u` (the compensators'
/// references are the models' outputs for it).
pub fn all_on(u: &[f64]) -> Vec<Case> {
    use rayon::prelude::*;
    // The families in parallel (a compensator's library run is most of the time), in order.
    let examples = OperatorModel::examples().expect("the registry's examples");
    let families: Vec<Vec<Case>> = examples
        .par_iter()
        .map(|op| {
            let label = op.family().name().replace('-', "_");
            let model = FittedModel::operator(
                op.clone(),
                vec![f64::NAN; op.as_operator().parameters().len()],
            );
            let mut out = cases_of(&label, &model, u);
            out.extend(after_histories(&label, op, u));
            if let Some(cw) = flipped(op) {
                let n = cw.as_operator().parameters().len();
                let model = FittedModel::operator(cw, vec![f64::NAN; n]);
                out.extend(cases_of(&format!("{label}_cw"), &model, u));
            }
            out
        })
        .collect();
    let mut out: Vec<Case> = families.into_iter().flatten().collect();
    // The structures the examples do not show (a PI with a static envelope: `pi_envelope`).
    for (variant, op) in OperatorModel::variants().expect("the registry's variants") {
        let label = format!("{}_{variant}", op.family().name().replace('-', "_"));
        let n = op.as_operator().parameters().len();
        out.extend(cases_of(
            &label,
            &FittedModel::operator(op.clone(), vec![f64::NAN; n]),
            u,
        ));
        out.extend(after_histories(&label, &op, u));
        if let Some(cw) = flipped(&op) {
            let n = cw.as_operator().parameters().len();
            let model = FittedModel::operator(cw, vec![f64::NAN; n]);
            out.extend(cases_of(&format!("{label}_cw"), &model, u));
        }
    }
    out.extend(kinds(u));
    out
}

/// The library's model of `case`, as its export runs it: the file's model, re-stepped when
/// the case is exported at another sample time than the file's (`FittedModel::resampled`).
pub fn model_of(case: &Case) -> FittedModel {
    let model = FittedModel::from_file(&case.file).expect("the case's model");
    match (case.file.sample_time, case.options.sample_time) {
        (Some(fitted), Some(ts)) if fitted != ts => model
            .resampled(fitted, ts)
            .unwrap_or_else(|| panic!("{}: not re-stepped", case.name)),
        _ => model,
    }
}

/// A PI operator's model file with the data's sample time and column names.
pub fn named_pi() -> ModelFile {
    let op = OperatorModel::examples().expect("examples").remove(0);
    let n = op.as_operator().parameters().len();
    FittedModel::operator(op, vec![f64::NAN; n])
        .to_file()
        .with_data(
            1e-4,
            Columns {
                inputs: vec!["voltage".into()],
                outputs: vec!["position".into()],
            },
        )
}

/// max |a − b| ÷ (max − min of b); infinite when the lengths differ.
pub fn relative_difference(got: &[f64], expected: &[f64]) -> f64 {
    if got.len() != expected.len() {
        return f64::INFINITY;
    }
    let (lo, hi) = expected
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
            (l.min(*v), h.max(*v))
        });
    let diff = got
        .iter()
        .zip(expected)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    diff / (hi - lo)
}

/// The input as text, one round-trip decimal a line.
pub fn input_text(input: &[f64]) -> String {
    input.iter().map(|v| format!("{v:?}\n")).collect()
}

/// The clipped count a driver printed for a compensator (a line `clipped N`), if any.
pub fn parse_clipped(text: &str) -> Option<usize> {
    text.lines()
        .find_map(|l| l.trim().strip_prefix("clipped "))
        .map(|n| n.parse().expect("a count"))
}

/// The fault count a driver printed (a line `faults N`), if any.
pub fn parse_faults(text: &str) -> Option<usize> {
    text.lines()
        .find_map(|l| l.trim().strip_prefix("faults "))
        .map(|n| n.parse().expect("a count"))
}

/// The outputs a driver printed, one a line; a line `error` when the diverged flag was set,
/// a line `faults N` (the bad samples: [`parse_faults`]) and, for a compensator, a line
/// `clipped N` ([`parse_clipped`]).
pub fn parse_outputs(text: &str) -> (Vec<f64>, bool) {
    let mut error = false;
    let mut values = Vec::new();
    for line in text
        .lines()
        .filter(|l| !l.starts_with("clipped ") && !l.starts_with("faults "))
    {
        if line.trim() == "error" {
            error = true;
        } else {
            values.push(line.trim().parse::<f64>().unwrap_or(f64::NAN));
        }
    }
    (values, error)
}

/// The cases whose generated Rust cannot meet [`BAR`], with their own bar and why: the
/// `libm` crate's `pow` differs from the platform's by an ulp, and the Newmark corrector's
/// stopping rule (|residual| ≤ 1e-13 of the unknowns) turns that ulp into a difference of its
/// tolerance at some steps, which the hysteresis integrates (measured 2.8e-8; the C, with the
/// platform's `pow`, is bit-identical).
///
/// The same holds for the Bouc–Wen operator's compensator on references beyond its reach
/// (measured 1.2e-10 alone, 6.2e-11 in a cascade): its per-sample solve searches the closest
/// output of a `pow`-based branch, and an ulp there moves the best point found; and after a
/// declared history (measured 8.9e-10 descending, 3.4e-10 and 4.4e-10 beyond reach), whose
/// first command integrates each trial's long excursion to the turn, where an ulp of `pow`
/// in the step control flips a sub-step's acceptance.
pub const RUST_EXCEPTIONS: [(&str, f64); 6] = [
    ("gb_bouc_wen_newmark_nu", 1e-7),
    ("bouc_wen_beyond", 1e-9),
    ("cascade_bouc_wen_beyond", 1e-9),
    ("bouc_wen_descending_inverse", 2e-9),
    ("bouc_wen_descending_beyond", 1e-9),
    ("bouc_wen_ascending_beyond", 1e-9),
];

/// The bar of `case` in `target`: [`BAR`], or its entry in [`RUST_EXCEPTIONS`] for Rust.
pub fn bar(target: &str, case: &str) -> f64 {
    RUST_EXCEPTIONS
        .iter()
        .find(|(name, _)| target == "Rust" && *name == case)
        .map_or(BAR, |(_, bar)| *bar)
}

/// Checks every result against its bar ([`bar`]), after printing the table of figures.
pub fn check(target: &str, results: &[(String, f64, bool)]) {
    println!("{target}: max |generated - library| / range");
    for (name, d, error) in results {
        println!(
            "  {name:<28} {d:.3e}{}",
            if *error { "  (error flag)" } else { "" }
        );
    }
    let bad: Vec<String> = results
        .iter()
        .filter(|(n, d, error)| *error || d.is_nan() || *d > bar(target, n))
        .map(|(n, d, _)| format!("{n} ({d:e} > {:e})", bar(target, n)))
        .collect();
    assert!(
        bad.is_empty(),
        "{target}: above the bar: {}",
        bad.join(", ")
    );
}

/// Checks the clipped count of every compensator against the library's, after printing them;
/// those of [`MUST_CLIP`] must be positive.
pub fn check_clipped(target: &str, cases: &[Case], got: &[Option<usize>]) {
    println!("{target}: clipped steps, generated vs library");
    let mut bad = Vec::new();
    for (case, got) in cases.iter().zip(got) {
        let Some(expected) = case.clipped else {
            continue;
        };
        println!("  {:<28} {got:?} vs {expected}", case.name);
        if *got != Some(expected) {
            bad.push(format!("{} ({got:?} vs {expected})", case.name));
        }
    }
    assert!(
        bad.is_empty(),
        "{target}: clipped counts differ: {}",
        bad.join(", ")
    );
    for name in MUST_CLIP {
        let case = cases.iter().find(|c| c.name == name);
        assert!(
            case.is_some_and(|c| c.clipped.is_some_and(|n| n > 0)),
            "{name}: the reference beyond reach should clip"
        );
    }
}

/// The compensators whose reference beyond reach must clip (a saturating Preisach plane and
/// Maxwell-slip operator, the Coleman–Hodgdon hysteresis from 0 and from the measured output,
/// an operator cascade, a clockwise backlash, Dahl).
const MUST_CLIP: [&str; 7] = [
    "preisach_saturating_beyond",
    "maxwell_slip_saturating_beyond",
    "ch_beyond",
    "ch_measured_beyond",
    "cascade_maxwell_slip_saturating_beyond",
    "backlash_cw_beyond",
    "dahl_beyond",
];
