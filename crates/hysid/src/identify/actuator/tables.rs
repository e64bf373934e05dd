//! The paper's tables regenerated from an identification (Gunnar et al. 2006, Tables I–III),
//! as Markdown and as a JSON report.
//!
//! * Table I: the parameters of m0 (steps 1 and 2) and of the four step-3 models, in the
//!   paper's units (J·10⁻⁴, Fv·10⁻³, Fc·10⁻¹, k1·10¹, k2·10², α·10¹, A·10¹), each with its
//!   standard deviation; parameters held fixed are starred.
//! * Table II: the model fit (%) of every model on data sets 6, 7 and 8, simulated from rest.
//! * Table III: the change of fit of m67 when one parameter at a time is moved by ±20 %.

use super::{ActuatorIdentification, PARAMETERS};
use crate::identify::validate::SensitivityRow;
use serde::Serialize;
use std::collections::BTreeMap;
use std::fmt::Write;

/// The models in the paper's order.
pub const MODELS: [&str; 5] = ["m0", "m67f", "m68f", "m67", "m68"];

/// The paper's column scale of each parameter (Table I prints value/scale).
const SCALES: [(f64, &str); 7] = [
    (1e-4, "J [10⁻⁴ N·m·s²]"),
    (1e-3, "Fv [10⁻³ N·m·s]"),
    (1e-1, "Fc [10⁻¹ N·m]"),
    (1e1, "k1 [10¹ N·m/rad]"),
    (1e2, "k2 [10² N·m/rad³]"),
    (1e1, "α [10¹ 1/rad]"),
    (1e1, "A [10¹ N·m/rad]"),
];

/// One parameter of one model in the JSON report.
#[derive(Clone, Debug, Serialize)]
pub struct ParameterValue {
    /// Estimate.
    pub value: f64,
    /// Standard deviation (0 for a fixed parameter).
    pub std: f64,
    /// Held at its m0 value during the estimation.
    pub fixed: bool,
}

/// One model in the JSON report.
#[derive(Clone, Debug, Serialize)]
pub struct ModelReport {
    /// The parameters by name (J, Fv, Fc, k1, k2, alpha, A).
    pub parameters: BTreeMap<String, ParameterValue>,
    /// fit % on data sets 6, 7 and 8.
    pub fit_percent: [f64; 3],
    /// The data sets the model was estimated on (empty for m0).
    pub estimated_on: Vec<usize>,
    /// Iterations of the output-error search (0 for m0).
    pub iterations: usize,
    /// Why the search stopped (empty for m0).
    pub termination: String,
    /// Wall-clock time of the estimation \[s\].
    pub elapsed_s: f64,
}

/// Step 1 in the JSON report.
#[derive(Clone, Debug, Serialize)]
pub struct RigidBodyReport {
    /// Jt, Fv, Fc by name.
    pub parameters: BTreeMap<String, ParameterValue>,
    /// Relative standard deviations [%].
    pub relative_std_percent: BTreeMap<String, f64>,
    /// Relative error of the regression [%].
    pub relative_error_percent: f64,
    /// J = Jt − r²m.
    pub j: f64,
}

/// Step 2 in the JSON report.
#[derive(Clone, Debug, Serialize)]
pub struct LoopReport {
    /// k1, k2, alpha, A by name (α's standard deviation is not given: its profile is not
    /// quadratic).
    pub parameters: BTreeMap<String, ParameterValue>,
    /// The loop amplitudes Q of data sets 2–5 \[rad\].
    pub amplitudes: Vec<f64>,
    /// Root-mean-square residual torque [N·m].
    pub rms_residual: f64,
}

/// The machine-readable report of the three steps.
#[derive(Clone, Debug, Serialize)]
pub struct ActuatorReport {
    /// Step 1.
    pub step1: RigidBodyReport,
    /// Step 2.
    pub step2: LoopReport,
    /// m0 and the step-3 models by name (Tables I and II).
    pub models: BTreeMap<String, ModelReport>,
    /// ±20 % sensitivity of m67 (Table III): change of fit % on data sets 6, 7, 8.
    pub sensitivity: Vec<SensitivityRow>,
    /// The true parameters, when the data came from the virtual rig.
    pub truth: Option<BTreeMap<String, f64>>,
}

