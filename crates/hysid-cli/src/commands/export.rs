//! `hysid export`: a saved model as C, no_std Rust or an FMU, in a directory of its own.

use crate::cli::{ExportArgs, TargetArg};
use crate::exit::UsageError;
use anyhow::{Context, Result};
use hysid::export::output::ExportDir;
use hysid::export::{export, ExportOptions, Target};
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
    if args.test_range.is_some() && !args.test_vectors {
        return Err(UsageError(
            "--test-range applies to --test-vectors only; leave it out; run 'hysid export --help' for the options".into(),
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
    let dir = ExportDir::new(&args.out, &[args.model.as_path()])?;
    let file = ModelFile::load(&args.model)?;
    let options = ExportOptions {
        inverse: args.inverse,
        sample_time: args.ts,
        binary: !args.no_binary,
        initial_output: args.y0,
        limits: args.limits,
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
        eprintln!(
            "warning: {} records no input_range (a file of an earlier version) and no --limits was given: the compensator's command is not limited",
            args.model.display()
        );
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
    println!(
        "Exported the {} of {} ({}) as {}:",
        if args.inverse { "compensator" } else { "model" },
        args.model.display(),
        file.kind(),
        target.name()
    );
    for f in &files {
        println!("  {}", args.out.join(&f.path).display());
    }
    Ok(())
}
