//! The three-step identification of Gunnar et al. (2006, §V), end to end.
//!
//! 1. **Rigid body** (data set 1, saddle free): inverse-dynamics least squares of
//!    Jt θ̈ + Fv θ̇ + Fc sgn(θ̇) = τ on the filtered, differentiated motor angle, with standard
//!    deviations; J = Jt − r²m.
//! 2. **Steady-state loops** (data sets 2–5, saddle fixed, one period each): nonlinear least
//!    squares of τn = k1 x1 + k2 x1³ + Cu/d(x1) with the corrected loop formula
//!    ([`loops`]), τn = τ − Fv x2 − Fc·(branch direction), Fv and Fc from step 1
//!    (docs/models/actuator.md §2). For fixed α the model is linear in (k1, k2, A), so α
//!    is found by a profile search (log grid and golden section) and the rest by least
//!    squares: no start values are needed.
//! 3. **Output error** (data set 6 with 7, and with 8): the saddle-fixed model
//!    [`ActuatorFixed`] from m0 = (J, Fv, Fc from step 1; k1, k2, α, A from step 2), all seven
//!    parameters free (m67, m68) or J, Fv, Fc fixed (m67f, m68f); stopped after 30 iterations
//!    or when the expected improvement falls below 0.01 %, as in the paper.
//!
//! Preprocessing (paper §VI-B): 4th-order Butterworth at 100 Hz, zero phase (`filtfilt`), on
//! every signal; optional mean removal; velocities by `gradient`.

pub mod loops;
pub mod tables;

use self::loops::{ascending, branch_samples, descending, turning_points};
use crate::data::{Channel, Experiment, IdData};
use crate::identify::greybox::{GreyBox, GreyBoxEstimation, GreyBoxFit, InitialStates};
use crate::identify::rigid_body::{RigidBodyEstimate, RigidBodyLs};
use crate::identify::validate::{sensitivity_table, SensitivityRow};
use crate::identify::OutputErrorModel;
use crate::model::greybox::models::ActuatorFixed;
use crate::model::greybox::{InputInterpolation, Integrator, Simulation, StateSpaceModel};
use crate::model::record_filters::Prefilter;
use crate::model::saved::FittedModel;
use crate::model::ParameterSet;
use crate::numerics::metrics::fit_percent;
use crate::numerics::signal::gradient;
use crate::numerics::{least_squares, LmConfig, Observer};
use crate::{Error, Result};
use nalgebra::DMatrix;
use serde::Serialize;
use std::collections::BTreeMap;
use std::sync::Arc;

pub use crate::data::actuator_records::{data_set_path, read_data_sets, Record, COLUMNS};

/// Settings of the procedure.
#[derive(Clone, Debug)]
pub struct ThreeSteps {
    /// Gear ratio r [m/rad] (known).
    pub r: f64,
    /// Saddle mass m \[kg\] (known).
    pub m: f64,
    /// Cut-off of the zero-phase Butterworth pre-filter \[Hz\].
    pub cutoff_hz: f64,
    /// Remove the sample mean of every signal before filtering.
    pub remove_mean: bool,
    /// Pre-filter the records of step 3 and of the fit tables as the paper does (true), or
    /// fit the unfiltered records (false). For this nonlinear model filtering input and output
    /// is not filtering the error: the response to the filtered torque keeps content above
    /// the cut-off at every stick and break-away, which biases step 3 slightly.
    pub prefilter_step3: bool,
    /// Step 2 leaves out the samples whose torsion lies within this fraction of the loop's
    /// peak-to-peak torsion from a reversal: the motor sticks there, the friction torque is
    /// anywhere in ±Fc and τn is unknown.
    pub reversal_margin: f64,
    /// Stopping of step 3 (paper: 30 iterations, 0.01 %).
    pub lm: LmConfig,
    /// Simulation of step 3.
    pub simulation: Simulation,
    /// Sees the iterations of step 3's fits ("iteration k/N") and may stop each at the
    /// best point so far (a front end's time limit).
    pub observer: Observer,
}

impl Default for ThreeSteps {
    fn default() -> Self {
        Self {
            r: 1.867e-3,
            m: 1.2,
            cutoff_hz: 100.0,
            remove_mean: false,
            prefilter_step3: true,
            reversal_margin: 0.05,
            lm: LmConfig {
                max_iterations: 30,
                improvement_tolerance: 1e-4,
                // Gunnar et al.'s rule: the expected improvement alone.
                ..LmConfig::improvement_rule()
            },
            simulation: Simulation {
                integrator: Integrator::Rk4 { substeps: 10 },
                interpolation: InputInterpolation::ZeroOrderHold,
            },
            observer: Observer::none(),
        }
    }
}

