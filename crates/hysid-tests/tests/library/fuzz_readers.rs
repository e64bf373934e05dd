//! Property tests of the readers: CSV, MAT and model files, random or mutated from valid
//! ones. Whatever the bytes, a reader returns a typed error or data that are finite and
//! consistent — it never panics, never hangs and never hands NaN or ±∞ on.
//!
//! Fixed seeds; 1 000 cases per reader in the fast test command, and 10 000 in CI's long step
//! (`HYSID_FUZZ_CASES=10000`, see `.ci/run`). Each case is a small file read in memory or from
//! a temporary directory.

use hysid::data::{CsvSpec, IdData};
use hysid::model::greybox::models;
use hysid::model::saved::FittedModel;
use hysid::model::saved::{FittedCascade, FittedGreyBox, FittedHysteresis};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};
use std::io::Read;
use std::path::{Path, PathBuf};

/// Cases per reader: `HYSID_FUZZ_CASES` when set (CI sets 10 000), else 1 000.
fn cases() -> u32 {
    std::env::var("HYSID_FUZZ_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1_000)
}

fn config(seed: u64) -> Config {
    Config {
        cases: cases(),
        rng_seed: RngSeed::Fixed(seed),
        failure_persistence: None,
        max_shrink_iters: 2_000,
        ..Config::default()
    }
}

fn spec(inputs: &[&str], outputs: &[&str]) -> CsvSpec {
    CsvSpec {
        inputs: inputs.iter().map(|s| s.to_string()).collect(),
        outputs: outputs.iter().map(|s| s.to_string()).collect(),
        ..CsvSpec::default()
    }
}

/// What a reader may return: an error of one line, or finite, consistent data.
fn check_data(result: hysid::Result<IdData>) -> Result<(), TestCaseError> {
    match result {
        Err(e) => {
            let m = e.to_string();
            prop_assert!(!m.is_empty() && !m.contains('\n'), "not one line: {m:?}");
        }
        Ok(data) => {
            prop_assert!(data.ts().is_finite() && data.ts() > 0.0, "ts {}", data.ts());
            for k in 0..data.n_experiments() {
                let exp = data.experiment(k);
                prop_assert!(!exp.is_empty());
                for c in 0..data.input_channels().len() {
                    prop_assert!(exp.input(c).len() == exp.len());
                    prop_assert!(exp.input(c).iter().all(|v| v.is_finite()));
                }
                for c in 0..data.output_channels().len() {
                    prop_assert!(exp.output(c).len() == exp.len());
                    prop_assert!(exp.output(c).iter().all(|v| v.is_finite()));
                }
            }
        }
    }
    Ok(())
}

/// A scratch file rewritten by every case of one test.
fn scratch(name: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    (dir, path)
}

// ---------------------------------------------------------------------------------------
// CSV

/// A cell: numbers, non-finite and huge spellings, text, blanks.
fn cell() -> impl Strategy<Value = String> {
    prop_oneof![
        4 => (-1e3f64..1e3).prop_map(|v| v.to_string()),
        1 => Just("nan".to_string()),
        1 => Just("NaN".to_string()),
        1 => Just("inf".to_string()),
        1 => Just("-inf".to_string()),
        1 => Just("1e308".to_string()),
        1 => Just("1e309".to_string()),
        1 => Just("-1e308".to_string()),
        1 => Just("1e-320".to_string()),
        1 => Just(String::new()),
        1 => Just(" 2.5 ".to_string()),
        1 => Just("abc".to_string()),
        1 => Just("\"1,5\"".to_string()),
        1 => Just("0x10".to_string()),
    ]
}

/// A header name: the wanted ones (also twice), others, a huge one, odd spacing.
fn header_name() -> impl Strategy<Value = String> {
    prop_oneof![
        3 => Just("u".to_string()),
        3 => Just("y".to_string()),
        2 => Just("t".to_string()),
        1 => Just(" u ".to_string()),
        1 => Just("U".to_string()),
        1 => Just("\u{feff}u".to_string()),
        1 => Just("x".repeat(5_000)),
        1 => Just(String::new()),
        1 => Just("\"y\"".to_string()),
    ]
}

/// A structured but wrong CSV text: BOM, header, ragged rows, mixed line ends.
fn csv_text() -> impl Strategy<Value = String> {
    let line_end = prop_oneof![Just("\n"), Just("\r\n"), Just("\r")];
    (
        any::<bool>(),
        prop::collection::vec(header_name(), 0..5),
        prop::collection::vec((prop::collection::vec(cell(), 0..6), line_end), 0..12),
        prop_oneof![Just(","), Just(";"), Just("\t")],
    )
        .prop_map(|(bom, header, rows, sep)| {
            let mut text = String::new();
            if bom {
                text.push('\u{feff}');
            }
            text.push_str(&header.join(sep));
            text.push('\n');
            for (cells, end) in rows {
                text.push_str(&cells.join(sep));
                text.push_str(end);
            }
            text
        })
}

proptest! {
    #![proptest_config(config(0x5eed_c5f1))]

    #[test]
    fn csv_random_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..256)) {
        let (_dir, path) = scratch("random.csv");
        std::fs::write(&path, &bytes).unwrap();
        check_data(IdData::from_csv(&path, &spec(&["u"], &["y"])))?;
    }
}

