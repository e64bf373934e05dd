//! The figure set of each identification: which data each figure shows, under which file
//! name. One function per result type; each returns the finished SVG documents.

use super::figure::{hline, Figure, Series, Style};
use super::svg::{convergence, render, render_panels, render_panels_sized};
use super::Svg;
use crate::data::IdData;
use crate::error::Result;
use crate::identify::actuator::{ActuatorIdentification, PARAMETERS};
use crate::identify::bouc_wen_benchmark::BenchmarkTest;
use crate::identify::cascade::CascadeFit;
use crate::identify::greybox::GreyBoxFit;
use crate::identify::hysteresis::HysteresisFit;
use crate::identify::validate::ResidualAnalysis;
use crate::model::HysteresisCascade;
use crate::numerics::metrics;

/// Points per plotted series of the actuator records: enough for the eye at 1 kHz, and SVG
/// files of a few hundred kilobytes.
const PLOT_POINTS: usize = 2500;

fn svg(name: &str, svg: String) -> Svg {
    Svg {
        name: name.to_string(),
        svg,
    }
}

/// The plots of a cascade fit on input `x` and output `y`: hysteresis loops (Vörös 2015
/// Figs. 4 and 8, with the `truth` when known), the input (Figs. 5 and 9), measured against
/// simulated output, and the estimates per iteration of the paper's iteration (Figs. 6–7,
/// 10–11) and of the output-error fit.
pub fn cascade_figures(
    fit: &CascadeFit,
    x: &[f64],
    y: &[f64],
    truth: Option<&HysteresisCascade>,
) -> Result<Vec<Svg>> {
    let mut files = Vec::new();
    let v_est = fit.model.hysteresis.simulate_unchecked(x, 0.0);
    let v_true = truth.map(|t| t.hysteresis.simulate_unchecked(x, 0.0));
    let mut loops = Figure::new(
        "Hysteresis loops: v against x",
        "x (hysteresis input)",
        "v (hysteresis output)",
    );
    if let Some(v) = &v_true {
        loops = loops.with(Series::line("true", x, v));
    }
    loops = loops.with(Series::dashed("identified", x, &v_est));
    files.push(svg("loops.svg", render(&loops)?));
    let input = Figure::new("Input x", "sample", "x").with(Series::indexed("x", x, Style::Line));
    files.push(svg("input.svg", render(&input)?));
    let yhat = &fit.output_error.simulated[0][0];
    let title = format!(
        "Output: measured and simulated (fit {:.2} %)",
        metrics::fit_percent(y, yhat)
    );
    let output = Figure::new(&title, "sample", "y")
        .with(Series::indexed("measured", y, Style::Line))
        .with(Series::indexed("simulated", yhat, Style::DashedLine));
    files.push(svg("output.svg", render(&output)?));
    let names = fit.output_error.parameters.names();
    let truth_params = truth.map(|t| t.params());
    if let Some(k) = fit.key_term.as_ref().filter(|k| k.history.len() > 1) {
        let title = "Paper iteration (key-term separation): estimates per iteration";
        let doc = convergence(title, &names, &k.history, truth_params.as_deref())?;
        files.push(svg("paper_iteration.svg", doc));
    }
    let lm: Vec<Vec<f64>> = fit
        .output_error
        .report
        .history
        .iter()
        .map(|r| r.theta.clone())
        .collect();
    if !lm.is_empty() {
        let title = "Output-error fit: estimates per iteration";
        let doc = convergence(title, &names, &lm, truth_params.as_deref())?;
        files.push(svg("output_error_iterations.svg", doc));
    }
    Ok(files)
}

/// The plots of a hysteresis fit: measured and simulated output against the input (every
/// experiment), and measured against simulated output of the first experiment.
pub fn hysteresis_figures(fit: &HysteresisFit, data: &IdData) -> Result<Vec<Svg>> {
    let x_name = data.input_channels()[0].to_string();
    let y_name = data.output_channels()[0].to_string();
    let mut loops = Figure::new(
        "Hysteresis: measured and simulated output against input",
        &x_name,
        &y_name,
    );
    let labels: Vec<(String, String)> = (0..data.n_experiments())
        .map(|e| {
            (
                format!("measured {}", e + 1),
                format!("simulated {}", e + 1),
            )
        })
        .collect();
    for (e, exp) in data.experiments().iter().enumerate() {
        loops = loops
            .with(Series::points(&labels[e].0, exp.input(0), exp.output(0)))
            .with(Series::dashed(
                &labels[e].1,
                exp.input(0),
                &fit.output_error.simulated[e][0],
            ));
    }
    let loops = svg("loops.svg", render(&loops)?);
    let exp = data.experiment(0);
    let title = format!(
        "Output: measured and simulated (fit {:.2} %)",
        fit.output_error.fit_percent[0][0]
    );
    let output = Figure::new(&title, "sample", &y_name)
        .with(Series::indexed("measured", exp.output(0), Style::Line))
        .with(Series::indexed(
            "simulated",
            &fit.output_error.simulated[0][0],
            Style::DashedLine,
        ));
    Ok(vec![loops, svg("output.svg", render(&output)?)])
}

