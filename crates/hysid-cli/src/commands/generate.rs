//! `hysid generate voros`: the examples' data as CSV.

use crate::cli::GenerateVorosArgs;
use crate::output::Outputs;
use anyhow::Result;
use hysid::data::write_csv;
use hysid::experiments::voros::CascadeExample;

/// Writes columns t, x, y of Example 1 or 2 (optionally extended to `--samples`).
pub fn voros(args: &GenerateVorosArgs) -> Result<()> {
    let mut ex = CascadeExample::number(args.example)?;
    let mut out = Outputs::new(&[], None, None, None)?;
    let csv = out.file_at(&args.csv)?;
    if let Some(n) = args.samples {
        anyhow::ensure!(n >= 2, "--samples must be at least 2, got {n}");
        crate::budget::check(
            "the generated record",
            hysid::identify::budget::simulation(n, 1, 1, 2, 0, false),
        )?;
        ex = ex.extended(n);
    }
    let data = ex.generate(args.seed, !args.noise_free)?;
    let t: Vec<f64> = (0..data.x.len()).map(|k| k as f64).collect();
    write_csv(&csv.tmp, &["t", "x", "y"], &[&t, &data.x, &data.y])?;
    out.finish(None, None)?;
    say!(
        "Example {} data: {} samples, seed {}, {} -> {}",
        args.example,
        data.x.len(),
        args.seed,
        if args.noise_free {
            "noise-free"
        } else {
            "SNR 50"
        },
        args.csv.display()
    );
    Ok(())
}