proptest! {
    #![proptest_config(config(0x5eed_c5f2))]

    #[test]
    fn csv_structured_but_wrong_never_panics_nor_passes_non_finite(
        text in csv_text(),
        with_time in any::<bool>(),
    ) {
        let (_dir, path) = scratch("structured.csv");
        std::fs::write(&path, text.as_bytes()).unwrap();
        let mut s = spec(&["u"], &["y"]);
        if with_time {
            s.time = Some("t".into());
        }
        check_data(IdData::from_csv(&path, &s))?;
    }
}

// ---------------------------------------------------------------------------------------
// MAT

fn fixture() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/piezo_150V_1Hz.mat")
}

fn le32(bytes: &[u8], at: usize) -> usize {
    u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize
}

/// The fixture with every compressed element inflated: the same variables, uncompressed,
/// so that mutations reach the array parser instead of the zlib check.
fn uncompressed_fixture(compressed: &[u8]) -> Vec<u8> {
    let mut out = compressed[..128].to_vec();
    let mut at = 128;
    while at + 8 <= compressed.len() {
        let (kind, len) = (le32(compressed, at), le32(compressed, at + 4));
        let data = &compressed[at + 8..at + 8 + len];
        if kind == 15 {
            let mut inflated = Vec::new();
            libflate::zlib::Decoder::new(data)
                .unwrap()
                .read_to_end(&mut inflated)
                .unwrap();
            out.extend_from_slice(&inflated);
        } else {
            out.extend_from_slice(&compressed[at..at + 8 + len]);
        }
        while !out.len().is_multiple_of(8) {
            out.push(0);
        }
        at += 8 + len;
    }
    out
}

/// Flip, overwrite, truncate, splice or insert, at positions drawn from `picks`.
#[derive(Clone, Debug)]
enum Mutation {
    Flip(usize, u8),
    Set(usize, u8),
    Truncate(usize),
    Splice(usize, usize, usize),
    Insert(usize, Vec<u8>),
    SetWord(usize, u32),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        3 => (any::<usize>(), 1u8..).prop_map(|(p, b)| Mutation::Flip(p, b)),
        2 => (any::<usize>(), any::<u8>()).prop_map(|(p, b)| Mutation::Set(p, b)),
        1 => any::<usize>().prop_map(Mutation::Truncate),
        1 => (any::<usize>(), any::<usize>(), 0usize..256)
            .prop_map(|(a, b, n)| Mutation::Splice(a, b, n)),
        1 => (any::<usize>(), prop::collection::vec(any::<u8>(), 1..16))
            .prop_map(|(p, v)| Mutation::Insert(p, v)),
        2 => (any::<usize>(), prop_oneof![
                Just(0u32), Just(1), Just(7), Just(u32::MAX), Just(0x7fff_ffff),
                Just(0x8000_0000), Just(14), Just(15), Just(1 << 20)
            ]).prop_map(|(p, w)| Mutation::SetWord(p, w)),
    ]
}