impl ActuatorIdentification {
    /// The JSON report; `truth` are the rig's true parameters when known.
    pub fn report(&self, truth: Option<&[f64]>) -> ActuatorReport {
        ActuatorReport {
            step1: self.step1_report(),
            step2: self.step2_report(),
            models: MODELS
                .iter()
                .map(|m| (m.to_string(), self.model_report(m)))
                .collect(),
            sensitivity: self.sensitivity.clone(),
            truth: truth.map(|t| named(t.iter().copied())),
        }
    }

    fn step1_report(&self) -> RigidBodyReport {
        let s = &self.step1;
        RigidBodyReport {
            parameters: s
                .names
                .iter()
                .zip(s.values.iter().zip(&s.std))
                .map(|(n, (v, e))| (n.clone(), value(*v, *e, false)))
                .collect(),
            relative_std_percent: s
                .names
                .iter()
                .cloned()
                .zip(s.relative_std_percent.iter().copied())
                .collect(),
            relative_error_percent: s.relative_error_percent,
            j: self.j,
        }
    }

    fn step2_report(&self) -> LoopReport {
        let s = &self.step2;
        LoopReport {
            parameters: ["k1", "k2", "alpha", "A"]
                .iter()
                .enumerate()
                .map(|(i, n)| (n.to_string(), value(s.values[i], s.std[i], false)))
                .collect(),
            amplitudes: s.loops.iter().map(|l| l.q).collect(),
            rms_residual: s.rms,
        }
    }

    /// The values, standard deviations and fixed flags of `model` (m0 or a step-3 name).
    pub fn parameters_of(&self, model: &str) -> Vec<ParameterValue> {
        match self.step3.get(model) {
            Some(fit) => {
                let (params, std) = (&fit.fit.parameters, fit.fit.std());
                (0..PARAMETERS.len())
                    .map(|i| value(params.get(i).value, std[i], params.get(i).fixed))
                    .collect()
            }
            None => {
                let std = [
                    self.step1.std[0],
                    self.step1.std[1],
                    self.step1.std[2],
                    self.step2.std[0],
                    self.step2.std[1],
                    self.step2.std[2],
                    self.step2.std[3],
                ];
                self.m0
                    .iter()
                    .zip(std)
                    .map(|(v, s)| value(*v, s, false))
                    .collect()
            }
        }
    }

    fn model_report(&self, model: &str) -> ModelReport {
        let fits = &self.fit_table[model];
        let fit = self.step3.get(model);
        ModelReport {
            parameters: PARAMETERS
                .iter()
                .map(|n| n.to_string())
                .zip(self.parameters_of(model))
                .collect(),
            fit_percent: [fits[0], fits[1], fits[2]],
            estimated_on: match model {
                "m67" | "m67f" => vec![6, 7],
                "m68" | "m68f" => vec![6, 8],
                _ => Vec::new(),
            },
            iterations: fit.map_or(0, |f| f.fit.report.iterations),
            termination: fit.map_or(String::new(), |f| f.fit.report.termination.to_string()),
            elapsed_s: fit.map_or(0.0, |f| f.elapsed_s),
        }
    }

    /// Table I (parameters ± standard deviation, the paper's units; fixed ones starred),
    /// with a first row of true values when given.
    pub fn table_i(&self, truth: Option<&[f64]>) -> String {
        let mut out = String::from("| model |");
        for (_, header) in SCALES {
            out += &format!(" {header} |");
        }
        out += "\n| --- |";
        out += &" --- |".repeat(SCALES.len());
        out.push('\n');
        if let Some(t) = truth {
            out += "| truth (rig) |";
            for (v, (scale, _)) in t.iter().zip(SCALES) {
                let _ = write!(out, " {:.4} |", v / scale);
            }
            out.push('\n');
        }
        for model in MODELS {
            let label = if model == "m0" {
                "m0 (steps 1+2)"
            } else {
                model
            };
            let _ = write!(out, "| {label} |");
            for (p, (scale, _)) in self.parameters_of(model).iter().zip(SCALES) {
                let _ = write!(out, " {} |", cell(p, scale));
            }
            out.push('\n');
        }
        out
    }