/// The plots of a grey-box fit: measured against simulated output, the residual auto- and
/// input cross-correlations of the first experiment with their 99 % band, and the criterion
/// per iteration.
pub fn greybox_figures(
    fit: &GreyBoxFit,
    data: &IdData,
    residuals: &[ResidualAnalysis],
) -> Result<Vec<Svg>> {
    let exp = data.experiment(0);
    let t: Vec<f64> = (0..exp.len()).map(|k| k as f64 * data.ts()).collect();
    let y_name = data.output_channels()[0].to_string();
    let title = format!(
        "Output: measured and simulated (fit {:.2} %)",
        fit.fit.fit_percent[0][0]
    );
    let output = Figure::new(&title, "t [s]", &y_name)
        .with(Series::line("measured", &t, exp.output(0)))
        .with(Series::dashed("simulated", &t, &fit.fit.simulated[0][0]));
    let mut files = vec![svg("output.svg", render(&output)?)];
    if let Some(a) = residuals.first() {
        files.push(svg("residuals.svg", residual_panels(a)?));
    }
    let cost: Vec<f64> = fit.fit.report.history.iter().map(|r| r.cost).collect();
    let convergence = Figure::new("Criterion per iteration", "iteration", "sum of squares")
        .with(Series::indexed("S", &cost, Style::Line));
    files.push(svg("convergence.svg", render(&convergence)?));
    Ok(files)
}

/// Residual auto-correlation and input-residual cross-correlation side by side.
fn residual_panels(a: &ResidualAnalysis) -> Result<String> {
    let lag_max = a.max_lag as f64;
    let lags: Vec<f64> = (0..=a.max_lag).map(|l| l as f64).collect();
    let cross_lags: Vec<f64> = (-(a.max_lag as i64)..=a.max_lag as i64)
        .map(|l| l as f64)
        .collect();
    let auto = Figure::new("Residual auto-correlation", "lag", "r")
        .with(Series::new(
            "r_e",
            lags.as_slice(),
            a.autocorrelation.as_slice(),
            Style::Points,
        ))
        .with(hline("99 %", (0.0, lag_max), a.band))
        .with(hline("-99 %", (0.0, lag_max), -a.band));
    let cross = Figure::new("Input-residual cross-correlation", "lag", "r")
        .with(Series::new(
            "r_eu",
            cross_lags.as_slice(),
            a.cross_correlation[0].as_slice(),
            Style::Points,
        ))
        .with(hline("99 %", (-lag_max, lag_max), a.band))
        .with(hline("-99 %", (-lag_max, lag_max), -a.band));
    render_panels("Residual analysis (experiment 1)", &[auto, cross], 2)
}

/// One plot per benchmark test record: measured, simulated and their difference
/// (`test1.svg`, `test2.svg`, …).
pub fn benchmark_test_figures(tests: &[BenchmarkTest]) -> Result<Vec<Svg>> {
    tests
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let title = format!("Test {}: e_RMS {:.3e} m", t.source, t.e_rms);
            let error = t.error();
            let fig = Figure::new(&title, "sample", "y [m]")
                .with(Series::indexed("measured", &t.y, Style::Line))
                .with(Series::indexed("simulated", &t.yhat, Style::DashedLine))
                .with(Series::indexed("error", &error, Style::Line));
            Ok(svg(&format!("test{}.svg", i + 1), render(&fig)?))
        })
        .collect()
}

/// The figures of the actuator identification (Gunnar et al. 2006): Figure 2 (the loops of
/// step 2 and the step-2 model), Figure 4 (torque against torsion, measured and simulated by
/// m67), the compare plots of data sets 6–8 (sample time `ts`) and the convergence of m67
/// (with the `truth` when known).
pub fn actuator_figures(
    id: &ActuatorIdentification,
    truth: Option<&[f64]>,
    ts: f64,
) -> Result<Vec<Svg>> {
    let mut files = vec![
        svg("fig2_loops.svg", loops_figure(id)?),
        svg("fig4_torque_torsion.svg", torque_torsion_figure(id)?),
        svg("compare.svg", compare_figure(id, ts)?),
    ];
    let m67 = &id.step3["m67"].fit.report.history;
    if !m67.is_empty() {
        let names: Vec<String> = PARAMETERS.iter().map(|p| p.to_string()).collect();
        let mut history: Vec<Vec<f64>> = vec![id.m0.clone()];
        history.extend(m67.iter().map(|r| r.theta[..PARAMETERS.len()].to_vec()));
        let title = "m67: estimates per iteration (0 = m0)";
        files.push(svg(
            "m67_convergence.svg",
            convergence(title, &names, &history, truth)?,
        ));
    }
    Ok(files)
}