/// Step 2's result.
#[derive(Clone, Debug, Serialize)]
pub struct LoopFit {
    /// k1, k2, α, A.
    pub values: [f64; 4],
    /// Standard deviations of k1, k2, A at the fitted α (conditional; α's profile is not
    /// quadratic).
    pub std: [f64; 4],
    /// Root-mean-square residual torque [N·m].
    pub rms: f64,
    /// Per loop: amplitude Q, torsion x1, torque τn, ascending flags.
    pub loops: Vec<Loop>,
}

impl LoopFit {
    /// The step-2 model's steady-state loop for the torsion amplitude `q`: x1 from −Q to Q
    /// and back in `2 (points + 1)` samples, and τn = k1 x1 + k2 x1³ + Cu(x1) on the way up,
    /// + Cd(x1) on the way down (Gunnar et al. 2006 eq. (10); [`loops`]).
    pub fn model_loop(&self, q: f64, points: usize) -> (Vec<f64>, Vec<f64>) {
        let [k1, k2, alpha, a] = self.values;
        let n = points.max(1);
        let up = (0..=n).map(|i| -q + 2.0 * q * i as f64 / n as f64);
        let down = (0..=n).map(|i| q - 2.0 * q * i as f64 / n as f64);
        let x: Vec<f64> = up.clone().chain(down.clone()).collect();
        let tau: Vec<f64> = up
            .map(|x| k1 * x + k2 * x.powi(3) + ascending(a, alpha, q, x))
            .chain(down.map(|x| k1 * x + k2 * x.powi(3) + descending(a, alpha, q, x)))
            .collect();
        (x, tau)
    }
}

/// One steady-state loop of step 2.
#[derive(Clone, Debug, Serialize)]
pub struct Loop {
    /// Data set number.
    pub set: usize,
    /// Amplitude Q of the torsion.
    pub q: f64,
    /// Torsion x1 on the samples step 2 uses (away from the reversals).
    pub x1: Vec<f64>,
    /// τn = τ − Fv ẋ1 − Fc·(direction of the motion) on the same samples.
    pub tau_n: Vec<f64>,
    /// True on the ascending branch.
    pub ascending: Vec<bool>,
}

/// The whole identification.
#[derive(Clone, Debug)]
pub struct ActuatorIdentification {
    /// Step 1 (Jt, Fv, Fc).
    pub step1: RigidBodyEstimate,
    /// J = Jt − r²m.
    pub j: f64,
    /// Step 2.
    pub step2: LoopFit,
    /// m0: (J, Fv, Fc, k1, k2, α, A).
    pub m0: Vec<f64>,
    /// Step 3 fits by name (m67, m68, m67f, m68f).
    pub step3: BTreeMap<String, GreyBoxFit>,
    /// fit % of every model (m0 and step 3) on data sets 6, 7, 8 (NaN where a model cannot
    /// be simulated on a set).
    pub fit_table: BTreeMap<String, Vec<f64>>,
    /// The simulated torsion of every model on data sets 6, 7, 8 (empty where it diverges).
    pub simulated: BTreeMap<String, Vec<Vec<f64>>>,
    /// ±20 % sensitivity of m67 on data sets 6, 7, 8.
    pub sensitivity: Vec<SensitivityRow>,
    /// The filtered estimation data of sets 6, 7, 8 (for plots).
    pub validation: IdData,
    /// What step 3 did to the records (saved with its models, so that they reproduce
    /// their fits on the raw records).
    pub prefilter: Option<Prefilter>,
}

impl ActuatorIdentification {
    /// The step-3 model `name` (m67, m68, m67f, m68f) simulated with `simulation`, with the
    /// pre-filter it was fitted with.
    pub fn fitted(&self, name: &str, simulation: Simulation) -> Option<FittedModel> {
        let fit = self.step3.get(name)?;
        Some(FittedModel::prefiltered(
            fit.fitted_model(&ActuatorFixed, simulation),
            self.prefilter,
        ))
    }
}

/// Names of the actuator parameters, in order.
pub const PARAMETERS: [&str; 7] = ["J", "Fv", "Fc", "k1", "k2", "alpha", "A"];

impl ThreeSteps {
    /// Runs the three steps on data sets 1–8 (`records[&k]` is set k).
    pub fn run(&self, records: &BTreeMap<usize, Record>) -> Result<ActuatorIdentification> {
        self.run_reporting(records, &mut |_| {})
    }

