//! The project's numerical examples for the hysteresis cascade
//! (docs/models/coleman-hodgdon-cascade.md §13).
//!
//! These are PROJECT settings: the seed copy of Vörös (2015) lost the numbers of its two
//! examples, so Example 1 and Example 2 here follow the paper's *description* (periodic
//! triangles in four segments of decreasing amplitude, a uniform input disturbance, Gaussian
//! output noise at SNR = 50 as a ratio of standard deviations) with values chosen by the
//! project. They are not the paper's values.
//!
//! | item | Example 1 | Example 2 |
//! | --- | --- | --- |
//! | hysteresis | ch4: α = 0.3, m1 = 1.0, c1 = 0.5, d = 3.0 | ch6: α = 0.4, m1 = 1.2, m2 = 0.15, c1 = 0.6, c2 = 0.1, d = 2.0 |
//! | linear block | a = [−0.6, 0.2], b = [1, 0.5], k = 1 | a = [−1.5, 0.7, −0.1], b = [1, 0.4, −0.2], k = 2 |
//! | samples | 4 × 1000 | 4 × 1250 |
//! | triangle period | 40 | 50 |
//! | peak amplitudes | 5, 4, 3.5, 2.5 | 4, 3, 2.5, 1.8 |
//! | input disturbance | uniform ±0.2 | uniform ±0.15 |
//! | initial values | d = 4.5, α = 0.2, m1 = 0.8, c1 = 0.4 | d = 3.6, α = 0.3, m1 = 1.0, m2 = 0.1, c1 = 0.5, c2 = 0.05 |

use crate::data::IdData;
use crate::model::{ColemanHodgdon, HysteresisCascade, LinearBlock};
use crate::numerics::signal::{add_noise_snr, triangle_schedule, uniform_noise, Segment};
use crate::{Error, Result};

/// The SNR of the examples' output noise, std(y)/std(noise) (SEED).
pub const EXAMPLE_SNR: f64 = 50.0;

/// One of the project's cascade examples.
#[derive(Clone, Debug)]
pub struct CascadeExample {
    /// 1 or 2.
    pub number: u8,
    /// The true cascade.
    pub truth: HysteresisCascade,
    /// The documented rough initial hysteresis parameters.
    pub initial: ColemanHodgdon,
    /// Triangle period in samples.
    pub period: usize,
    /// Amplitude schedule.
    pub segments: Vec<Segment>,
    /// Half-width of the uniform input disturbance.
    pub disturbance: f64,
}

/// Signals generated from an example.
#[derive(Clone, Debug)]
pub struct ExampleData {
    /// The cascade input x (triangles plus disturbance).
    pub x: Vec<f64>,
    /// The internal hysteresis output v.
    pub v: Vec<f64>,
    /// The noise-free output.
    pub y_clean: Vec<f64>,
    /// The output handed to the estimator (noisy unless noise-free was asked).
    pub y: Vec<f64>,
    /// Standard deviation of the added noise (0 when noise-free).
    pub noise_std: f64,
}

impl ExampleData {
    /// The estimation data: input `x`, output `y`, sample time 1.
    pub fn id_data(&self) -> Result<IdData> {
        IdData::siso(1.0, "x", self.x.clone(), "y", self.y.clone())
    }
}

impl CascadeExample {
    /// Example 1 or 2.
    pub fn number(n: u8) -> Result<Self> {
        match n {
            1 => Ok(Self::example1()),
            2 => Ok(Self::example2()),
            _ => Err(Error::invalid_option(
                "example",
                n,
                format!("there are examples 1 and 2, not {n}"),
            )),
        }
    }

    /// Example 1: ch4 hysteresis, second-order linear block, k = 1.
    pub fn example1() -> Self {
        let truth = HysteresisCascade::new(
            ColemanHodgdon::saturated(0.3, 1.0, 0.5, 3.0).expect("valid"),
            LinearBlock::new(vec![-0.6, 0.2], vec![1.0, 0.5], 1).expect("valid"),
        )
        .expect("valid");
        Self {
            number: 1,
            truth,
            initial: ColemanHodgdon::saturated(0.2, 0.8, 0.4, 4.5).expect("valid"),
            period: 40,
            segments: schedule(1000, &[5.0, 4.0, 3.5, 2.5]),
            disturbance: 0.2,
        }
    }

    /// Example 2: ch6 hysteresis, third-order linear block, k = 2.
    pub fn example2() -> Self {
        let truth = HysteresisCascade::new(
            ColemanHodgdon::general(0.4, 1.2, 0.15, 0.6, 0.1, 2.0).expect("valid"),
            LinearBlock::new(vec![-1.5, 0.7, -0.1], vec![1.0, 0.4, -0.2], 2).expect("valid"),
        )
        .expect("valid");
        Self {
            number: 2,
            truth,
            initial: ColemanHodgdon::general(0.3, 1.0, 0.1, 0.5, 0.05, 3.6).expect("valid"),
            period: 50,
            segments: schedule(1250, &[4.0, 3.0, 2.5, 1.8]),
            disturbance: 0.15,
        }
    }

    /// Repeats the amplitude schedule until the record holds `n` samples (for speed tests
    /// on long records with the example's input pattern).
    pub fn extended(mut self, n: usize) -> Self {
        let pattern = self.segments.clone();
        let mut segments = Vec::new();
        let mut total = 0;
        'outer: loop {
            for s in &pattern {
                let len = s.len.min(n - total);
                segments.push(Segment {
                    len,
                    amplitude: s.amplitude,
                });
                total += len;
                if total >= n {
                    break 'outer;
                }
            }
        }
        self.segments = segments;
        self
    }

    /// Generates the input and outputs. The input disturbance uses `seed`, the output noise a
    /// stream derived from it; `noisy = false` gives the noise-free variant.
    pub fn generate(&self, seed: u64, noisy: bool) -> Result<ExampleData> {
        let triangles = triangle_schedule(self.period, &self.segments)?;
        let disturbance = uniform_noise(triangles.len(), self.disturbance, seed)?;
        let x: Vec<f64> = triangles
            .iter()
            .zip(&disturbance)
            .map(|(a, b)| a + b)
            .collect();
        let out = self.truth.simulate(&x)?;
        let (y, noise_std) = if noisy {
            add_noise_snr(&out.y, EXAMPLE_SNR, noise_seed(seed))?
        } else {
            (out.y.clone(), 0.0)
        };
        Ok(ExampleData {
            x,
            v: out.v,
            y_clean: out.y,
            y,
            noise_std,
        })
    }
}

/// Four equal segments with the given peak amplitudes.
fn schedule(len: usize, amplitudes: &[f64]) -> Vec<Segment> {
    amplitudes
        .iter()
        .map(|&amplitude| Segment { len, amplitude })
        .collect()
}

/// An independent stream for the output noise (splitmix64 increment).
fn noise_seed(seed: u64) -> u64 {
    seed.wrapping_add(0x9E37_79B9_7F4A_7C15)
}