fn loops_figure(id: &ActuatorIdentification) -> Result<String> {
    let labels: Vec<String> = id
        .step2
        .loops
        .iter()
        .map(|l| format!("set {} (Q = {:.3} rad)", l.set, l.q))
        .collect();
    let curves: Vec<(Vec<f64>, Vec<f64>)> = id
        .step2
        .loops
        .iter()
        .map(|l| id.step2.model_loop(l.q, 200))
        .collect();
    let mut fig = Figure::new(
        "Figure 2: steady-state loops (points) and the step-2 model (lines)",
        "torsion x1 [rad]",
        "τn [N·m]",
    );
    for ((l, label), (x, y)) in id.step2.loops.iter().zip(&labels).zip(&curves) {
        fig = fig
            .with(Series::new(
                label.as_str(),
                thin(&l.x1, 400),
                thin(&l.tau_n, 400),
                Style::Points,
            ))
            .with(Series::new("", x.as_slice(), y.as_slice(), Style::Line));
    }
    render(&fig)
}

fn torque_torsion_figure(id: &ActuatorIdentification) -> Result<String> {
    let titles = ["data set 6", "data set 7", "data set 8"];
    let panels: Vec<Figure> = id
        .validation
        .experiments()
        .iter()
        .zip(&id.simulated["m67"])
        .zip(titles)
        .map(|((exp, sim), title)| {
            let tau = thin(exp.input(0), PLOT_POINTS);
            let fig = Figure::new(title, "torsion x1 [rad]", "torque τ [N·m]").with(Series::new(
                "measured",
                thin(exp.output(0), PLOT_POINTS),
                tau.clone(),
                Style::Line,
            ));
            if sim.is_empty() {
                fig
            } else {
                fig.with(Series::new(
                    "simulated (m67)",
                    thin(sim, PLOT_POINTS),
                    tau,
                    Style::DashedLine,
                ))
            }
        })
        .collect();
    render_panels(
        "Figure 4: torque against torsion, measured and simulated",
        &panels,
        3,
    )
}

fn compare_figure(id: &ActuatorIdentification, ts: f64) -> Result<String> {
    let titles: Vec<String> = (6..=8)
        .map(|set| {
            let f = &id.fit_table;
            format!(
                "data set {set}: fit m0 {:.1} %, m67 {:.1} %",
                f["m0"][set - 6],
                f["m67"][set - 6]
            )
        })
        .collect();
    let times: Vec<Vec<f64>> = id
        .validation
        .experiments()
        .iter()
        .map(|e| (0..e.len()).map(|k| k as f64 * ts).collect())
        .collect();
    let panels: Vec<Figure> = (0..3)
        .map(|e| {
            let exp = &id.validation.experiments()[e];
            let t = thin(&times[e], PLOT_POINTS);
            let mut fig = Figure::new(&titles[e], "t [s]", "torsion x1 [rad]").with(Series::new(
                "measured",
                t.clone(),
                thin(exp.output(0), PLOT_POINTS),
                Style::Line,
            ));
            for name in ["m0", "m67"] {
                let sim = &id.simulated[name][e];
                if !sim.is_empty() {
                    fig = fig.with(Series::new(
                        name,
                        t.clone(),
                        thin(sim, PLOT_POINTS),
                        Style::DashedLine,
                    ));
                }
            }
            fig
        })
        .collect();
    render_panels_sized(
        "Measured and simulated torsion (MATLAB compare)",
        &panels,
        1,
        (1400, 1050),
    )
}

/// Every k-th sample, k chosen to keep at most `max` of them.
fn thin(x: &[f64], max: usize) -> Vec<f64> {
    let step = x.len().div_ceil(max.max(1)).max(1);
    x.iter().step_by(step).copied().collect()
}

/// The plots of an operator cascade fit (any hysteresis operator Γ followed by a linear block,
/// `docs/models/operator-cascade.md`) on input `u` and output `y`: the identified operator's
/// loop v = Γ\[u\] against u, and the measured against the simulated output.
pub fn operator_cascade_figures(
    fit: &crate::identify::operator_cascade::OperatorCascadeFit,
    u: &[f64],
    y: &[f64],
) -> Result<Vec<Svg>> {
    let v = fit.model.simulate(u)?.v;
    let loops = Figure::new(
        "Identified operator: v against u",
        "u (input)",
        "v (operator output)",
    )
    .with(Series::line("identified", u, &v));
    let yhat = &fit.output_error.simulated[0][0];
    let title = format!(
        "Output: measured and simulated (fit {:.2} %)",
        fit.fit_percent
    );
    let output = Figure::new(&title, "sample", "y")
        .with(Series::indexed("measured", y, Style::Line))
        .with(Series::indexed("simulated", yhat, Style::DashedLine));
    Ok(vec![
        svg("loops.svg", render(&loops)?),
        svg("output.svg", render(&output)?),
    ])
}
