//! Tests of `hysid::model::operators::registry`.

use hysid::model::operators::registry::*;
use hysid::model::operators::Orientation;
use hysid::model::operators::{PrandtlIshlinskii, Preisach};

#[test]
fn structure_round_trips_and_is_checked() {
    let pi = PrandtlIshlinskii::new(
        0.5,
        vec![0.3, 0.2],
        vec![0.1, 0.4],
        1.0,
        Orientation::CLOCKWISE,
    )
    .unwrap();
    let m = OperatorModel::Pi(pi);
    let s = m.structure().unwrap();
    assert_eq!(OperatorModel::from_structure("pi", &s).unwrap(), m);
    // A non-monotone threshold grid in a file is refused by the constructor.
    let mut bad = s.clone();
    bad["thresholds"] = serde_json::json!([0.4, 0.1]);
    assert!(OperatorModel::from_structure("pi", &bad).is_err());
    assert!(OperatorModel::from_structure("nope", &s).is_err());
}

#[test]
fn preisach_cache_is_rebuilt() {
    let w = vec![1.0, 0.5, 2.0];
    let p = Preisach::new(-1.0, 1.0, 2, w, 0.1, 0.0, Orientation::default()).unwrap();
    let m = OperatorModel::Preisach(p);
    let back = OperatorModel::from_structure("preisach", &m.structure().unwrap()).unwrap();
    let u = [0.0, 0.8, -0.3, 0.5, -1.0, 1.0];
    assert_eq!(
        back.as_operator().simulate(&u).unwrap(),
        m.as_operator().simulate(&u).unwrap()
    );
}

/// An input with nested reversals over about ±1 (the examples' range).
fn reversals() -> Vec<f64> {
    (0..400)
        .map(|k| {
            let t = k as f64 / 400.0;
            (1.0 - 0.6 * t) * (19.0 * t).sin() + 0.2 * (71.0 * t).sin()
        })
        .collect()
}

/// Every family of the list: its serde tag is its name, its structure and values round-trip
/// through the validating constructor, and its output scale scales the output.
#[test]
fn every_family_of_the_registry_is_consistent() {
    let examples = OperatorModel::examples().unwrap();
    let operators: Vec<Family> = Family::operators().collect();
    assert_eq!(
        examples
            .iter()
            .map(OperatorModel::family)
            .collect::<Vec<_>>(),
        operators
    );
    let u = reversals();
    let variants = OperatorModel::variants().unwrap();
    assert!(!variants.is_empty(), "the PI with an envelope");
    for m in examples.iter().chain(variants.iter().map(|(_, m)| m)) {
        let name = m.family().name();
        assert_eq!(m.as_operator().family(), name);
        assert_eq!(Family::parse(name).unwrap(), m.family());
        let json = serde_json::to_value(m).unwrap();
        assert_eq!(
            json["family"], name,
            "{name}: the serde tag is the family's name"
        );
        let back: OperatorModel = serde_json::from_value(json).unwrap();
        assert_eq!(&back, m, "{name}: serde round trip");
        let structure = m.structure().unwrap();
        assert_eq!(&OperatorModel::from_structure(name, &structure).unwrap(), m);
        let values = m.as_operator().parameters().values();
        assert_eq!(&m.with_values(&values).unwrap(), m, "{name}: with_values");
        assert!(
            m.with_values(&values[1..]).is_err(),
            "{name}: a short list is refused"
        );
        let y = m.as_operator().simulate(&u).unwrap();
        assert!(y.iter().all(|v| v.is_finite()), "{name}");
        if m.output_scale().is_some() {
            let scaled = m.scaled(2.0).unwrap();
            let ys = scaled.as_operator().simulate(&u).unwrap();
            for (a, b) in ys.iter().zip(&y) {
                assert!(
                    (a - 2.0 * b).abs() <= 1e-9 * (1.0 + b.abs()),
                    "{name}: {a} vs 2·{b}"
                );
            }
        }
        for i in m.held() {
            assert!(i < values.len(), "{name}: held index {i}");
        }
    }
}

/// The docs table is the registry's (`docs/zoo.md` holds `Family::markdown_table()`).
#[test]
fn docs_table_is_the_registry() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/zoo.md");
    let text = std::fs::read_to_string(path).unwrap();
    assert!(
        text.contains(&Family::markdown_table()),
        "docs/zoo.md must hold the registry's table; paste this:\n{}",
        Family::markdown_table()
    );
}

/// The Python package's family names (`hysid.FamilyName`, `hysid.FAMILIES`) are generated
/// from the registry into `python/hysid/_families.py`; `HYSID_WRITE_SCHEMA=1` rewrites it.
#[test]
fn registry_python_names() {
    let items: String = Family::ALL
        .iter()
        .map(|f| format!("    \"{}\",\n", f.name()))
        .collect();
    let expected = format!(
        "\"\"\"The hysteresis families of the library's registry, as Python names.\n\n\
         Generated from ``hysid::model::operators::Family`` — do not edit: the test\n\
         ``registry_python_names`` in ``crates/hysid-tests`` checks this file and rewrites it under\n\
         ``HYSID_WRITE_SCHEMA=1 cargo test --release -p hysid-tests --test library registry``.\n\
         \"\"\"\n\n\
         from typing import Literal, Tuple\n\n\
         #: A hysteresis family's name, as ``hysid identify operator --family`` takes it.\n\
         FamilyName = Literal[\n{items}]\n\n\
         #: Every family name, in the registry's order.\n\
         FAMILIES: Tuple[str, ...] = (\n{items})\n"
    );
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../hysid-py/python/hysid/_families.py"
    );
    if std::env::var_os("HYSID_WRITE_SCHEMA").is_some() {
        std::fs::write(path, &expected).unwrap();
    }
    let found = std::fs::read_to_string(path).unwrap();
    assert_eq!(
        found, expected,
        "_families.py is out of date: run HYSID_WRITE_SCHEMA=1 cargo test --release -p hysid-tests --test library registry"
    );
}