    /// Table II: fit % on data sets 6, 7, 8.
    pub fn table_ii(&self) -> String {
        let mut out = String::from(
            "| model | data set 6 | data set 7 | data set 8 |\n| --- | --- | --- | --- |\n",
        );
        for model in MODELS {
            let _ = write!(out, "| {model} |");
            for f in &self.fit_table[model] {
                if f.is_finite() {
                    let _ = write!(out, " {f:.2} |");
                } else {
                    out += " diverges |";
                }
            }
            out.push('\n');
        }
        out
    }

    /// Table III: change of the fit of m67 on data sets 6, 7, 8 [percentage points] when one
    /// parameter at a time is multiplied by 1.2 (+) or 0.8 (−).
    pub fn table_iii(&self) -> String {
        let mut out = String::from("| parameter | 6: +20 % | 6: −20 % | 7: +20 % | 7: −20 % | 8: +20 % | 8: −20 % |\n| --- | --- | --- | --- | --- | --- | --- |\n");
        for row in &self.sensitivity {
            let _ = write!(out, "| {} |", row.name);
            for (up, down) in row.up.iter().zip(&row.down) {
                let _ = write!(out, " {} | {} |", change(*up), change(*down));
            }
            out.push('\n');
        }
        out
    }

    /// Step 1 and step 2 as Markdown lines (values ± standard deviations).
    pub fn steps_1_and_2(&self) -> String {
        let s1 = &self.step1;
        let mut out = String::from("Step 1 (data set 1, rigid-body least squares): ");
        let parts: Vec<String> = s1
            .names
            .iter()
            .zip(s1.values.iter().zip(&s1.std))
            .map(|(n, (v, e))| format!("{n} = {v:.4e} (± {e:.2e})"))
            .collect();
        out += &parts.join(", ");
        let _ = writeln!(
            out,
            "; relative error {:.2} %; J = Jt − r²m = {:.4e}.",
            s1.relative_error_percent, self.j
        );
        let s2 = &self.step2;
        let q: Vec<String> = s2.loops.iter().map(|l| format!("{:.4}", l.q)).collect();
        let _ = writeln!(
            out,
            "\nStep 2 (data sets 2–5, loop amplitudes {} rad): k1 = {:.4e} (± {:.2e}), k2 = {:.4e} (± {:.2e}), α = {:.4e}, A = {:.4e} (± {:.2e}); RMS residual {:.3e} N·m.",
            q.join(", "),
            s2.values[0],
            s2.std[0],
            s2.values[1],
            s2.std[1],
            s2.values[2],
            s2.values[3],
            s2.std[3],
            s2.rms
        );
        out
    }

    /// All of it as one Markdown document.
    pub fn markdown(&self, truth: Option<&[f64]>) -> String {
        format!(
            "# Linear actuator: the three-step identification (Gunnar et al. 2006)\n\n{}\n## Table I: parameter estimates (± one standard deviation; * held fixed)\n\n{}\n## Table II: model fit [%]\n\n{}\n## Table III: change of the fit of m67 with ±20 % parameter changes [percentage points]\n\n{}",
            self.steps_1_and_2(),
            self.table_i(truth),
            self.table_ii(),
            self.table_iii()
        )
    }
}

fn value(value: f64, std: f64, fixed: bool) -> ParameterValue {
    ParameterValue {
        value,
        std: if fixed { 0.0 } else { std },
        fixed,
    }
}

fn named(values: impl Iterator<Item = f64>) -> BTreeMap<String, f64> {
    PARAMETERS
        .iter()
        .map(|n| n.to_string())
        .zip(values)
        .collect()
}

/// "4.991 ± 1.2e-3" in units of `scale`; "5.396*" when fixed.
fn cell(p: &ParameterValue, scale: f64) -> String {
    if p.fixed {
        format!("{:.3}*", p.value / scale)
    } else if p.std.is_finite() {
        format!("{:.3} ± {:.1e}", p.value / scale, p.std / scale)
    } else {
        format!("{:.3}", p.value / scale)
    }
}

fn change(v: f64) -> String {
    if v.is_finite() {
        format!("{v:+.2}")
    } else {
        "diverges".into()
    }
}
