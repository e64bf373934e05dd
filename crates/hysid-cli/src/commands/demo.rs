//! `hysid demo voros`: the project's cascade examples end to end.

use super::cascade::{print_summary, rows, uncertainty};
use crate::cli::{UncertaintyArg, VorosArgs};
use crate::output::Outputs;
use crate::progress::FitProgress;
use crate::report::print_table;
use anyhow::Result;
use hysid::experiments::voros::{CascadeExample, EXAMPLE_SNR};
use hysid::identify::cascade::CascadeIdentification;
use hysid::report::cascade_report;
use hysid::report::plot::cascade_figures;
use serde_json::json;

/// Generates Example 1 or 2, identifies it and reports against the truth.
pub fn voros(args: &VorosArgs) -> Result<()> {
    let ex = CascadeExample::number(args.example)?;
    // The plots go into their own subdirectory, so other demos' plots beside it stay.
    let dir = args.plots.join(format!("voros-example{}", args.example));
    let out = Outputs::new(&[], args.json.as_deref(), None, Some(&dir))?;
    let generated = ex.generate(args.seed, !args.noise_free)?;
    let data = generated.id_data()?;
    let truth = &ex.truth;
    let (form, lin) = (truth.hysteresis.form(), &truth.linear);
    // Without noise every standard deviation is zero to round-off: no bootstrap needed.
    let choice = if args.noise_free {
        UncertaintyArg::Asymptotic
    } else {
        args.uncertainty
    };
    let mut id = CascadeIdentification::new(form, lin.na(), lin.nb(), lin.delay())
        .initial(ex.initial.clone());
    id.uncertainty = uncertainty(choice, args.replicates);
    id.bootstrap_seed = args.seed;

    say!(
        "Vörös (2015) cascade, project Example {} (docs/models/coleman-hodgdon-cascade.md §13; the paper's own numbers were lost):",
        args.example
    );
    say!(
        "  {} hysteresis, linear block na = {}, nb = {}, delay k = {}; {} samples, seed {}, {}",
        form.short_name(),
        lin.na(),
        lin.nb(),
        lin.delay(),
        generated.x.len(),
        args.seed,
        if args.noise_free {
            "no output noise".to_string()
        } else {
            format!(
                "output noise SNR {EXAMPLE_SNR} (std {:.4e})",
                generated.noise_std
            )
        }
    );
    crate::budget::check(
        "the cascade identification",
        id.work_estimate(data.n_samples()),
    )?;
    let fit = {
        let progress = FitProgress::new("identifying");
        id.observer = progress.observer();
        let mut callback = progress.callback();
        id.estimate(&data, &mut callback)?
    };
    say!();
    let truth_params = truth.params();
    print_table(&rows(&fit, Some(&truth_params), Some(&ex.initial.params())));
    let extra = json!({
        "example": args.example,
        "seed": args.seed,
        "noise_free": args.noise_free,
        "noise_std": generated.noise_std,
        "true_parameters": truth_params,
        "initial_hysteresis": ex.initial.params(),
    });
    let source = vec![format!("built-in: project Example {}", args.example)];
    let report = cascade_report("demo voros", &fit, &data, source, extra)?;
    print_summary(&fit, &report);
    out.figures(|| cascade_figures(&fit, &generated.x, &generated.y, Some(truth)))?;
    out.finish(Some(&report), None)
}
