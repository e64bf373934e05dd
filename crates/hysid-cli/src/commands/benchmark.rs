//! `hysid benchmark bouc-wen`: the hysteretic benchmark of Noël & Schoukens (2016).
//!
//! Fits the Bouc–Wen oscillator on a training record and scores test records by e_RMS in
//! simulation mode (docs/benchmarks.md §1); `generate` makes test signals by the official recipe.

use super::greybox::configure;
use super::present::{print_fit, print_residuals};
use crate::cli::{BoucWenArgs, BoucWenGenerate, BoucWenGenerateArgs, SignalArg};
use crate::output::{write_figures, Outputs};
use crate::progress::FitProgress;
use anyhow::{bail, Context, Result};
use hysid::data::{write_csv, IdData};
use hysid::identify::bouc_wen_benchmark::{
    generate as generate_record, record_spec, BenchmarkTest, BoucWenBenchmark, TestSignal,
    PUBLISHED, UP,
};
use hysid::report::plot::{benchmark_test_figures, greybox_figures};
use hysid::report::{bouc_wen_benchmark_report, ValidationEntry};
use std::path::Path;

/// Runs the benchmark (or the generator).
pub fn bouc_wen(args: &BoucWenArgs) -> Result<()> {
    if let Some(BoucWenGenerate::Generate(g)) = &args.generate {
        return generate(g);
    }
    let Some(train) = &args.train else {
        bail!(
            "give the training record with --train FILE (columns t_s, u_N, y_m), or use `generate`"
        );
    };
    let mut inputs = vec![train.as_path()];
    inputs.extend(args.test.iter().map(|p| p.as_path()));
    let mut out = Outputs::new(
        &inputs,
        args.json.as_deref(),
        args.model_out.as_deref(),
        args.plots.as_deref(),
    )?;
    let data = record(train)?;
    out.fitted_on(&data);
    let tests = args
        .test
        .iter()
        .map(|path| Ok((path.display().to_string(), record(path)?)))
        .collect::<Result<Vec<_>>>()?;
    let params = BoucWenBenchmark::start_values(args.start_factor).context("--start-factor")?;
    let params = configure(params, &[], &[], &args.init, &[])?;
    let mut benchmark = BoucWenBenchmark {
        substeps: args.search.substeps,
        starts: args.search.starts,
        seed: args.search.seed,
        steady_state: args.steady_state,
        observer: Default::default(),
    };
    crate::budget::check(
        "the Bouc–Wen fit",
        benchmark.estimation().work_estimate(
            data.n_samples(),
            1,
            3,
            params.free_indices().len() + 3,
        ),
    )?;
    let result = {
        let progress = FitProgress::new("fitting Bouc–Wen");
        benchmark.observer = progress.observer();
        let mut callback = progress.callback();
        benchmark.run(&data, &params, &tests, &mut callback)?
    };
    let fit = &result.fit;
    print_fit(
        &format!(
            "Bouc–Wen benchmark: fitted to {} ({} samples)",
            train.display(),
            data.n_samples()
        ),
        fit,
    );
    let residuals = print_residuals(fit, &data);
    say!(
        "  training e_RMS {:.4e} m (the record's noise is 7.4e-6 m)",
        result.training_e_rms
    );
    print_tests(&result.tests);
    if let Some(dir) = &out.plots {
        write_figures(&dir.tmp, &greybox_figures(fit, &data, &residuals)?)?;
        write_figures(&dir.tmp, &benchmark_test_figures(&result.tests)?)?;
    }
    // The report (with its own residual analysis) only when it is written.
    let report = match out.json {
        Some(_) => Some(bouc_wen_benchmark_report(
            fit,
            &data,
            vec![train.display().to_string()],
            result.model.to_file(),
            result
                .tests
                .iter()
                .map(ValidationEntry::of_benchmark)
                .collect::<hysid::Result<_>>()?,
            args.steady_state,
        )?),
        None => None,
    };
    out.finish(report.as_ref(), Some(&result.model))
}

/// e_RMS per test record, and the published figures for comparison.
fn print_tests(tests: &[BenchmarkTest]) {
    for t in tests {
        say!(
            "  test {}: e_RMS {:.4e} m, fit {:.2} % ({} samples)",
            t.source,
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
        say!(
            "  published e_RMS on the official multisine test set: {}",
            published.join("; ")
        );
    }
}

/// A benchmark record: columns t_s, u_N, y_m.
fn record(path: &Path) -> Result<IdData> {
    IdData::from_file(path, &record_spec())
        .with_context(|| "benchmark records need the columns t_s, u_N, y_m".to_string())
}

/// Simulates a test signal by the official recipe: the input at 15 kHz, Newmark (γ = ½,
/// β = ¼) at 15 kHz, low-pass filtering and decimation back to 750 Hz.
fn generate(args: &BoucWenGenerateArgs) -> Result<()> {
    let mut out = Outputs::new(&[], None, None, None)?;
    let csv = out.file_at(&args.csv)?;
    let signal = match args.signal {
        SignalArg::Multisine => {
            anyhow::ensure!(args.periods >= 1, "--periods must be at least 1");
            TestSignal::Multisine {
                periods: args.periods,
            }
        }
        SignalArg::Sweep => {
            anyhow::ensure!(args.samples >= 2, "--samples must be at least 2");
            TestSignal::Sweep {
                samples: args.samples,
            }
        }
    };
    let samples = match &signal {
        TestSignal::Multisine { periods } => periods.saturating_mul(8192),
        TestSignal::Sweep { samples } => *samples,
    };
    // The simulation runs at UP times the rate, on the band-limited input.
    crate::budget::check(
        "the test-signal simulation",
        hysid::identify::budget::simulation(samples.saturating_mul(UP), 1, 1, 3, 0, true),
    )?;
    let record = generate_record(signal, args.noise, args.seed)?;
    write_csv(
        &csv.tmp,
        &["t_s", "u_N", "y_m"],
        &[&record.t, &record.u, &record.y],
    )?;
    out.finish(None, None)?;
    say!(
        "Bouc–Wen {} test signal, {} samples at 750 Hz (Newmark at 15 kHz, decimated) -> {}",
        match args.signal {
            SignalArg::Multisine => "multisine",
            SignalArg::Sweep => "sine-sweep",
        },
        record.u.len(),
        args.csv.display()
    );
    Ok(())
}