    /// [`run`](Self::run), telling `progress` what it starts (for long runs).
    pub fn run_reporting(
        &self,
        records: &BTreeMap<usize, Record>,
        progress: &mut dyn FnMut(&str),
    ) -> Result<ActuatorIdentification> {
        self.check()?;
        for set in 1..=8 {
            if !records.contains_key(&set) {
                return Err(Error::InvalidData(format!(
                    "data set {set} is missing; the procedure needs data sets 1 to 8"
                )));
            }
        }
        progress("step 1: rigid-body least squares on data set 1");
        let step1 = self.step1(&records[&1])?;
        let (jt, fv, fc) = (step1.values[0], step1.values[1], step1.values[2]);
        let j = jt - self.r * self.r * self.m;
        progress("step 2: steady-state loops of data sets 2-5");
        let step2 = self.step2(&[2, 3, 4, 5].map(|s| (s, &records[&s])), fv, fc)?;
        let m0 = vec![
            j,
            fv,
            fc,
            step2.values[0],
            step2.values[1],
            step2.values[2],
            step2.values[3],
        ];
        let validation = self.estimation_data(&[6, 7, 8].map(|s| &records[&s]))?;
        let step3 = self.step3(&validation, &m0, progress)?;
        progress("tables: fit on data sets 6-8 and the ±20 % sensitivity of m67");
        let (fit_table, simulated) = self.fit_table(&validation, &m0, &step3)?;
        let m67 = &step3["m67"];
        let structure = self.structure(&validation)?;
        let nominal = structure.parameter_set(&model_parameters(&m67.fit.parameters));
        let sensitivity = sensitivity_table(&structure, &validation, &nominal, 0.2)?;
        Ok(ActuatorIdentification {
            step1,
            j,
            step2,
            m0,
            step3,
            fit_table,
            simulated,
            sensitivity,
            validation,
            prefilter: self.step3_filter(),
        })
    }

    /// Refuses settings no actuator has: a non-positive gear ratio or cut-off, a negative
    /// saddle mass, a reversal margin that would leave no branch samples.
    fn check(&self) -> Result<()> {
        let bad = |name: &str, value: f64, reason: &str| {
            Err(Error::InvalidParameter {
                name: name.into(),
                value,
                reason: reason.into(),
            })
        };
        if !(self.r.is_finite() && self.r > 0.0) {
            return bad("r", self.r, "the gear ratio must be positive (m/rad)");
        }
        if !(self.m.is_finite() && self.m >= 0.0) {
            return bad("m", self.m, "the saddle mass must be zero or positive (kg)");
        }
        if !(self.cutoff_hz.is_finite() && self.cutoff_hz > 0.0) {
            return bad(
                "cutoff",
                self.cutoff_hz,
                "the pre-filter cut-off must be positive (Hz)",
            );
        }
        if !(0.0..0.25).contains(&self.reversal_margin) {
            return bad(
                "reversal_margin",
                self.reversal_margin,
                "must lie in [0, 0.25) of the loop's peak-to-peak torsion",
            );
        }
        Ok(())
    }

    /// The pre-filter of the paper (§VI-B): optional mean removal, then a 4th-order
    /// zero-phase Butterworth low-pass at `cutoff_hz`.
    pub fn record_filter(&self) -> Prefilter {
        Prefilter {
            remove_mean: self.remove_mean,
            cutoff_hz: Some(self.cutoff_hz),
            order: 4,
        }
    }

    /// What step 3 and the fit tables do to a record: the pre-filter, mean removal alone, or
    /// nothing (None).
    pub fn step3_filter(&self) -> Option<Prefilter> {
        match (self.prefilter_step3, self.remove_mean) {
            (true, _) => Some(self.record_filter()),
            (false, true) => Some(Prefilter {
                cutoff_hz: None,
                ..self.record_filter()
            }),
            (false, false) => None,
        }
    }

    /// A signal as step 3 fits it.
    fn step3_signal(&self, x: &[f64], ts: f64) -> Result<Vec<f64>> {
        match self.step3_filter() {
            Some(f) => f.apply(x, ts),
            None => Ok(x.to_vec()),
        }
    }

    /// The zero-phase Butterworth pre-filter (with optional mean removal).
    fn prefilter(&self, x: &[f64], ts: f64) -> Result<Vec<f64>> {
        self.record_filter().apply(x, ts)
    }

    /// Step 1 on data set 1.
    pub fn step1(&self, record: &Record) -> Result<RigidBodyEstimate> {
        let torque = self.prefilter(&record.torque, record.ts)?;
        let ls = RigidBodyLs {
            inertia_name: "Jt".into(),
            cutoff_hz: self.cutoff_hz,
            border: 50,
            ..RigidBodyLs::default()
        };
        ls.estimate(&record.angle, &torque, record.ts)
    }

