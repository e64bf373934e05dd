//! The program of each model kind: which components (an operator of the registry, a linear
//! block, the Coleman–Hodgdon recursion) a model is made of and how its step chains them.
//!
//! | kind | forward | compensator |
//! |---|---|---|
//! | `operator` | the family's step | the family's inverse step |
//! | `operator_cascade` | operator, then the linear block | the block's inverse (the reference k samples ahead), then the operator's inverse; refused unless B is minimum-phase |
//! | `coleman_hodgdon` | the recursion, from 0 (`initial_output: zero`) or from the measured y(0) given at export (`--y0`, `initial_output: measured`) | the per-sample solve |
//! | `ch_cascade` | the recursion from 0, then the linear block | none (as `hysid compensate`) |
//!
//! | grey-box, `equations` | the integration of the last interval, then h(x, u) ([`greybox`]) | none (not invertible) |
//!
//! Every step sets the diverged flag where the library's `simulate` errors on a non-finite
//! output; a compensator's command is limited to [`ExportOptions::limits`] and a bad
//! (non-finite) sample skipped, by the rule of [`crate::model::limits`].

use super::code::{call, Expr};
use super::program::{count_clip, limit, Ns, Program, DIVERGED_FIELD};
use super::{coleman_hodgdon, families, greybox, linear, ExportOptions};
use crate::model::coleman_hodgdon::InitialOutput;
use crate::model::saved::FittedModel;
use crate::{Error, Result};
use std::ops::Not;

/// The streaming program of `model`, or of its compensator when `inverse`, sampled every
/// `ts` seconds (read by the grey-box models only).
pub fn program(model: &FittedModel, options: &ExportOptions, ts: f64) -> Result<Program> {
    let inverse = options.inverse;
    if let Some(prog) = greybox::program(model, inverse, ts)? {
        return Ok(prog);
    }
    let mut prog = Program::new(1, 1);
    if inverse {
        prog.count_clipped()?;
    }
    let (op, lin, ch) = (Ns::new("op_"), Ns::new("lin_"), Ns::new("ch_"));
    let kind = || model.to_file().kind().to_string();
    // The helpers applied in turn to the step's input.
    let chain: Vec<String> = match (model, inverse) {
        (FittedModel::Operator { model, .. }, false) => {
            vec![families::forward(model, &op, &mut prog)?]
        }
        (FittedModel::Operator { model, .. }, true) => {
            vec![families::inverse(model, &op, &mut prog)?]
        }
        (FittedModel::OperatorCascade { model, .. }, false) => vec![
            families::forward(&model.operator, &op, &mut prog)?,
            linear::forward(&model.linear, &lin, &mut prog)?,
        ],
        (FittedModel::OperatorCascade { model, .. }, true) => {
            let radius = model.zero_radius();
            if radius >= 1.0 {
                return Err(Error::NotInvertible {
                    kind: kind(),
                    reason: format!(
                        "the linear block is not minimum phase (a zero of B at |z| = {radius:.4} \
                         >= 1), so its inverse is unstable; export the operator's compensator \
                         alone, or refit with fewer B coefficients"
                    ),
                });
            }
            vec![
                linear::inverse(&model.linear, &lin, &mut prog)?,
                families::inverse(&model.operator, &op, &mut prog)?,
            ]
        }
        (FittedModel::Hysteresis { model, initial, .. }, false) => {
            let v0 = match (initial, options.initial_output) {
                (InitialOutput::Zero, _) => 0.0,
                (InitialOutput::Measured, Some(y0)) if y0.is_finite() => y0,
                (InitialOutput::Measured, _) => {
                    return Err(Error::invalid_option(
                        "y0",
                        options
                            .initial_output
                            .map_or("none".into(), |v| v.to_string()),
                        "this hysteresis starts from the measured output (initial_output: \
                         measured): give the measured initial output y(0), a finite number, \
                         or export its compensator"
                            .into(),
                    ))
                }
            };
            vec![coleman_hodgdon::forward(model, v0, &ch, &mut prog)?]
        }
        (FittedModel::Hysteresis { model, initial, .. }, true) => {
            vec![coleman_hodgdon::inverse(model, *initial, &ch, &mut prog)?]
        }
        (FittedModel::Cascade { model, .. }, false) => vec![
            coleman_hodgdon::forward(&model.hysteresis, 0.0, &ch, &mut prog)?,
            linear::forward(&model.linear, &lin, &mut prog)?,
        ],
        (FittedModel::Cascade { .. }, true) => {
            return Err(Error::NotInvertible {
                kind: kind(),
                reason: "compensation inverts hysteresis operators, the Coleman–Hodgdon \
                         hysteresis alone and operator cascades with a minimum-phase linear \
                         block; identify one of those"
                    .into(),
            })
        }
        _ => {
            return Err(Error::UnsupportedKind {
                kind: kind(),
                operation: "export as code (a model fitted to pre-filtered records or by \
                            inverse dynamics needs the whole record; export the model itself)"
                    .into(),
            })
        }
    };
    let counting = prog.counts_clipped();
    // A compensator's command is limited (`model::limits`), as the library's compensator.
    let limits = options.limits.filter(|_| inverse);
    prog.fallible_step(|b| {
        count_clip(counting, b, |b| {
            let mut value = Expr::Input(0);
            for (i, helper) in chain.iter().enumerate() {
                value = b.let_(&format!("stage{i}"), call(helper, vec![value]));
            }
            b.if_(value.clone().is_finite().not(), |b| {
                b.set_state(DIVERGED_FIELD, Expr::Flag(true))
            });
            match &limits {
                Some(limits) => {
                    limit(b, "y0", value, limits);
                }
                None => {
                    b.let_("y0", value);
                }
            }
        });
    })?;
    if let Some(limits) = limits {
        prog.hold_initially(&[limits.midpoint()]);
    }
    Ok(prog)
}
