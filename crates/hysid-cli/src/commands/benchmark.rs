//! `hysid benchmark bouc-wen`: the hysteretic benchmark of Noël & Schoukens (2016).
//!
//! Fits the Bouc–Wen oscillator on a training record and scores test records by e_RMS in
//! simulation mode (docs/benchmarks.md §1); `generate` makes test signals by the official recipe.

use super::greybox::{configure, plots};
use super::present::{print_fit, print_residuals, report};
use crate::cli::{BoucWenArgs, BoucWenGenerate, BoucWenGenerateArgs, SignalArg};
use crate::output::{ensure_dir, preflight, write_model, write_report};
use crate::plot::{plot, Figure, Series};
use crate::progress::FitProgress;
use anyhow::{bail, Context, Result};
use hysid::data::{write_csv, CsvSpec, IdData};
use hysid::identify::greybox::{GreyBoxEstimation, GreyBoxFit, InitialStates};
use hysid::model::greybox::models::BoucWen;
use hysid::model::greybox::simulate::band_limited_upsample;
use hysid::model::greybox::{InputInterpolation, Integrator, Simulation, StateSpaceModel};
use hysid::model::saved::FittedModel;
use hysid::numerics::metrics;
use hysid::numerics::signal::{decimate_fir, gaussian_noise, multisine, sine_sweep};
use hysid::report::ValidationEntry;
use serde_json::json;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Sampling frequency of the benchmark records.
const FS: f64 = 750.0;
/// Published e_RMS on the official multisine test set (docs/benchmarks.md §1.4).
const PUBLISHED: [(&str, f64); 3] = [
    ("dynoNet (Forgione & Piga 2021)", 4.52e-5),
    ("decoupled polynomial nonlinear state space", 1.87e-5),
    ("local-model network", 16.3e-5),
];

/// Runs the benchmark (or the generator).
pub fn bouc_wen(args: &BoucWenArgs) -> Result<()> {
    if let Some(BoucWenGenerate::Generate(g)) = &args.generate {
        return generate(g);
    }
    preflight(
        &[args.json.as_deref(), args.model_out.as_deref()],
        &[args.plots.as_deref()],
    )?;
    let Some(train) = &args.train else {
        bail!(
            "give the training record with --train FILE (columns t_s, u_N, y_m), or use `generate`"
        );
    };
    let data = record(train)?;
    let (fit, simulation) = fit_training(args, &data)?;
    print_fit(
        &format!(
            "Bouc–Wen benchmark: fitted to {} ({} samples)",
            train.display(),
            data.n_samples()
        ),
        &fit,
    );
    let residuals = print_residuals(&fit, &data);
    println!(
        "  training e_RMS {:.4e} m (the record's noise is 7.4e-6 m)",
        fit.fit.mse[0][0].sqrt()
    );
    let fitted = fit.fitted_model(&BoucWen, simulation);
    let tests = args
        .test
        .iter()
        .map(|path| score(&fitted, path, args.steady_state))
        .collect::<Result<Vec<_>>>()?;
    print_tests(&tests);
    if let Some(dir) = &args.plots {
        plots(dir, &fit, &data, &residuals)?;
        test_plots(dir, &tests)?;
        println!("  plots: {}", dir.display());
    }
    if let Some(path) = &args.json {
        let extra = json!({
            "training_e_rms": fit.fit.mse[0][0].sqrt(),
            "steady_state": args.steady_state,
            "published_multisine_e_rms": PUBLISHED.iter().map(|(who, e)| json!({"method": who, "e_rms": e})).collect::<Vec<_>>(),
            "residual_analysis": residuals,
        });
        let sources = vec![train.display().to_string()];
        let mut report = report(
            "benchmark bouc-wen",
            &fit,
            &data,
            sources,
            fitted.to_file(),
            extra,
        )?;
        report.validation = tests
            .iter()
            .map(|t| {
                ValidationEntry::of(t.file.display().to_string(), &t.y, &t.yhat, Some(t.e_rms))
            })
            .collect::<hysid::Result<_>>()?;
        write_report(path, &report)?;
        println!("  report: {}", path.display());
    }
    if let Some(path) = &args.model_out {
        write_model(path, &fitted)?;
        println!("  model: {}", path.display());
    }
    Ok(())
}

/// The output-error fit of the training record from the nominal start times
/// `--start-factor` (and `--init`), with the benchmark's integrator settings.
fn fit_training(args: &BoucWenArgs, data: &IdData) -> Result<(GreyBoxFit, Simulation)> {
    let mut params = BoucWen.parameters();
    for i in params.free_indices() {
        params.get_mut(i).value *= args.start_factor;
    }
    let params = configure(params, &[], &[], &args.init, &[])?;
    let simulation = Simulation {
        integrator: Integrator::Rk4 {
            substeps: args.search.substeps.max(1),
        },
        interpolation: InputInterpolation::BandLimited,
    };
    let estimation = GreyBoxEstimation {
        simulation,
        starts: args.search.starts.max(1),
        seed: args.search.seed,
        ..GreyBoxEstimation::default()
    };
    crate::budget::check(
        "the Bouc–Wen fit",
        estimation.work_estimate(data.n_samples(), 1, 3, params.free_indices().len() + 3),
    )?;
    let fit = {
        let progress = FitProgress::new("fitting Bouc–Wen");
        let estimation = GreyBoxEstimation {
            observer: progress.observer(),
            ..estimation
        };
        let mut callback = progress.callback();
        estimation.estimate(
            Arc::new(BoucWen),
            data,
            &params,
            InitialStates::at_rest(3, 1),
            &mut callback,
        )?
    };
    Ok((fit, simulation))
}

