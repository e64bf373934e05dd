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
//! Each kind's program is its struct's [`ExportKind`] (the structs of `fitted_kinds!`,
//! [`crate::model::kinds`]; the list generates the dispatch). Every step sets the diverged
//! flag where the library's `simulate` errors on a non-finite output; a compensator's command is limited to [`ExportOptions::limits`] and a bad
//! (non-finite) sample skipped, by the rule of [`crate::model::limits`].

use super::code::{call, Expr};
use super::program::{count_clip, limit, Ns, Program, DIVERGED_FIELD};
use super::{coleman_hodgdon, families, greybox, linear, ExportOptions};
use crate::model::coleman_hodgdon::InitialOutput;
use crate::model::kinds::fitted_kinds;
use crate::model::saved::{
    FittedCascade, FittedEquations, FittedGreyBox, FittedHysteresis, FittedHysteresisOperator,
    FittedKind, FittedModel, FittedOperatorCascade,
};
use crate::{Error, Result};
use std::ops::Not;

/// What an export knows of a fitted model of one kind: its streaming program. Implemented
/// for each struct of `fitted_kinds!` ([`crate::model::kinds`]), here, in the export layer.
pub trait ExportKind {
    /// The streaming program of the model, or of its compensator when `options.inverse`,
    /// sampled every `ts` seconds.
    fn program(&self, options: &ExportOptions, ts: f64) -> Result<Program>;
}

/// Generates the dispatch from a [`FittedModel`] to its kind's [`ExportKind`].
macro_rules! define_export_dispatch {
    ($($(#[$doc:meta])* $variant:ident => $fitted:ty),* $(,)?) => {
        /// The export of `model`'s kind; None for a model behind its record processing.
        fn export_kind(model: &FittedModel) -> Option<&dyn ExportKind> {
            match model {
                $(FittedModel::$variant(m) => Some(m),)*
                FittedModel::Prefiltered { .. } | FittedModel::InverseDynamics { .. } => None,
            }
        }
    };
}

fitted_kinds!(define_export_dispatch);

/// The streaming program of `model`, or of its compensator when `inverse`, sampled every
/// `ts` seconds (read by the grey-box models only).
pub fn program(model: &FittedModel, options: &ExportOptions, ts: f64) -> Result<Program> {
    match export_kind(model) {
        Some(kind) => kind.program(options, ts),
        None => Err(Error::UnsupportedKind {
            kind: model.to_file().kind().to_string(),
            operation: "export as code (a model fitted to pre-filtered records or by \
                        inverse dynamics needs the whole record; export the model itself)"
                .into(),
        }),
    }
}

/// After the declared history the model starts from, as `simulate`, the streams and the
/// compensators run it (`model::operators::initial_state`).
impl ExportKind for FittedHysteresisOperator {
    fn program(&self, options: &ExportOptions, _ts: f64) -> Result<Program> {
        let history = self.history();
        chained(options, |op, _, _, prog| {
            Ok(vec![match options.inverse {
                false => families::forward_after(&self.model, history, op, prog)?,
                true => families::inverse_after(&self.model, history, op, prog)?,
            }])
        })
    }
}

impl ExportKind for FittedOperatorCascade {
    fn program(&self, options: &ExportOptions, _ts: f64) -> Result<Program> {
        let model = &self.model;
        if !options.inverse {
            return chained(options, |op, lin, _, prog| {
                Ok(vec![
                    families::forward(&model.operator, op, prog)?,
                    linear::forward(&model.linear, lin, prog)?,
                ])
            });
        }
        let radius = model.zero_radius();
        if radius >= 1.0 {
            return Err(Error::NotInvertible {
                kind: self.saved().kind().to_string(),
                reason: format!(
                    "the linear block is not minimum phase (a zero of B at |z| = {radius:.4} \
                     >= 1), so its inverse is unstable; export the operator's compensator \
                     alone, or refit with fewer B coefficients"
                ),
            });
        }
        chained(options, |op, lin, _, prog| {
            Ok(vec![
                linear::inverse(&model.linear, lin, prog)?,
                families::inverse(&model.operator, op, prog)?,
            ])
        })
    }
}

impl ExportKind for FittedHysteresis {
    fn program(&self, options: &ExportOptions, _ts: f64) -> Result<Program> {
        let (model, initial) = (&self.model, self.initial);
        if options.inverse {
            return chained(options, |_, _, ch, prog| {
                Ok(vec![coleman_hodgdon::inverse(model, initial, ch, prog)?])
            });
        }
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
        chained(options, |_, _, ch, prog| {
            Ok(vec![coleman_hodgdon::forward(model, v0, ch, prog)?])
        })
    }
}

impl ExportKind for FittedCascade {
    fn program(&self, options: &ExportOptions, _ts: f64) -> Result<Program> {
        if options.inverse {
            return Err(crate::model::kinds::not_invertible(self.saved().kind()));
        }
        let model = &self.model;
        chained(options, |_, lin, ch, prog| {
            Ok(vec![
                coleman_hodgdon::forward(&model.hysteresis, 0.0, ch, prog)?,
                linear::forward(&model.linear, lin, prog)?,
            ])
        })
    }
}

impl ExportKind for FittedGreyBox {
    fn program(&self, options: &ExportOptions, ts: f64) -> Result<Program> {
        greybox::grey_box_program(self, options.inverse, ts)
    }
}

impl ExportKind for FittedEquations {
    fn program(&self, options: &ExportOptions, ts: f64) -> Result<Program> {
        greybox::equations_program(self, options.inverse, ts)
    }
}

/// The program of a single-input, single-output kind whose step applies helpers in turn to
/// its input: `helpers` emits them into the program (given the namespaces of the operator,
/// the linear block and the Coleman–Hodgdon recursion) and returns their names in the order
/// applied. Every step sets the diverged flag on a non-finite value; a compensator's
/// command is limited to [`ExportOptions::limits`] and clipped references are counted.
fn chained(
    options: &ExportOptions,
    helpers: impl FnOnce(&Ns, &Ns, &Ns, &mut Program) -> Result<Vec<String>>,
) -> Result<Program> {
    let inverse = options.inverse;
    let mut prog = Program::new(1, 1);
    if inverse {
        prog.count_clipped()?;
    }
    let (op, lin, ch) = (Ns::new("op_"), Ns::new("lin_"), Ns::new("ch_"));
    let chain = helpers(&op, &lin, &ch, &mut prog)?;
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