fn apply(bytes: &mut Vec<u8>, m: &Mutation) {
    let n = bytes.len().max(1);
    match m {
        Mutation::Flip(p, b) => {
            if let Some(x) = bytes.get_mut(p % n) {
                *x ^= b;
            }
        }
        Mutation::Set(p, b) => {
            if let Some(x) = bytes.get_mut(p % n) {
                *x = *b;
            }
        }
        Mutation::Truncate(p) => bytes.truncate(p % n),
        Mutation::Splice(a, b, len) => {
            let (a, b) = (a % n, b % n);
            let chunk: Vec<u8> = bytes.iter().skip(a).take(*len).copied().collect();
            let end = (b + chunk.len()).min(bytes.len());
            bytes.splice(b..end, chunk);
        }
        Mutation::Insert(p, v) => {
            let p = (p % n).min(bytes.len());
            bytes.splice(p..p, v.iter().copied());
        }
        Mutation::SetWord(p, w) => {
            // Aligned to 4 bytes: tags, sizes and dimensions are words.
            let p = (p % n) / 4 * 4;
            if p + 4 <= bytes.len() {
                bytes[p..p + 4].copy_from_slice(&w.to_le_bytes());
            }
        }
    }
}

proptest! {
    #![proptest_config(config(0x5eed_3a71))]

    #[test]
    fn mat_mutated_fixtures_never_panic_nor_pass_non_finite(
        compressed in any::<bool>(),
        mutations in prop::collection::vec(mutation(), 1..4),
        column in prop_oneof![
            Just("voltage_V"), Just("record(:,2)"), Just("z"), Just("t"), Just("displacement_um")
        ],
    ) {
        thread_local! {
            static FIXTURES: (Vec<u8>, Vec<u8>) = {
                let c = std::fs::read(fixture()).unwrap();
                let u = uncompressed_fixture(&c);
                (c, u)
            };
        }
        let mut bytes = FIXTURES.with(|(c, u)| if compressed { c.clone() } else { u.clone() });
        for m in &mutations {
            apply(&mut bytes, m);
        }
        let path = Path::new("mutated.mat");
        check_data(IdData::from_mat_bytes(path, &bytes, &spec(&[column], &[])))?;
    }

    #[test]
    fn mat_random_bodies_never_panic(body in prop::collection::vec(any::<u8>(), 0..512)) {
        let mut bytes = std::fs::read(fixture()).unwrap()[..128].to_vec();
        bytes.extend_from_slice(&body);
        check_data(IdData::from_mat_bytes(Path::new("random.mat"), &bytes, &spec(&["u"], &[])))?;
    }
}

#[test]
fn the_uncompressed_fixture_reads_as_the_compressed_one() {
    // The test's own inflating must be right for its mutations to mean anything.
    let c = std::fs::read(fixture()).unwrap();
    let u = uncompressed_fixture(&c);
    let s = spec(&["voltage_V"], &["record(:,2)"]);
    let a = IdData::from_mat_bytes(Path::new("c.mat"), &c, &s).unwrap();
    let b = IdData::from_mat_bytes(Path::new("c.mat"), &u, &s).unwrap();
    assert_eq!(a.input(0, 0), b.input(0, 0));
    assert_eq!(a.output(0, 0), b.output(0, 0));
    assert_eq!(a.input(0, 0).len(), 2000);
}