/// e_RMS per test record, and the published figures for comparison.
fn print_tests(tests: &[TestScore]) {
    for t in tests {
        println!(
            "  test {}: e_RMS {:.4e} m, fit {:.2} % ({} samples)",
            t.file.display(),
            t.e_rms,
            t.fit_percent,
            t.y.len()
        );
    }
    if !tests.is_empty() {
        let published: Vec<String> = PUBLISHED
            .iter()
            .map(|(who, e)| format!("{who} {e:.2e}"))
            .collect();
        println!(
            "  published e_RMS on the official multisine test set: {}",
            published.join("; ")
        );
    }
}

/// A benchmark record: columns t_s, u_N, y_m.
fn record(path: &Path) -> Result<IdData> {
    let spec = CsvSpec {
        inputs: vec!["u_N".into()],
        outputs: vec!["y_m".into()],
        time: Some("t_s".into()),
        ts: None,
    };
    IdData::from_file(path, &spec)
        .with_context(|| "benchmark records need the columns t_s, u_N, y_m".to_string())
}

/// A scored test record.
struct TestScore {
    file: PathBuf,
    e_rms: f64,
    fit_percent: f64,
    y: Vec<f64>,
    yhat: Vec<f64>,
}

/// e_RMS of the fitted model on a test record, from rest or in the periodic steady state.
fn score(model: &FittedModel, path: &Path, steady_state: bool) -> Result<TestScore> {
    let data = record(path)?;
    let exp = data.experiment(0);
    let (u, y) = (exp.input(0), exp.output(0));
    let yhat = if steady_state {
        let twice: Vec<f64> = u.iter().chain(u).copied().collect();
        model.simulate(&[&twice], data.ts(), None)?.remove(0)[u.len()..].to_vec()
    } else {
        model.simulate(&[u], data.ts(), None)?.remove(0)
    };
    Ok(TestScore {
        file: path.to_path_buf(),
        e_rms: metrics::rmse(y, &yhat),
        fit_percent: metrics::fit_percent(y, &yhat),
        y: y.to_vec(),
        yhat,
    })
}

fn test_plots(dir: &Path, tests: &[TestScore]) -> Result<()> {
    ensure_dir(dir)?;
    for (i, t) in tests.iter().enumerate() {
        let title = format!("Test {}: e_RMS {:.3e} m", t.file.display(), t.e_rms);
        let error: Vec<f64> = t.y.iter().zip(&t.yhat).map(|(a, b)| a - b).collect();
        let fig = Figure::new(&title, "sample", "y [m]")
            .with(Series::indexed("measured", &t.y, crate::plot::Style::Line))
            .with(Series::indexed(
                "simulated",
                &t.yhat,
                crate::plot::Style::DashedLine,
            ))
            .with(Series::indexed("error", &error, crate::plot::Style::Line));
        plot(&dir.join(format!("test{}.svg", i + 1)), &fig)?;
    }
    Ok(())
}

/// Upsampling factor of the official simulator (750 Hz → 15 kHz).
const UP: usize = 20;

/// Simulates a test signal by the official recipe: the input at 15 kHz, Newmark (γ = ½,
/// β = ¼) at 15 kHz, low-pass filtering and decimation back to 750 Hz.
fn generate(args: &BoucWenGenerateArgs) -> Result<()> {
    preflight(&[Some(&args.csv)], &[])?;
    let samples = match args.signal {
        SignalArg::Multisine => args.periods.saturating_mul(8192),
        SignalArg::Sweep => args.samples,
    };
    // The simulation runs at UP times the rate, on the band-limited input.
    crate::budget::check(
        "the test-signal simulation",
        hysid::identify::budget::simulation(samples.saturating_mul(UP), 1, 1, 3, 0, true),
    )?;
    let (u, u_fine) = match args.signal {
        SignalArg::Multisine => {
            anyhow::ensure!(args.periods >= 1, "--periods must be at least 1");
            let u = multisine(8192, args.periods, FS, 5.0, 150.0, 50.0, args.seed)?;
            // The multisine is band-limited and periodic: its 15 kHz samples are exact.
            let fine = band_limited_upsample(&u, UP);
            (u, fine)
        }
        SignalArg::Sweep => {
            anyhow::ensure!(args.samples >= 2, "--samples must be at least 2");
            let fine = sine_sweep(args.samples * UP, FS * UP as f64, 40.0, 18.0, 1.0 / 6.0);
            (fine.iter().step_by(UP).copied().collect(), fine)
        }
    };
    let input = IdData::input_only(1.0 / (FS * UP as f64), "u", u_fine)?;
    let model = FittedModel::GreyBox {
        kind: "bouc_wen".into(),
        parameters: BoucWen.parameters(),
        std: vec![0.0; 7],
        simulation: Simulation {
            integrator: Integrator::Newmark { substeps: 1 },
            interpolation: InputInterpolation::Linear,
        },
        initial_state: vec![0.0; 3],
    };
    let y_fine = model
        .simulate(&[input.experiment(0).input(0)], input.ts(), None)?
        .remove(0);
    let mut y = decimate_fir(&y_fine, UP);
    y.truncate(u.len());
    if args.noise > 0.0 {
        let noise = gaussian_noise(y.len(), args.noise, args.seed.wrapping_add(7))?;
        y.iter_mut().zip(&noise).for_each(|(a, b)| *a += b);
    }
    let t: Vec<f64> = (0..u.len()).map(|k| k as f64 / FS).collect();
    write_csv(&args.csv, &["t_s", "u_N", "y_m"], &[&t, &u, &y])?;
    println!(
        "Bouc–Wen {} test signal, {} samples at 750 Hz (Newmark at 15 kHz, decimated) -> {}",
        match args.signal {
            SignalArg::Multisine => "multisine",
            SignalArg::Sweep => "sine-sweep",
        },
        u.len(),
        args.csv.display()
    );
    Ok(())
}
