//! Vörös (2015): a Coleman–Hodgdon hysteresis followed by a linear system, identified from
//! its input and noisy output alone — the hysteresis output is never measured.
//!
//! The data are the project's Example 1 (docs/models/coleman-hodgdon-cascade.md §13, a
//! project setting: the paper's own
//! numbers were lost) at SNR 50. No initial values are given: the estimator searches a grid
//! over (α, d), solves the bilinear rest by over-parameterised least squares and a rank-one
//! factorisation, runs the paper's key-term-separation iteration from there and finishes by
//! output error, which removes the bias noise gives plain least squares.
//!
//! Run with `cargo run --release -p hysid --example cascade_from_a_rough_start`.

use hysid::experiments::voros::CascadeExample;
use hysid::identify::cascade::CascadeIdentification;
use hysid::model::HysteresisCascade;
use hysid::numerics::Control;

fn main() -> hysid::Result<()> {
    let example = CascadeExample::example1();
    let data = example.generate(1, true)?.id_data()?;
    let truth = &example.truth;
    let form = truth.hysteresis.form();
    let (na, nb, delay) = (truth.linear.na(), truth.linear.nb(), truth.linear.delay());

    let fit = CascadeIdentification::new(form, na, nb, delay)
        .estimate(&data, &mut |_| Control::Continue)?;

    let names = HysteresisCascade::parameter_names(form, na, nb);
    let (estimate, std) = (fit.model.params(), fit.std());
    println!(
        "{:<6} {:>10} {:>10} {:>9}",
        "name", "true", "estimate", "std"
    );
    for (i, name) in names.iter().enumerate() {
        println!(
            "{name:<6} {:>10.5} {:>10.5} {:>9.2e}",
            truth.params()[i],
            estimate[i],
            std[i]
        );
    }
    println!(
        "\nfit {:.2} %, stopped: {}, {:.2} s",
        fit.output_error.fit_percent[0][0], fit.output_error.report.termination, fit.elapsed_s
    );
    Ok(())
}
