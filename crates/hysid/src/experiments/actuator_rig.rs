//! A virtual test rig that reproduces the eight experiments of Gunnar et al. (2006, §VI-A)
//! on the two-mass actuator model, at 1 kHz (PROJECT: the paper does not state its rate).
//!
//! | set | saddle | excitation (paper) | here |
//! | --- | --- | --- | --- |
//! | 1 | free | PI speed control to 210 sin(2π·1·t) rad/s, 10 s | same |
//! | 2–5 | fixed | PI angle control to Q sin(0.5t), max flexibility torque 0.9–1.6 N·m, one steady-state period | Q for 0.9, 1.13, 1.37, 1.6 N·m; one period of warm-up, then 12.6 s (a full 12.57 s period; the paper's 12.3 s is a little short of it) |
//! | 6 | fixed | torque 1.4 sin(2t) N·m | 2 periods (6.3 s) from rest |
//! | 7, 8 | fixed | multisine torque 1–30 Hz, 5 s, two amplitude/phase sets (8 smaller) | RMS 0.5 and 0.4 N·m, seeds 7 and 8 |
//!
//! The plant is integrated by RK4 with 10 steps per sample (stick–slip aware, see
//! [`crate::model::greybox::stick_slip`]), the torque held between samples. The controllers act on
//! the true signals.
//!
//! **Measurement noise** (PROJECT levels): the logged angle and torque carry white Gaussian
//! noise with the standard deviation of a rounding to 16-bit numbers — one count of a
//! 16-bit-per-revolution encoder, 2π/2¹⁶/√12 = 2.77·10⁻⁵ rad, and one count of a 16-bit torque
//! log over ±5 N·m, 10/2¹⁶/√12 = 4.40·10⁻⁵ N·m. Larger torque noise makes the output-error
//! step biased (errors in the input variable, amplified by the stick–slip of the friction):
//! the README reports what it costs.
//!
//! **Backlash** (optional, unmodelled by the identification, as on the real actuator): the
//! spring sees the deflection d of a play of width b on the torsion x1 (d follows x1 only
//! when the gap |x1 − d| = b/2 is closed), and the hysteresis is driven by ḋ. The rig then
//! splits each step: RK4 for the mechanics with (d, x4) held, then the play and the exact
//! Dhaouadi update x4 ← (A/α)sgn Δd + (x4 − (A/α)sgn Δd)·e^{−α|Δd|}.
//!
//! Without backlash and noise, the saddle-fixed sets are exactly what the identification
//! model [`ActuatorFixed`] simulates with the same integrator.

use crate::data::actuator_records::{data_set_path, Record, COLUMNS};
use crate::data::write_csv;
use crate::model::greybox::models::{coulomb_direction, ActuatorFixed, ActuatorFree};
use crate::model::greybox::simulate::rk4_step;
use crate::model::greybox::stick_slip::StickSlip;
use crate::model::greybox::StateSpaceModel;
use crate::numerics::integrate::Stage;
use crate::numerics::signal::{gaussian_noise, multisine};
use crate::{Error, Result};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::f64::consts::{PI, TAU};
use std::path::{Path, PathBuf};

/// One count of a 16-bit-per-revolution motor encoder \[rad\].
pub const ANGLE_QUANTUM: f64 = TAU / 65_536.0;

/// One count of a 16-bit torque log over ±5 N·m [N·m].
pub const TORQUE_QUANTUM: f64 = 10.0 / 65_536.0;

/// √12: a uniform rounding error of one count q has standard deviation q/√12.
const SQRT_12: f64 = 3.464_101_615_137_754_6;

/// The largest magnitude of a true parameter of the rig (SI units): the actuator's
/// parameters are of order 1e-4 to 1e2, and beyond 1e12 the simulation or the tables
/// (which scale them by up to 1e4) leave the finite range.
pub const MAX_TRUTH: f64 = 1e12;

