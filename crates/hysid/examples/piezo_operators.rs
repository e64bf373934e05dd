//! The linear-in-weights hysteresis operators on a real piezo-actuator record (Chandra et al.
//! 2023, 150 V, 1 Hz; `data/piezo`): each family is fitted on the first 60 % of the samples,
//! simulated over the whole record from its initial state, and scored (fit %) on the last
//! 40 %, next to the Coleman–Hodgdon hysteresis (ch4, ch6) fitted and scored the same way.
//!
//! Run with `cargo run --release -p hysid --example piezo_operators [path.csv]`.

use hysid::data::IdData;
use hysid::identify::hysteresis::HysteresisIdentification;
use hysid::identify::operators::{backlash, gpi, maxwell_slip, pi, preisach};
use hysid::model::operators::HysteresisOperator;
use hysid::model::ChForm;
use hysid::numerics::metrics::fit_percent;
use hysid::numerics::Control;

fn read(path: &str) -> Result<(Vec<f64>, Vec<f64>), Box<dyn std::error::Error>> {
    let text = std::fs::read_to_string(path)?;
    let (mut u, mut y) = (Vec::new(), Vec::new());
    for line in text.lines().skip(1) {
        let cells: Vec<f64> = line.split(',').map(str::parse).collect::<Result<_, _>>()?;
        u.push(cells[1]);
        y.push(cells[2]);
    }
    Ok((u, y))
}

fn report(name: &str, train: f64, sim: &[f64], y: &[f64], split: usize, seconds: f64) {
    let val = fit_percent(&y[split..], &sim[split..]);
    println!("{name:<14} {train:>9.2} {val:>11.2} {seconds:>9.4}");
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args().nth(1).unwrap_or_else(|| {
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../data/piezo/piezo_150V_1Hz.csv"
        )
        .into()
    });
    let (u, y) = read(&path)?;
    let split = u.len() * 6 / 10;
    let (ut, yt) = (&u[..split], &y[..split]);
    println!(
        "{} samples, train 0..{split}, validate {split}..{}",
        u.len(),
        u.len()
    );
    println!(
        "{:<14} {:>9} {:>11} {:>9}",
        "family", "train %", "validate %", "fit s"
    );

    let f = backlash::fit(ut, yt, &backlash::BacklashOptions::default())?;
    report(
        "backlash",
        f.fit_percent,
        &f.model.simulate(&u)?,
        &y,
        split,
        f.elapsed_s,
    );
    let f = pi::fit(ut, yt, &pi::PiOptions::default())?;
    report(
        "pi (10)",
        f.fit_percent,
        &f.model.simulate(&u)?,
        &y,
        split,
        f.elapsed_s,
    );
    let f = gpi::fit(ut, yt, &gpi::GpiOptions::default())?;
    report(
        "gpi (10, 4+4)",
        f.fit_percent,
        &f.model.simulate(&u)?,
        &y,
        split,
        f.elapsed_s,
    );
    let f = preisach::fit(ut, yt, &preisach::PreisachOptions::default())?;
    report(
        "preisach (20)",
        f.fit_percent,
        &f.model.simulate(&u)?,
        &y,
        split,
        f.elapsed_s,
    );
    let f = maxwell_slip::fit(ut, yt, &maxwell_slip::MaxwellSlipOptions::default())?;
    report(
        "maxwell-slip",
        f.fit_percent,
        &f.model.simulate(&u)?,
        &y,
        split,
        f.elapsed_s,
    );

    let ts = 1e-3;
    let train = IdData::siso(ts, "u", ut.to_vec(), "y", yt.to_vec())?;
    for (name, form) in [("ch4", ChForm::Saturated4), ("ch6", ChForm::General6)] {
        let fit =
            HysteresisIdentification::new(form).estimate(&train, &mut |_| Control::Continue)?;
        let sim = fit.model.simulate_unchecked(&u, y[0]);
        let train_fit = fit_percent(yt, &sim[..split]);
        report(name, train_fit, &sim, &y, split, fit.elapsed_s);
        println!(
            "               (the estimator's own training fit %: {:.2}; admissible: {})",
            fit.output_error.fit_percent[0][0],
            fit.model.admissibility().holds
        );
    }
    Ok(())
}