    /// Step 2 on the loop data sets, with the friction `fv`, `fc` from step 1.
    pub fn step2(&self, sets: &[(usize, &Record)], fv: f64, fc: f64) -> Result<LoopFit> {
        let loops: Vec<Loop> = sets
            .iter()
            .map(|(set, r)| self.one_loop(*set, r, fv, fc))
            .collect::<Result<_>>()?;
        // Profile over α: log grid between 0.1/Qmax and 100/Qmin, then golden section.
        let q_min = loops.iter().map(|l| l.q).fold(f64::INFINITY, f64::min);
        let q_max = loops.iter().map(|l| l.q).fold(0.0, f64::max);
        let (lo, hi) = ((0.1 / q_max).ln(), (100.0 / q_min).ln());
        let cost = |ln_alpha: f64| {
            linear_part(&loops, ln_alpha.exp()).map_or(f64::INFINITY, |(_, _, c)| c)
        };
        let grid: Vec<f64> = (0..=60).map(|i| lo + (hi - lo) * i as f64 / 60.0).collect();
        let best = grid
            .iter()
            .copied()
            .min_by(|a, b| cost(*a).total_cmp(&cost(*b)))
            .expect("grid");
        let step = (hi - lo) / 60.0;
        let ln_alpha =
            crate::identify::hysteresis::golden_section(cost, best - step, best + step, 60);
        let alpha = ln_alpha.exp();
        let (theta, std, sse) = linear_part(&loops, alpha)
            .ok_or_else(|| Error::Singular("the loops do not determine k1, k2 and A".into()))?;
        let n: usize = loops.iter().map(|l| l.x1.len()).sum();
        Ok(LoopFit {
            values: [theta[0], theta[1], alpha, theta[2]],
            std: [std[0], std[1], f64::NAN, std[2]],
            rms: (sse / n as f64).sqrt(),
            loops,
        })
    }

    /// One steady-state period of a loop data set: τn = τ − Fv ẋ1 − Fc·(branch direction)
    /// on the samples away from the reversals ([`branch_samples`]).
    fn one_loop(&self, set: usize, record: &Record, fv: f64, fc: f64) -> Result<Loop> {
        let x1 = self.prefilter(&record.angle, record.ts)?;
        let tau = self.prefilter(&record.torque, record.ts)?;
        let x2 = gradient(&x1, record.ts);
        let (max, min) = x1
            .iter()
            .fold((f64::MIN, f64::MAX), |(a, b), v| (a.max(*v), b.min(*v)));
        // A reversal counts once the torsion has come back by a tenth of its range.
        let points = turning_points(&x1, 0.1 * (max - min));
        if points.len() < 2 {
            return Err(Error::InvalidData(format!(
                "data set {set} holds no full loop period (the motion reverses {} time(s), a period needs 2); record at least one period of the sinusoid",
                points.len()
            )));
        }
        let used = branch_samples(&x1, &points, self.reversal_margin * (max - min));
        Ok(Loop {
            set,
            q: 0.5 * (max - min),
            tau_n: used
                .iter()
                .map(|&(k, d)| tau[k] - fv * x2[k] - fc * d)
                .collect(),
            ascending: used.iter().map(|&(_, d)| d > 0.0).collect(),
            x1: used.iter().map(|&(k, _)| x1[k]).collect(),
        })
    }

    /// Sets 6, 7, 8 filtered, as three experiments of (τ → x1).
    fn estimation_data(&self, records: &[&Record; 3]) -> Result<IdData> {
        let ts = records[0].ts;
        if let Some(k) = records.iter().position(|r| (r.ts / ts - 1.0).abs() > 1e-6) {
            return Err(Error::InvalidData(format!(
                "data sets 6, 7 and 8 must share one sample time; set {} has {} s, set 6 {ts} s",
                k + 6,
                records[k].ts
            )));
        }
        let experiments = records
            .iter()
            .zip([6, 7, 8])
            .map(|(r, set)| {
                let torque = self.step3_signal(&r.torque, r.ts)?;
                let angle = self.step3_signal(&r.angle, r.ts)?;
                Experiment::new(format!("data set {set}"), vec![torque], vec![angle])
            })
            .collect::<Result<Vec<_>>>()?;
        IdData::new(
            ts,
            vec![Channel::new("tau").with_unit("N*m")],
            vec![Channel::new("x1").with_unit("rad")],
            experiments,
        )
    }

    fn structure(&self, data: &IdData) -> Result<GreyBox> {
        GreyBox::new(
            Arc::new(ActuatorFixed),
            data,
            self.simulation,
            InitialStates::at_rest(3, data.n_experiments()),
        )
    }