/// Settings of the virtual rig.
#[derive(Clone, Debug)]
pub struct Rig {
    /// True (J, Fv, Fc, k1, k2, α, A); default Table I's m67.
    pub truth: Vec<f64>,
    /// Gear ratio r [m/rad].
    pub r: f64,
    /// Saddle mass m \[kg\].
    pub m: f64,
    /// Sampling frequency \[Hz\].
    pub fs: f64,
    /// RK4 steps per sample.
    pub substeps: usize,
    /// Standard deviation of the logged angle noise \[rad\].
    pub angle_noise: f64,
    /// Standard deviation of the logged torque noise [N·m].
    pub torque_noise: f64,
    /// Play width b of the backlash in the flexibility \[rad\]; 0 for none.
    pub backlash: f64,
    /// RMS torque of the multisines of data sets 7 and 8 [N·m] (8 the smaller, as in the
    /// paper).
    pub multisine_rms: [f64; 2],
    /// Seed of the noise.
    pub seed: u64,
}

impl Default for Rig {
    fn default() -> Self {
        Self {
            truth: ActuatorFixed.parameters().values(),
            r: 1.867e-3,
            m: 1.2,
            fs: 1000.0,
            substeps: 10,
            angle_noise: ANGLE_QUANTUM / SQRT_12,
            torque_noise: TORQUE_QUANTUM / SQRT_12,
            backlash: 0.0,
            multisine_rms: [0.5, 0.4],
            seed: 1,
        }
    }
}

/// One logged experiment.
#[derive(Clone, Debug)]
pub struct RigRecord {
    /// Data set number, 1–8.
    pub set: usize,
    /// True when the saddle moved (set 1).
    pub saddle_free: bool,
    /// Sample time \[s\].
    pub ts: f64,
    /// Logged motor torque [N·m].
    pub torque: Vec<f64>,
    /// Logged motor angle \[rad\].
    pub angle: Vec<f64>,
}

impl RigRecord {
    /// Writes the record as `datasetK.csv` in `dir` (columns t_s, tau_Nm, theta_rad; written
    /// through a temporary file, never half-written); returns the path.
    pub fn write(&self, dir: &Path) -> Result<PathBuf> {
        let path = data_set_path(dir, self.set);
        let t: Vec<f64> = (0..self.torque.len()).map(|k| k as f64 * self.ts).collect();
        write_csv(&path, &COLUMNS, &[&t, &self.torque, &self.angle])?;
        Ok(path)
    }
}

/// How a data set is excited.
enum Excitation {
    Speed { amplitude: f64, frequency: f64 },
    Angle { amplitude: f64, omega: f64 },
    Torque(Vec<f64>),
}