#[test]
fn a_decompression_bomb_is_refused_with_the_figure_and_the_limit() {
    // One element of 40 MiB of zeros in 40 kB (tools/reference/bomb_fixture.py): far past
    // 64 times the file and 16 MiB.
    let stream = std::fs::read(fixture().with_file_name("bomb_40MiB.zlib")).unwrap();
    let mut bytes = std::fs::read(fixture()).unwrap()[..128].to_vec();
    bytes.extend_from_slice(&15u32.to_le_bytes());
    bytes.extend_from_slice(&(stream.len() as u32).to_le_bytes());
    bytes.extend_from_slice(&stream);
    let e = IdData::from_mat_bytes(Path::new("bomb.mat"), &bytes, &spec(&["u"], &[]))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("decompresses to more than 16777216 bytes") && e.contains("bomb.mat"),
        "{e}"
    );
    assert_eq!(e.lines().count(), 1);
}

// ---------------------------------------------------------------------------------------
// Model files

/// Valid model files of every kind, as JSON values (written by the library itself).
fn valid_models() -> Vec<serde_json::Value> {
    use hysid::model::coleman_hodgdon::InitialOutput;
    use hysid::model::greybox::Simulation;
    use hysid::model::{ChForm, ColemanHodgdon, HysteresisCascade, LinearBlock};
    let ch4 = ColemanHodgdon::from_params(ChForm::Saturated4, &[0.3, 1.0, 0.5, 3.0]).unwrap();
    let ch6 =
        ColemanHodgdon::from_params(ChForm::General6, &[0.3, 1.0, 0.5, 3.0, 0.2, 0.1]).unwrap();
    let linear = LinearBlock::new(vec![-0.6, 0.2], vec![1.0, 0.5], 1).unwrap();
    let mut fitted = vec![
        FittedModel::Hysteresis(FittedHysteresis {
            model: ch4,
            initial: InitialOutput::Zero,
            std: vec![0.01; 4],
        }),
        FittedModel::Cascade(FittedCascade {
            model: HysteresisCascade::new(ch6, linear).unwrap(),
            std: vec![0.01; 9],
        }),
    ];
    for kind in ["bouc_wen", "rigid_body"] {
        let model = models::by_kind(kind).unwrap();
        let parameters = model.parameters();
        fitted.push(FittedModel::GreyBox(FittedGreyBox {
            kind: kind.into(),
            std: vec![0.01; parameters.len()],
            parameters,
            simulation: Simulation::default(),
            initial_state: vec![0.0; model.states().len()],
        }));
    }
    fitted
        .iter()
        .map(|f| serde_json::to_value(f.to_file()).unwrap())
        .collect()
}

/// Every path to a node of `value` (the root excluded).
fn node_paths(value: &serde_json::Value, prefix: &mut Vec<String>, out: &mut Vec<Vec<String>>) {
    let children: Vec<(String, &serde_json::Value)> = match value {
        serde_json::Value::Object(m) => m.iter().map(|(k, v)| (k.clone(), v)).collect(),
        serde_json::Value::Array(a) => a
            .iter()
            .enumerate()
            .map(|(i, v)| (i.to_string(), v))
            .collect(),
        _ => Vec::new(),
    };
    for (key, child) in children {
        prefix.push(key);
        out.push(prefix.clone());
        node_paths(child, prefix, out);
        prefix.pop();
    }
}

fn node_mut<'a>(value: &'a mut serde_json::Value, path: &[String]) -> &'a mut serde_json::Value {
    path.iter().fold(value, |v, key| match v {
        serde_json::Value::Array(a) => &mut a[key.parse::<usize>().unwrap()],
        other => &mut other[key.as_str()],
    })
}

