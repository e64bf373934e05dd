//! `hysid export`: a saved model as C, no_std Rust or an FMU, in a directory of its own.

use crate::cli::{ExportArgs, PrecisionArg, TargetArg};
use crate::exit::UsageError;
use anyhow::{Context, Result};
use hysid::data::{CsvSpec, IdData};
use hysid::export::output::ExportDir;
use hysid::export::{export, ExportOptions, Precision, Target};
use hysid::model::saved::ModelFile;

/// Registers the output directory (refused when it is or holds the model file, or holds
/// anything), reads the model, generates the files and renames the directory into place.
pub fn run(args: &ExportArgs) -> Result<()> {
    if args.no_binary && args.target != TargetArg::Fmu {
        return Err(UsageError(
            "--no-binary applies to --target fmu only; leave it out; run 'hysid export --help' for the options".into(),
        )
        .into());
    }
    if args.test_vectors && args.target == TargetArg::Fmu {
        return Err(UsageError(
            "--test-vectors applies to --target c and rust only; leave it out; run 'hysid export --help' for the options".into(),
        )
        .into());
    }
    if args.test_range.is_some() && !args.test_vectors && args.precision != PrecisionArg::Single {
        return Err(UsageError(
            "--test-range applies to --test-vectors and --precision single only; leave it out; run 'hysid export --help' for the options".into(),
        )
        .into());
    }
    if args.test_range.is_some_and(|r| r.lo() >= r.hi()) {
        return Err(UsageError(
            "--test-range needs LO < HI; run 'hysid export --help' for the options".into(),
        )
        .into());
    }
    let target = match args.target {
        TargetArg::C => Target::C,
        TargetArg::Rust => Target::Rust,
        TargetArg::Fmu => Target::Fmu,
    };
    let precision = match args.precision {
        PrecisionArg::Double => Precision::Double,
        PrecisionArg::Single => Precision::Single,
    };
    check_precision(args, precision)?;
    let mut inputs = vec![args.model.as_path()];
    inputs.extend(args.data.as_deref());
    let dir = ExportDir::new(&args.out, &inputs)?;
    let file = ModelFile::load(&args.model)?;
    let bound_record = args
        .data
        .as_deref()
        .map(|path| bound_record(path, args))
        .transpose()?;
    let options = ExportOptions {
        inverse: args.inverse,
        sample_time: args.ts,
        binary: !args.no_binary,
        initial_output: args.y0,
        limits: args.limits,
        precision,
        bound_record,
        test_vectors: args.test_vectors,
        test_range: args.test_range,
    };
    if args.limits.is_some() && !args.inverse {
        return Err(UsageError(
            "--limits applies to --inverse only (a compensator's command); leave it out; run 'hysid export --help' for the options".into(),
        )
        .into());
    }
    if args.inverse && hysid::export::export_limits(&file, &options).is_none() {
        tell!(
            "warning: {} records no input_range (a file of an earlier version) and no --limits was given: the compensator's command is not limited",
            args.model.display()
        );
    }
    if args.inverse {
        // A file that does not rebuild is refused, with its reason, by the export below.
        if let Ok(model) = hysid::model::saved::FittedModel::from_file(&file) {
            super::warn_history_beyond_the_inverse(&model, &args.model);
        }
    }
    let files = export(&file, target, &args.name, &options).with_context(|| {
        format!(
            "exporting {} ({}) to {}",
            args.model.display(),
            file.kind(),
            target.name()
        )
    })?;
    dir.write(&files)?;
    say!(
        "Exported the {} of {} ({}) as {}:",
        if args.inverse { "compensator" } else { "model" },
        args.model.display(),
        file.kind(),
        target.name()
    );
    for f in &files {
        say!("  {}", args.out.join(&f.path).display());
    }
    Ok(())
}

/// The precision's options, checked before any file is read: single is for C and Rust,
/// `--data` for single only, and its columns are those the exported step reads.
fn check_precision(args: &ExportArgs, precision: Precision) -> Result<()> {
    let usage = |text: &str| -> Result<()> {
        Err(UsageError(format!("{text}; run 'hysid export --help' for the options")).into())
    };
    if precision.is_single() && args.target == TargetArg::Fmu {
        return usage(
            "--precision single applies to --target c or rust (an FMU computes in double: FMI 2.0's Real is a double)",
        );
    }
    if args.data.is_some() && !precision.is_single() {
        return usage("--data gives the record a single-precision bound is measured on; add --precision single, or leave --data out");
    }
    if args.data.is_none() && (!args.input.is_empty() || args.output.is_some()) {
        return usage(
            "--input and --output name columns of --data; give --data FILE, or leave them out",
        );
    }
    if args.data.is_some() {
        if args.inverse && args.output.is_none() {
            return usage("with --inverse, --data needs --output COLUMN (the references fed to the compensator)");
        }
        if !args.inverse && args.input.is_empty() {
            return usage("--data needs --input COLUMN (the model's inputs; repeat for several)");
        }
    }
    Ok(())
}

/// The rows of `--data` the exported step is fed to measure the single-precision bound:
/// the `--input` columns of a model, the `--output` column of a compensator.
fn bound_record(path: &std::path::Path, args: &ExportArgs) -> Result<Vec<Vec<f64>>> {
    let spec = CsvSpec {
        inputs: args.input.clone(),
        outputs: args.output.iter().cloned().collect(),
        time: None,
        ts: Some(1.0),
        ..CsvSpec::default()
    };
    let data = IdData::from_file(path, &spec)
        .with_context(|| format!("reading --data {}", path.display()))?;
    let columns: Vec<&[f64]> = if args.inverse {
        vec![data.output(0, 0)]
    } else {
        (0..args.input.len()).map(|j| data.input(0, j)).collect()
    };
    Ok((0..columns[0].len())
        .map(|k| columns.iter().map(|c| c[k]).collect())
        .collect())
}
