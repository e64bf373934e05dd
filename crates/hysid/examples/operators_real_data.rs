//! The differential hysteresis operators on the vendored real records:
//! * the four Mn-Zn ferrite B(H) loops (`data/ferrite`): each family fitted to each loop;
//! * the piezo actuator record (`data/piezo`): fitted on the first 60 %, simulated over the
//!   whole record from the fitted initial state and scored on the last 40 %.
//!
//! Run with `cargo run --release -p hysid --example operators_real_data`.

use hysid::identify::operators::{bouc_wen, dahl, duhem, jiles_atherton, OperatorFit};
use hysid::model::operators::HysteresisOperator;
use hysid::numerics::metrics::fit_percent;
use std::path::Path;

fn columns(file: &str) -> Result<Vec<Vec<f64>>, Box<dyn std::error::Error>> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data")
        .join(file);
    let mut reader = csv::Reader::from_path(path)?;
    let mut cols: Vec<Vec<f64>> = Vec::new();
    for row in reader.records() {
        let row = row?;
        cols.resize(row.len(), Vec::new());
        for (c, v) in row.iter().enumerate() {
            cols[c].push(v.trim().parse()?);
        }
    }
    Ok(cols)
}

fn line<M: HysteresisOperator>(what: &str, fit: &hysid::Result<OperatorFit<M>>) {
    match fit {
        Ok(f) => println!(
            "{what:<32} fit {:7.2} %  {:>4} it  {:6.2} s  {}  {:?}",
            f.fit_percent,
            f.iterations,
            f.elapsed_s,
            f.termination,
            f.parameters.values()
        ),
        Err(e) => println!("{what:<32} error: {e}"),
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let ferrite = columns("ferrite/mnzn_ferrite_bh_loops.csv")?;
    for l in 0..4 {
        let (h, b) = (&ferrite[2 * l], &ferrite[2 * l + 1]);
        let name = |f: &str| format!("ferrite loop {} {f}", l + 1);
        line(
            &name("jiles-atherton"),
            &jiles_atherton::fit(h, b, &Default::default()),
        );
        line(&name("bouc-wen"), &bouc_wen::fit(h, b, &Default::default()));
        line(&name("duhem"), &duhem::fit(h, b, &Default::default()));
        line(&name("dahl"), &dahl::fit(h, b, &Default::default()));
    }
    let piezo = columns("piezo/piezo_150V_1Hz.csv")?;
    let (v, x) = (&piezo[1], &piezo[2]);
    let split = v.len() * 6 / 10;
    let validate = |sim: hysid::Result<Vec<f64>>| match sim {
        Ok(s) => fit_percent(&x[split..], &s[split..]),
        Err(_) => f64::NAN,
    };
    let bw = bouc_wen::fit(&v[..split], &x[..split], &Default::default());
    line("piezo 60 % bouc-wen", &bw);
    if let Ok(f) = &bw {
        println!(
            "  validation (last 40 %): {:.2} %",
            validate(f.model.simulate(v))
        );
    }
    let bw_n = bouc_wen::fit(
        &v[..split],
        &x[..split],
        &bouc_wen::BoucWenOptions {
            estimate_n: true,
            ..Default::default()
        },
    );
    line("piezo 60 % bouc-wen (n free)", &bw_n);
    if let Ok(f) = &bw_n {
        println!(
            "  validation (last 40 %): {:.2} %",
            validate(f.model.simulate(v))
        );
    }
    let du = duhem::fit(&v[..split], &x[..split], &Default::default());
    line("piezo 60 % duhem", &du);
    if let Ok(f) = &du {
        println!(
            "  validation (last 40 %): {:.2} %",
            validate(f.model.simulate(v))
        );
    }
    Ok(())
}