    /// Step 3: the four output-error fits.
    fn step3(
        &self,
        validation: &IdData,
        m0: &[f64],
        progress: &mut dyn FnMut(&str),
    ) -> Result<BTreeMap<String, GreyBoxFit>> {
        let variants = [
            ("m67", 1, false),
            ("m68", 2, false),
            ("m67f", 1, true),
            ("m68f", 2, true),
        ];
        let mut out = BTreeMap::new();
        for (name, second, fixed) in variants {
            progress(&format!(
                "step 3: {name}, output error on data sets 6 and {}{}",
                second + 6,
                if fixed { " (J, Fv, Fc fixed)" } else { "" }
            ));
            let data = validation.select(&[0, second])?;
            let mut params = ActuatorFixed.parameters();
            params.set_values(m0);
            for i in 0..3 {
                params.get_mut(i).fixed = fixed;
            }
            let estimation = GreyBoxEstimation {
                simulation: self.simulation,
                lm: self.lm.clone(),
                ..GreyBoxEstimation::default()
            };
            let fit = estimation.estimate(
                Arc::new(ActuatorFixed),
                &data,
                &params,
                InitialStates::at_rest(3, 2),
                &mut |r| {
                    self.observer
                        .report("iteration", r.iteration, self.lm.max_iterations)
                },
            )?;
            out.insert(name.to_string(), fit);
        }
        Ok(out)
    }

    /// fit % of m0 and the step-3 models on sets 6, 7, 8 (simulated from rest), NaN where a
    /// model cannot be simulated on a set (it diverges there); and the simulations.
    #[allow(clippy::type_complexity)]
    fn fit_table(
        &self,
        validation: &IdData,
        m0: &[f64],
        step3: &BTreeMap<String, GreyBoxFit>,
    ) -> Result<(BTreeMap<String, Vec<f64>>, BTreeMap<String, Vec<Vec<f64>>>)> {
        let structure = self.structure(validation)?;
        let mut models = vec![("m0".to_string(), m0.to_vec())];
        for (name, fit) in step3 {
            models.push((
                name.clone(),
                fit.fit.parameters.values()[..PARAMETERS.len()].to_vec(),
            ));
        }
        let (mut table, mut simulated) = (BTreeMap::new(), BTreeMap::new());
        for (name, values) in models {
            let mut params = ActuatorFixed.parameters();
            params.set_values(&values);
            let theta = structure.parameter_set(&params).values();
            let (mut fits, mut outputs) = (Vec::new(), Vec::new());
            for (e, exp) in validation.experiments().iter().enumerate() {
                let mut y = vec![vec![0.0; exp.len()]];
                match structure.simulate(&theta, validation, e, &mut y) {
                    Ok(()) => {
                        fits.push(fit_percent(exp.output(0), &y[0]));
                        outputs.push(y.swap_remove(0));
                    }
                    Err(Error::Diverged { .. }) => {
                        fits.push(f64::NAN);
                        outputs.push(Vec::new());
                    }
                    Err(other) => return Err(other),
                }
            }
            table.insert(name.clone(), fits);
            simulated.insert(name, outputs);
        }
        Ok((table, simulated))
    }
}

/// The actuator's seven parameters of `params` (the initial states dropped).
fn model_parameters(params: &ParameterSet) -> ParameterSet {
    ParameterSet::new(params.iter().take(PARAMETERS.len()).cloned().collect())
        .expect("unique names")
}

/// For fixed α: least squares of τn on [x1, x1³, C(x1)/A] over all loops; (θ, std, SSE).
fn linear_part(loops: &[Loop], alpha: f64) -> Option<(Vec<f64>, Vec<f64>, f64)> {
    let rows: usize = loops.iter().map(|l| l.x1.len()).sum();
    let mut phi = DMatrix::zeros(rows, 3);
    let mut y = Vec::with_capacity(rows);
    let mut r = 0;
    for l in loops {
        for ((x, t), up) in l.x1.iter().zip(&l.tau_n).zip(&l.ascending) {
            let branch = if *up {
                ascending(1.0, alpha, l.q, *x)
            } else {
                descending(1.0, alpha, l.q, *x)
            };
            phi[(r, 0)] = *x;
            phi[(r, 1)] = x.powi(3);
            phi[(r, 2)] = branch;
            y.push(*t);
            r += 1;
        }
    }
    let ls = least_squares(&phi, &y, &["k1", "k2", "A"]).ok()?;
    let std = ls.std();
    Some((ls.theta.iter().copied().collect(), std, ls.residual_ss))
}