impl Rig {
    /// The four loop amplitudes Q of sets 2–5: the amplitudes whose maximum flexibility
    /// torque k1Q + k2Q³ + (A/α)tanh(αQ) is 0.9, 1.133, 1.367 and 1.6 N·m.
    pub fn loop_amplitudes(&self) -> Vec<f64> {
        let t = &self.truth;
        let peak = |q: f64| t[3] * q + t[4] * q.powi(3) + t[6] / t[5] * (t[5] * q).tanh();
        (0..4)
            .map(|i| {
                let target = 0.9 + 0.7 * i as f64 / 3.0;
                let (mut lo, mut hi) = (0.0, 1.0);
                for _ in 0..100 {
                    let mid = 0.5 * (lo + hi);
                    if peak(mid) < target {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                0.5 * (lo + hi)
            })
            .collect()
    }

    /// All eight data sets, in parallel.
    pub fn records(&self) -> Result<Vec<RigRecord>> {
        (1..=8)
            .into_par_iter()
            .map(|set| self.record(set))
            .collect()
    }

    /// All eight data sets as the identification reads them (`[&k]` is set k).
    pub fn data_sets(&self) -> Result<BTreeMap<usize, Record>> {
        Ok(self
            .records()?
            .into_iter()
            .map(|r| {
                let record = Record {
                    ts: r.ts,
                    torque: r.torque,
                    angle: r.angle,
                };
                (r.set, record)
            })
            .collect())
    }

    /// Data set `set` (1–8).
    pub fn record(&self, set: usize) -> Result<RigRecord> {
        self.validate()?;
        let fs = self.fs;
        let (excitation, warmup, length) = match set {
            1 => (
                Excitation::Speed {
                    amplitude: 210.0,
                    frequency: 1.0,
                },
                0.0,
                10.0,
            ),
            2..=5 => {
                let omega = 0.5;
                let period = TAU / omega;
                (
                    Excitation::Angle {
                        amplitude: self.loop_amplitudes()[set - 2],
                        omega,
                    },
                    period,
                    12.6,
                )
            }
            6 => {
                let n = (2.0 * PI * fs).round() as usize;
                (
                    Excitation::Torque((0..n).map(|k| 1.4 * (2.0 * k as f64 / fs).sin()).collect()),
                    0.0,
                    n as f64 / fs,
                )
            }
            7 | 8 => {
                let rms = self.multisine_rms[set - 7];
                let n = (5.0 * fs).round() as usize;
                (
                    Excitation::Torque(multisine(n, 1, fs, 1.0, 30.0, rms, set as u64)?),
                    0.0,
                    5.0,
                )
            }
            other => {
                return Err(Error::invalid_option(
                    "data_set",
                    other,
                    format!("the rig has data sets 1 to 8, not {other}"),
                ))
            }
        };
        let (torque, angle) = self.run(
            &excitation,
            set == 1,
            (warmup * fs).round() as usize,
            (length * fs).round() as usize,
        );
        if let Some(index) = torque.iter().chain(&angle).position(|v| !v.is_finite()) {
            return Err(Error::Diverged {
                index: index % torque.len().max(1),
                reason: format!(
                    "the rig's simulation of data set {set} left the finite range with these \
                     settings; check the true parameters, the backlash and the constants"
                ),
            });
        }
        let (torque, angle) = self.add_noise(set, torque, angle)?;
        Ok(RigRecord {
            set,
            saddle_free: set == 1,
            ts: 1.0 / fs,
            torque,
            angle,
        })
    }

    /// Refuses true parameters (J, Fv, Fc, k1, k2, α, A) the rig cannot simulate, or whose
    /// tables would not be finite: not 7 values, a value outside the model's bounds (positive
    /// inertia, non-negative friction and hysteresis rate), or a magnitude beyond
    /// [`MAX_TRUTH`]. Used for the rig's settings and for the truth file (`rig.json`) read
    /// back beside its data sets.
    pub fn check_truth(truth: &[f64]) -> Result<()> {
        if truth.len() != 7 {
            return Err(Error::invalid_option(
                "truth",
                truth.len(),
                format!(
                    "the rig needs 7 true parameters (J, Fv, Fc, k1, k2, alpha, A), got {}",
                    truth.len()
                ),
            ));
        }
        for (p, &value) in ActuatorFixed.parameters().iter().zip(truth) {
            if !value.is_finite() || value.abs() > MAX_TRUTH {
                return Err(Error::InvalidParameter {
                    name: p.name.clone(),
                    value,
                    reason: format!(
                        "the actuator's true {} must be finite and at most {MAX_TRUTH:e} in magnitude (SI units); a larger one makes the simulation or its tables non-finite",
                        p.name
                    ),
                });
            }
            // The physics: positive inertia, non-negative friction and hysteresis rate.
            if !(p.min..=p.max).contains(&value) {
                return Err(Error::InvalidParameter {
                    name: p.name.clone(),
                    value,
                    reason: format!(
                        "the actuator's true {} must lie in [{}, {}]",
                        p.name,
                        crate::error::number(&p.min),
                        crate::error::number(&p.max)
                    ),
                });
            }
        }
        Ok(())
    }

    fn validate(&self) -> Result<()> {
        Self::check_truth(&self.truth)?;
        if self.fs.is_nan()
            || self.fs <= 0.0
            || self.substeps == 0
            || self.backlash < 0.0
            || self.angle_noise < 0.0
            || self.torque_noise < 0.0
        {
            return Err(Error::invalid_option(
                "rig",
                format!(
                    "fs = {}, substeps = {}, backlash = {}, noise = {}/{}",
                    self.fs, self.substeps, self.backlash, self.angle_noise, self.torque_noise
                ),
                "the rig needs fs > 0, substeps >= 1 and non-negative backlash and noise".into(),
            ));
        }
        if !(self.r.is_finite() && self.r > 0.0 && self.m.is_finite() && self.m >= 0.0) {
            return Err(Error::invalid_option("r, m", format!("{}, {}", self.r, self.m), format!(
                "the rig needs a positive gear ratio and a non-negative saddle mass, got r = {} m/rad, m = {} kg",
                self.r, self.m
            )));
        }
        Ok(())
    }

    /// Simulates `warmup` + `length` samples; returns the last `length` of (torque, angle).
    fn run(
        &self,
        excitation: &Excitation,
        saddle_free: bool,
        warmup: usize,
        length: usize,
    ) -> (Vec<f64>, Vec<f64>) {
        let plant = Plant {
            saddle_free,
            backlash: self.backlash,
            r: self.r,
            m: self.m,
        };
        let h = 1.0 / (self.fs * self.substeps as f64);
        // State: θ, θ̇, z, ż, x4, d (the spring deflection).
        let mut x = [0.0; 6];
        let mut controller = Pid::default();
        let (mut torque, mut angle) = (Vec::with_capacity(length), Vec::with_capacity(length));
        for k in 0..warmup + length {
            let t = k as f64 / self.fs;
            let tau = match excitation {
                Excitation::Torque(u) => u[k - warmup],
                Excitation::Speed {
                    amplitude,
                    frequency,
                } => controller.speed(
                    amplitude * (TAU * frequency * t).sin() - x[1],
                    1.0 / self.fs,
                ),
                Excitation::Angle { amplitude, omega } => {
                    controller.angle(amplitude * (omega * t).sin() - x[0], x[1], 1.0 / self.fs)
                }
            };
            if k >= warmup {
                torque.push(tau);
                angle.push(x[0]);
            }
            for j in 0..self.substeps {
                plant.step(&self.truth, t + j as f64 * h, &mut x, tau, h);
            }
        }
        (torque, angle)
    }

    fn add_noise(
        &self,
        set: usize,
        mut torque: Vec<f64>,
        mut angle: Vec<f64>,
    ) -> Result<(Vec<f64>, Vec<f64>)> {
        let base = self.seed.wrapping_mul(1000).wrapping_add(10 * set as u64);
        if self.torque_noise > 0.0 {
            let e = gaussian_noise(torque.len(), self.torque_noise, base)?;
            torque.iter_mut().zip(&e).for_each(|(a, b)| *a += b);
        }
        if self.angle_noise > 0.0 {
            let e = gaussian_noise(angle.len(), self.angle_noise, base + 1)?;
            angle.iter_mut().zip(&e).for_each(|(a, b)| *a += b);
        }
        Ok((torque, angle))
    }
}

/// The rig's controllers: PI on speed (set 1), PID on angle (sets 2–5), torque saturated at
/// ±5 N·m.
#[derive(Default)]
struct Pid {
    integral: f64,
}

impl Pid {
    /// Speed loop: bandwidth about 30 Hz on the rigid inertia.
    fn speed(&mut self, error: f64, dt: f64) -> f64 {
        const KP: f64 = 0.1;
        const KI: f64 = 4.0;
        self.integral += error * dt;
        (KP * error + KI * self.integral).clamp(-5.0, 5.0)
    }

    /// Angle loop on the saddle-fixed flexibility, derivative on the measured speed.
    fn angle(&mut self, error: f64, speed: f64, dt: f64) -> f64 {
        const KP: f64 = 200.0;
        const KI: f64 = 4000.0;
        const KD: f64 = 0.4;
        self.integral += error * dt;
        (KP * error + KI * self.integral - KD * speed).clamp(-5.0, 5.0)
    }
}

/// The rig plant (see the module docs), states (θ, θ̇, z, ż, x4, d).
struct Plant {
    saddle_free: bool,
    backlash: f64,
    r: f64,
    m: f64,
}

impl Plant {
    fn step(&self, theta: &[f64], t: f64, x: &mut [f64; 6], tau: f64, h: f64) {
        if self.backlash == 0.0 {
            self.step_smooth(theta, t, x, tau, h);
        } else {
            self.step_with_play(theta, t, x, tau, h);
        }
    }

    /// Without backlash: RK4 on the identification model's equations (d = x1).
    fn step_smooth(&self, theta: &[f64], t: f64, x: &mut [f64; 6], tau: f64, h: f64) {
        if self.saddle_free {
            let mut full = theta.to_vec();
            full.extend([self.r, self.m]);
            // ActuatorFree on (x1, x2, x3, x4); θ and z follow from x1 = θ − z/r by the
            // linear invariance of RK4: integrate z alongside.
            let mut s = [x[0] - x[2] / self.r, x[1], x[3], x[4], x[2]];
            rk4_step(&FreeWithPosition, &full, t, &mut s, &[tau], h);
            x[1] = s[1];
            x[3] = s[2];
            x[4] = s[3];
            x[2] = s[4];
            x[0] = s[0] + x[2] / self.r;
        } else {
            let mut s = [x[0], x[1], x[4]];
            rk4_step(&ActuatorFixed, theta, t, &mut s, &[tau], h);
            x[0] = s[0];
            x[1] = s[1];
            x[4] = s[2];
        }
        x[5] = x[0] - x[2] / self.r;
    }

    /// With backlash: mechanics by RK4 with the spring torque held, then the play and the
    /// exact hysteresis update.
    fn step_with_play(&self, th: &[f64], _t: f64, x: &mut [f64; 6], tau: f64, h: f64) {
        let (d, x4) = (x[5], x[4]);
        let g = th[3] * d + th[4] * d.powi(3) + x4;
        let (j, fv, fc) = (th[0], th[1], th[2]);
        let (r, m, free) = (self.r, self.m, self.saddle_free);
        // (θ, θ̇, z, ż) with the spring torque g held over the step.
        let mut rate = |_: Stage, s: &[f64], held: Option<f64>, ds: &mut [f64]| {
            let applied = tau - g - fv * s[1];
            let direction = held.or_else(|| coulomb_direction(s[1], applied, fc));
            ds[0] = s[1];
            ds[1] = direction.map_or(0.0, |dir| (applied - fc * dir) / j);
            ds[2] = if free { s[3] } else { 0.0 };
            ds[3] = if free { g / (r * m) } else { 0.0 };
        };
        let mut s = [x[0], x[1], x[2], x[3]];
        StickSlip::new(4).step(&mut rate, &mut s, h, Some(1), None);
        x[..4].copy_from_slice(&s);
        let x1 = x[0] - x[2] / r;
        let half = 0.5 * self.backlash;
        // max/min, not clamp: a diverged state (NaN) must reach the finite check of the
        // records, not panic here.
        let new_d = d.max(x1 - half).min(x1 + half);
        let delta = new_d - d;
        if delta != 0.0 {
            let target = th[6] / th[5] * delta.signum();
            x[4] = target + (x4 - target) * (-th[5] * delta.abs()).exp();
        }
        x[5] = new_d;
    }
}

/// [`ActuatorFree`] with the saddle position z appended as a fifth state (ż = x3).
struct FreeWithPosition;

impl StateSpaceModel for FreeWithPosition {
    fn kind(&self) -> &'static str {
        "actuator_free_rig"
    }
    fn states(&self) -> Vec<crate::data::Channel> {
        let mut s = ActuatorFree.states();
        s.push(crate::data::Channel::new("z"));
        s
    }
    fn inputs(&self) -> Vec<crate::data::Channel> {
        ActuatorFree.inputs()
    }
    fn outputs(&self) -> Vec<crate::data::Channel> {
        ActuatorFree.outputs()
    }
    fn parameters(&self) -> crate::model::ParameterSet {
        ActuatorFree.parameters()
    }
    fn rhs(&self, t: f64, x: &[f64], u: &[f64], theta: &[f64], dx: &mut [f64]) {
        ActuatorFree.rhs(t, &x[..4], u, theta, &mut dx[..4]);
        dx[4] = x[2];
    }
    fn output(&self, x: &[f64], u: &[f64], theta: &[f64], y: &mut [f64]) {
        ActuatorFree.output(x, u, theta, y);
    }
    fn stick_slip_velocity(&self) -> Option<usize> {
        ActuatorFree.stick_slip_velocity()
    }
    fn rhs_sliding(&self, t: f64, x: &[f64], u: &[f64], th: &[f64], d: f64, dx: &mut [f64]) {
        ActuatorFree.rhs_sliding(t, &x[..4], u, th, d, &mut dx[..4]);
        dx[4] = x[2];
    }
}
