//! Each operator family's streaming code: one file per family implementing [`Emit`], and the
//! dispatch from an [`OperatorModel`] to it, generated from the family registry
//! (`operator_families!`), so that a family missing here does not compile.
//!
//! The rate-independent families with a core operator G and an [`Orientation`] implement
//! [`oriented::EmitCore`] (G and G⁻¹) and get their [`Emit`] from [`oriented`]; the
//! differential families implement [`differential::EmitOde`] (their slope and output) and
//! get theirs from the one Dormand–Prince driver of [`differential`].
//!
//! [`Orientation`]: crate::model::operators::Orientation

pub mod backlash;
pub mod bouc_wen;
pub mod dahl;
pub mod differential;
pub mod duhem;
pub mod gpi;
pub mod jiles_atherton;
pub mod kp;
pub mod maxwell_slip;
pub mod oriented;
pub mod pi;
pub mod preisach;

use super::code::{lit, local, Expr, Ty};
use super::program::{Ns, Program};
use crate::model::operators::differential::HistoryRun;
use crate::model::operators::initial_state::History;
use crate::model::operators::OperatorModel;
use crate::Result;
use std::ops::Not;

/// What a family supplies to the exporter: its forward step and its inverse step, as helpers
/// of a [`Program`] in the namespace `ns`.
pub trait Emit {
    /// Emits `ns.step(x) -> f64`: Γ\[u\]ₖ for the input uₖ = x (the sample the library's
    /// `simulate` gives at k), advancing the operator's state; with the fields and the
    /// initialisation it needs. Returns the helper's name.
    fn emit_forward(&self, ns: &Ns, prog: &mut Program) -> Result<String>;
    /// Emits `ns.inverse(r) -> f64`: the input uₖ the library's `invert` gives for the
    /// reference rₖ, advancing the state; with `history`, the first command runs that
    /// declared history as the library's differential inverse does
    /// (`differential::HistoryRun`; the other families are primed by [`inverse_after`] and
    /// are given None). Returns the helper's name.
    fn emit_inverse(
        &self,
        history: Option<HistoryRun>,
        ns: &Ns,
        prog: &mut Program,
    ) -> Result<String>;
}

/// The dispatch from an operator of any family to its [`Emit`].
macro_rules! dispatch {
    ($($variant:ident: $ty:ty),* $(,)?) => {
        /// The family's forward step ([`Emit::emit_forward`]).
        pub fn forward(op: &OperatorModel, ns: &Ns, prog: &mut Program) -> Result<String> {
            match op {
                $(OperatorModel::$variant(m) => Emit::emit_forward(m, ns, prog),)*
            }
        }
        /// The family's inverse step ([`Emit::emit_inverse`]) from its documented initial
        /// state.
        pub fn inverse(op: &OperatorModel, ns: &Ns, prog: &mut Program) -> Result<String> {
            inverse_running(op, None, ns, prog)
        }
        /// The family's inverse step ([`Emit::emit_inverse`]) running `history`.
        fn inverse_running(
            op: &OperatorModel,
            history: Option<HistoryRun>,
            ns: &Ns,
            prog: &mut Program,
        ) -> Result<String> {
            match op {
                $(OperatorModel::$variant(m) => Emit::emit_inverse(m, history, ns, prog),)*
            }
        }
    };
}
crate::model::operators::operator_families!(dispatch);

/// The forward step after the declared `history` (none: the family's step as it is): at the
/// first good sample u₀ the step runs u₀ and the turn u_turn (their outputs dropped), then u₀,
/// the path of the library's stream (`OperatorModel::stepper_from`) with the same arithmetic
/// for u_turn ([`History::turn_at`]), so the same bits. Returns the helper to call.
pub fn forward_after(
    op: &OperatorModel,
    history: Option<History>,
    ns: &Ns,
    prog: &mut Program,
) -> Result<String> {
    let step = forward(op, ns, prog)?;
    let Some(history) = history else {
        return Ok(step);
    };
    let primed = prog.field(
        &ns.name("history_run"),
        Ty::Flag,
        None,
        "the declared history has run (at the first good sample)",
    )?;
    let reach = History::reach(op.as_operator());
    prog.bound(format!(
        "the first good sample runs the declared {} history: three steps of the operator",
        history.state.name()
    ));
    prog.function(
        &ns.name("after_history"),
        &[("x", Ty::F64)],
        Some(Ty::F64),
        |b| {
            b.if_(Expr::State(primed.clone()).not(), |b| {
                let turn = turn_at(history, reach, local("x"));
                let turn = b.let_("turn", turn);
                b.call(&step, vec![local("x")]);
                b.call(&step, vec![turn]);
                b.set_state(&primed, Expr::Flag(true));
            });
            b.ret(Expr::Call(step.clone(), vec![local("x")]));
        },
    )
}

/// The turn of a declared history before a record whose first input is `x`, with the
/// library's arithmetic ([`History::turn_at`]): the saved turn when it lies beyond x in the
/// history's direction, otherwise x ± max(reach, |x − turn|, 10⁻⁶·max(|x|, 1)).
pub(super) fn turn_at(history: History, reach: f64, x: Expr) -> Expr {
    let direction = history.direction();
    let beyond = match history.turn {
        Some(t) => (x.clone() - lit(t)).abs(),
        None => lit(0.0),
    };
    let margin = lit(reach)
        .max(beyond)
        .max(lit(1e-6) * x.clone().abs().max(lit(1.0)));
    let own = x.clone() + lit(direction) * margin;
    match history.turn {
        Some(t) => super::code::select(((lit(t) - x) * lit(direction)).gt(lit(0.0)), lit(t), own),
        None => own,
    }
}

/// The inverse step after the declared `history`, where it reaches the library's inverse
/// (`OperatorModel::history_reaches_the_inverse`): for a family whose memory wipes out the
/// initialisation runs the inverse once on the priming reference r_turn
/// (`OperatorModel::priming_reference`), as the library's compensator does at construction
/// and reset; a differential family's first command runs the history on each trial
/// (`differential::HistoryRun`). Returns the helper to call.
pub fn inverse_after(
    op: &OperatorModel,
    history: Option<History>,
    ns: &Ns,
    prog: &mut Program,
) -> Result<String> {
    let priming = op.priming_reference(history)?;
    let run = history
        .filter(|_| priming.is_none() && op.history_reaches_the_inverse(history))
        .map(|history| HistoryRun {
            history,
            reach: History::reach(op.as_operator()),
        });
    let inverse = inverse_running(op, run, ns, prog)?;
    if let Some(r) = priming {
        prog.init(|b| b.call(&inverse, vec![lit(r)]));
    }
    Ok(inverse)
}