/// Replacement values: NaN-like strings, negative and huge sizes, wrong kinds and types.
fn replacement() -> impl Strategy<Value = serde_json::Value> {
    use serde_json::json;
    prop_oneof![
        Just(json!("NaN")),
        Just(json!("nan")),
        Just(json!("inf")),
        Just(json!("-Infinity")),
        Just(json!(0)),
        Just(json!(-1)),
        Just(json!(-1.5)),
        Just(json!(1e308)),
        Just(json!(-1e308)),
        Just(json!(1e-320)),
        Just(json!(u64::MAX)),
        Just(json!(1e11)),
        Just(json!(1_000_000)),
        Just(json!(100_000_000_000u64)),
        Just(json!(null)),
        Just(json!([])),
        Just(json!({})),
        Just(json!(true)),
        Just(json!("ch_cascade")),
        Just(json!("bouc_wen")),
        Just(json!("rigid_body")),
        Just(json!("actuator_free")),
        Just(json!("ch5")),
        Just(json!("newmark")),
        Just(json!("band_limited")),
        Just(json!("")),
        Just(json!("x".repeat(1000))),
        Just(json!({"value": -1.0, "std": 0.0})),
        Just(json!([{"value": 1e300}])),
    ]
}

/// Textual replacements of number tokens that JSON does not allow or that overflow.
fn number_text() -> impl Strategy<Value = &'static str> {
    prop_oneof![
        Just("NaN"),
        Just("Infinity"),
        Just("-Infinity"),
        Just("1e999"),
        Just("-1e999"),
        Just("-0"),
        Just("1e-400"),
        Just("18446744073709551616"),
        Just("0x10"),
        Just("")
    ]
}

/// Checks that a loaded model simulates to finite outputs or refuses with an error.
fn check_model(path: &Path) -> Result<(), TestCaseError> {
    let Ok(model) = FittedModel::load(path) else {
        return Ok(());
    };
    let x: Vec<f64> = (0..64).map(|k| (k as f64 * 0.1).sin()).collect();
    match model.simulate(&[&x], 0.01, Some(0.0)) {
        Ok(outputs) => {
            for y in outputs {
                prop_assert_eq!(y.len(), x.len());
                prop_assert!(
                    y.iter().all(|v| v.is_finite()),
                    "non-finite output from {:?}",
                    std::fs::read_to_string(path).unwrap()
                );
            }
        }
        Err(e) => prop_assert!(!e.to_string().contains('\n')),
    }
    Ok(())
}

proptest! {
    #![proptest_config(config(0x5eed_0de1))]

    #[test]
    fn model_files_with_mutated_values_load_valid_or_refuse(
        which in 0usize..4,
        edits in prop::collection::vec((any::<usize>(), replacement()), 1..3),
    ) {
        let mut file = valid_models().swap_remove(which);
        for (pick, value) in edits {
            let mut paths = Vec::new();
            node_paths(&file, &mut Vec::new(), &mut paths);
            if paths.is_empty() {
                break;
            }
            *node_mut(&mut file, &paths[pick % paths.len()]) = value;
        }
        let (_dir, path) = scratch("model.json");
        std::fs::write(&path, file.to_string()).unwrap();
        check_model(&path)?;
    }

    #[test]
    fn model_files_with_mutated_text_load_valid_or_refuse(
        which in 0usize..4,
        pick in any::<usize>(),
        token in number_text(),
        bytes in prop::collection::vec((any::<usize>(), any::<u8>()), 0..3),
    ) {
        let text = valid_models().swap_remove(which).to_string();
        // Replace one number token of the text.
        let starts: Vec<usize> = text
            .char_indices()
            .filter(|&(i, c)| (c.is_ascii_digit() || c == '-')
                && !text[..i].ends_with(|p: char| p.is_ascii_digit() || p == '.' || p == 'e' || p == '-'))
            .map(|(i, _)| i)
            .collect();
        let start = starts[pick % starts.len()];
        let end = text[start..]
            .find(|c: char| !(c.is_ascii_digit() || "+-.eE".contains(c)))
            .map_or(text.len(), |n| start + n);
        let mut mutated = format!("{}{token}{}", &text[..start], &text[end..]).into_bytes();
        for (at, b) in bytes {
            let n = mutated.len();
            mutated[at % n] = b;
        }
        let (_dir, path) = scratch("model.json");
        std::fs::write(&path, &mutated).unwrap();
        check_model(&path)?;
    }
}
