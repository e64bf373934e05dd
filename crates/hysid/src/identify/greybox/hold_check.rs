//! Says when the default zero-order hold misleads: a grey-box fit that holds a band-limited
//! input constant between samples.
//!
//! The simulator needs the input between samples. Held constant (zero-order hold, the
//! default), a smooth input becomes a staircase that lags it by half a sample on average
//! and carries spectral images above the band; on a band-limited record the fitted model
//! then absorbs that error or leaves it in the residuals (the Silverbox multisine with a
//! four-parameter Duffing equation file: 13 mV RMSE held, 1.2 mV band-limited). After a fit
//! with [`InputInterpolation::ZeroOrderHold`](crate::model::greybox::InputInterpolation),
//! [`hold_check`] computes two statistics and the fit carries a warning when both hold:
//!
//! 1. **The input is band-limited well below Nyquist**: for every experiment and input
//!    channel, the fraction of the input's energy (mean removed, Hann window, one-sided DFT,
//!    [`high_band_fraction`]) above [`HIGH_BAND_FROM`] = ½ of the Nyquist frequency is at
//!    most [`HIGH_BAND_MAX`] = 10⁻³. A record that really is held between samples is a
//!    staircase whose jumps spread energy over the whole band: a random staircase held for
//!    k samples has about 0.5 (k = 1), 0.03 (k = 10) and 0.003 (k = 100) of its energy up
//!    there, all above the threshold, while a multisine or a low-pass-filtered record has
//!    none but leakage (10⁻⁸ and less after the window). An input for which the hold is
//!    right is not flagged whatever the residuals.
//! 2. **The residuals correlate with the input**: the largest |r_εu(τ)|, τ = −25 … 25, of
//!    the residual analysis ([`residual_analysis`], every experiment, output and input) is
//!    more than [`CROSS_FACTOR`] = 2 times the half-width 2.576/√N of its 99 % band. Twice
//!    the band, rather than the band itself, because among 51 lags of independent residuals
//!    one value falls outside the 99 % band four times in ten; beyond twice the band (a
//!    5.2σ value) almost never. A fit whose residuals do not correlate with the input has
//!    nothing left to gain from a better interpolation of it.
//!
//! Both are needed: a band-limited input fitted well (the model happens to tolerate the
//! half-sample lag) is not flagged, and neither is a held input with a poor model.

use crate::data::IdData;
use crate::identify::validate::residual_analysis;
use crate::numerics::signal::high_band_fraction;
use serde::Serialize;

/// The input energy above this fraction of the Nyquist frequency counts as high-band.
pub const HIGH_BAND_FROM: f64 = 0.5;
/// At most this fraction of the input's energy high in the band: band-limited.
pub const HIGH_BAND_MAX: f64 = 1e-3;
/// The residuals correlate with the input when the peak |r_εu| exceeds this many 99 % bands.
pub const CROSS_FACTOR: f64 = 2.0;
/// Lags of the residual–input cross-correlation: τ = −CROSS_LAGS … CROSS_LAGS.
pub const CROSS_LAGS: usize = 25;

/// The statistics of [`hold_check`] and its verdict.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct HoldCheck {
    /// The largest fraction of input energy above [`HIGH_BAND_FROM`] of Nyquist, over the
    /// experiments and input channels.
    pub high_band_fraction: f64,
    /// The largest |r_εu(τ)| divided by the 99 % band, over experiments, outputs, inputs and
    /// lags.
    pub cross_correlation_ratio: f64,
    /// Both criteria hold: the input should have been interpolated band-limited.
    pub fires: bool,
}

impl HoldCheck {
    /// The warning of a check that fires (one line).
    pub fn warning(&self) -> Option<String> {
        self.fires.then(|| {
            format!(
                "the input is band-limited (a fraction {:.1e} of its energy above half the Nyquist \
                 frequency) and the residuals correlate with it ({:.1} times the 99 % band), but it \
                 was held constant between samples (zero-order hold, the default): the fit may be \
                 much worse than it should be; fit again with --interpolation band-limited",
                self.high_band_fraction, self.cross_correlation_ratio
            )
        })
    }
}

/// The check of a fit with zero-order hold on `data`, whose simulated outputs are
/// `simulated[experiment][output][t]` (see the module docs).
pub fn hold_check(data: &IdData, simulated: &[Vec<Vec<f64>>]) -> HoldCheck {
    let mut fraction: f64 = 0.0;
    let mut ratio: f64 = 0.0;
    for (e, outputs) in simulated.iter().enumerate().take(data.n_experiments()) {
        let experiment = data.experiment(e);
        for c in 0..data.input_channels().len() {
            fraction = fraction.max(high_band_fraction(experiment.input(c), HIGH_BAND_FROM));
        }
        for (o, yhat) in outputs.iter().enumerate() {
            let analysis = residual_analysis(data, e, o, yhat, CROSS_LAGS);
            let peak = analysis
                .cross_correlation
                .iter()
                .flatten()
                .fold(
                    0.0_f64,
                    |m, r| if r.is_finite() { m.max(r.abs()) } else { m },
                );
            if analysis.band > 0.0 {
                ratio = ratio.max(peak / analysis.band);
            }
        }
    }
    HoldCheck {
        high_band_fraction: fraction,
        cross_correlation_ratio: ratio,
        fires: fraction <= HIGH_BAND_MAX && ratio > CROSS_FACTOR,
    }
}
