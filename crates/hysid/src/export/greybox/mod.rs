//! Grey-box models (the built-in ones and equation files) as streaming code: the library's
//! one-sample step (`model::stream`'s grey-box kernel) transliterated.
//!
//! A step is lazy by one interval, as the library's: step k first integrates the state over
//! [t_{k−1}, t_k] — now that both of its ends u_{k−1}, u_k are known — then gives
//! y_k = h(x(t_k), u_k). The state holds x, the previous input and the number of steps
//! taken (the time of the interval, t = (k − 1 + τ)·ts, for models that read t). The input
//! between the two samples is held (`zero_order_hold`) or interpolated linearly (`linear`)
//! exactly as the library's input track reads it, on the integrator's half-step grid or at
//! a stage's own time.
//!
//! Each model supplies only its right-hand side f(t, x, u) and output h(x, u)
//! ([`EmitStateSpace`]): the built-in models in [`models`], equation files from their
//! compiled listing in [`equations`]. The integrator is emitted once ([`rk4`], with the
//! stick–slip steps of models with Coulomb friction; [`dopri`]; [`newmark`], whose Newton
//! corrector solves with a fixed-size LU with partial pivoting in nalgebra's order of
//! operations, a singular Newton matrix setting the error flag); a discrete-time model runs
//! its recursion. A `band_limited` model is refused: its stream differs from its simulation
//! ([`FittedModel::streaming_differs`](crate::model::saved::FittedModel::streaming_differs)).

pub mod dopri;
pub mod equations;
pub mod models;
pub mod newmark;
pub mod rk4;

use super::code::{idx, local, select, Block, Expr, Ty};
use super::program::{Ns, Program, DIVERGED_FIELD};
use crate::model::greybox::equation_model::EquationStateSpace;
use crate::model::greybox::models::GreyBoxKind;
use crate::model::greybox::simulate::{check_integrator, InputTrack};
use crate::model::greybox::{InputInterpolation, Integrator, Simulation, StateSpaceModel};
use crate::model::saved::{FittedEquations, FittedGreyBox, FittedKind};
use crate::{Error, Result};
use std::ops::Not;

/// Where a right-hand side or an output is evaluated: the expressions of t, x and u.
#[derive(Clone, Debug)]
pub struct Point {
    /// The time in seconds.
    pub t: Expr,
    /// The states.
    pub x: Vec<Expr>,
    /// The inputs.
    pub u: Vec<Expr>,
}

/// A state-space model as code: its right-hand side and output, emitted in the library's
/// order of operations.
pub trait EmitStateSpace {
    /// The library's model (names, sizes, time domain, friction velocity).
    fn model(&self) -> &dyn StateSpaceModel;
    /// Emits into `b` what f(t, x, u) needs and returns one expression per state: ẋ (or
    /// the next state of a discrete-time model), with the Coulomb friction held in the
    /// direction `held` (±1) when Some (the library's `rhs_sliding`).
    fn emit_rhs(&self, b: &mut Block, at: &Point, held: Option<Expr>) -> Vec<Expr>;
    /// Emits into `b` what h(x, u) needs and returns one expression per output.
    fn emit_output(&self, b: &mut Block, at: &Point) -> Vec<Expr>;
}

/// sgn with sgn(0) = 0 (`models::sign0`); `v` is evaluated up to twice: pass a local or a
/// field.
pub fn sign0(v: Expr) -> Expr {
    select(v.clone().gt(0.0), 1.0, select(v.lt(0.0), -1.0, 0.0))
}

/// The names of the driver's state and of the right-hand side's helper.
#[derive(Clone, Debug)]
pub struct Driver {
    /// The namespace of every name below.
    pub ns: Ns,
    /// x at the last sample.
    pub x: String,
    /// The previous input u_{k−1}.
    pub u_prev: String,
    /// This step's input u_k.
    pub u_next: String,
    /// The number of steps taken.
    pub steps: String,
    /// The right-hand side's arguments: x …
    pub xs: String,
    /// … and u; it writes `rate`.
    pub us: String,
    /// f(t, xs, us) as the last `rhs` call wrote it.
    pub rate: String,
    /// `rhs(t, d)`: f at t, xs, us into `rate`, the friction held in d (0: not held).
    pub rhs: String,
    /// The sample time.
    pub ts: f64,
    /// The input interpolation (zero-order hold or linear).
    pub interpolation: InputInterpolation,
}

impl Driver {
    /// The time t_{k−1} of the interval being integrated, as a double (k ≥ 1 steps taken).
    pub fn interval_start(&self) -> Expr {
        (Expr::State(self.steps.clone()) - idx(1)).to_f64()
    }

    /// Writes `us` with the input at fraction `tau` of the interval, as the library's
    /// `InputTrack::at` (and `at_node`, whose τ is the node's) computes it.
    pub fn input_at(&self, b: &mut Block, n_inputs: usize, tau: &Expr) {
        for c in 0..n_inputs {
            let prev = Expr::StateAt(self.u_prev.clone(), Box::new(idx(c)));
            let next = Expr::StateAt(self.u_next.clone(), Box::new(idx(c)));
            let value = match self.interpolation {
                InputInterpolation::Linear => prev.clone() + tau.clone() * (next - prev),
                _ => prev,
            };
            b.set_at(&self.us, idx(c), value);
        }
    }
}

/// A grey-box or equation model to export: its code, its simulation settings and its
/// initial state.
struct Exported<'a> {
    code: Box<dyn EmitStateSpace>,
    simulation: Simulation,
    x0: &'a [f64],
}

impl<'a> Exported<'a> {
    /// The built-in grey-box model `model` as code.
    fn grey_box(model: &'a FittedGreyBox) -> Result<Self> {
        let kind = GreyBoxKind::parse(&model.kind).ok_or_else(|| {
            Error::InvalidModel(format!("unknown grey-box model '{}'", model.kind))
        })?;
        Ok(Self {
            code: Box::new(models::BuiltIn::new(kind, model.parameters.values())),
            simulation: model.simulation,
            x0: &model.initial_state,
        })
    }

    /// The equation model `model` as code.
    fn equations(model: &'a FittedEquations) -> Result<Self> {
        let parsed = EquationStateSpace::parse(&model.equations, "saved model")?;
        Ok(Self {
            code: Box::new(equations::Equations::new(parsed, model.parameters.values())),
            simulation: model.simulation,
            x0: &model.initial_state,
        })
    }
}

/// The streaming program of the built-in grey-box model `model` sampled every `ts` seconds
/// (refused: the compensator, a `band_limited` model, an integrator the library refuses).
pub fn grey_box_program(model: &FittedGreyBox, inverse: bool, ts: f64) -> Result<Program> {
    program(Exported::grey_box(model)?, model, inverse, ts)
}

/// The streaming program of the equation model `model` sampled every `ts` seconds (refused:
/// the compensator, a `band_limited` model, an integrator the library refuses).
pub fn equations_program(model: &FittedEquations, inverse: bool, ts: f64) -> Result<Program> {
    program(Exported::equations(model)?, model, inverse, ts)
}

/// The streaming program of a grey-box or equation model (`exported`, the code of `model`)
/// sampled every `ts` seconds. Refused: the compensator (no grey-box model is invertible),
/// a `band_limited` model, and the integrators the library refuses for the model.
fn program(exported: Exported, model: &dyn FittedKind, inverse: bool, ts: f64) -> Result<Program> {
    let Exported {
        code,
        simulation,
        x0,
    } = exported;
    let kind = || model.saved().kind().to_string();
    if inverse {
        return Err(crate::model::kinds::not_invertible(&kind()));
    }
    if let Some(why) = model.streaming_differs() {
        return Err(Error::UnsupportedKind {
            kind: kind(),
            operation: format!(
                "export as code: {why}; refit it with --interpolation linear (or save it with \
                 \"interpolation\": \"linear\") and export that"
            ),
        });
    }
    let m = code.model();
    let (n, n_in, n_out) = (m.states().len(), m.inputs().len(), m.outputs().len());
    // The library's refusals of an integrator (Coulomb friction needs RK4, Newmark a
    // mechanical model), in its words.
    let rest = [0.0; 2];
    let track = InputTrack::new(&vec![&rest[..]; n_in], &simulation)?;
    check_integrator(m, &track, simulation.integrator)?;
    if x0.len() != n {
        return Err(Error::InvalidModel(format!(
            "the initial state has {} values for {n} states",
            x0.len()
        )));
    }
    let mut prog = Program::new(n_in, n_out);
    let d = driver(code.as_ref(), &Ns::new("gb_"), ts, simulation, &mut prog)?;
    let advance = if m.discrete_time() {
        recursion(code.as_ref(), &d, &mut prog)?
    } else {
        match simulation.integrator {
            Integrator::Rk4 { substeps } => rk4::emit(code.as_ref(), &d, substeps, &mut prog)?,
            Integrator::Adaptive { rtol, atol } => {
                dopri::emit(code.as_ref(), &d, (rtol, atol), &mut prog)?
            }
            Integrator::Newmark { substeps } => {
                newmark::emit(code.as_ref(), &d, substeps, &mut prog)?
            }
        }
    };
    prog.init(|b| {
        for (i, v) in x0.iter().enumerate() {
            b.set_at(&d.x, idx(i), *v);
        }
    });
    prog.fallible_step(|b| step(code.as_ref(), &d, &advance, b))?;
    Ok(prog)
}

/// The step: integrate the last interval (from the second step on), then y = h(x, u).
fn step(code: &dyn EmitStateSpace, d: &Driver, advance: &str, b: &mut Block) {
    let m = code.model();
    let (n, n_in) = (m.states().len(), m.inputs().len());
    let error = |b: &mut Block| b.set_state(DIVERGED_FIELD, Expr::Flag(true));
    for c in 0..n_in {
        b.if_(Expr::Input(c).is_finite().not(), error);
        b.set_at(&d.u_next, idx(c), Expr::Input(c));
    }
    b.if_(Expr::State(d.steps.clone()).gt(idx(0)), |b| {
        b.call(advance, vec![])
    });
    let x: Vec<Expr> = (0..n)
        .map(|i| Expr::StateAt(d.x.clone(), Box::new(idx(i))))
        .collect();
    for xi in &x {
        b.if_(xi.clone().is_finite().not(), error);
    }
    let at = Point {
        t: Expr::F64(0.0),
        x,
        u: (0..n_in).map(Expr::Input).collect(),
    };
    for (i, y) in code.emit_output(b, &at).into_iter().enumerate() {
        let y = b.let_(&format!("y{i}"), y);
        b.if_(y.is_finite().not(), error);
    }
    for c in 0..n_in {
        b.set_at(&d.u_prev, idx(c), Expr::Input(c));
    }
    b.set_state(&d.steps, Expr::State(d.steps.clone()) + idx(1));
}

/// The driver's state and the right-hand side's helper `rhs(t, d)`.
fn driver(
    code: &dyn EmitStateSpace,
    ns: &Ns,
    ts: f64,
    simulation: Simulation,
    prog: &mut Program,
) -> Result<Driver> {
    let m = code.model();
    let (n, n_in) = (m.states().len(), m.inputs().len());
    let f64s = |prog: &mut Program, name: &str, len: usize, doc: &str| {
        prog.field(&ns.name(name), Ty::F64, Some(len), doc)
    };
    let x = f64s(prog, "x", n, "the state at the last sample")?;
    let u_prev = f64s(prog, "u_prev", n_in, "the input at the last sample")?;
    let u_next = f64s(prog, "u_next", n_in, "the input at this sample")?;
    let steps = prog.field(&ns.name("steps"), Ty::Index, None, "the steps taken")?;
    let xs = f64s(
        prog,
        "xs",
        n,
        "the state the right-hand side is evaluated at",
    )?;
    let us = f64s(
        prog,
        "us",
        n_in,
        "the input the right-hand side is evaluated at",
    )?;
    let rate = f64s(prog, "rate", n, "the right-hand side's last value")?;
    let at = Point {
        t: local("t"),
        x: (0..n)
            .map(|i| Expr::StateAt(xs.clone(), Box::new(idx(i))))
            .collect(),
        u: (0..n_in)
            .map(|c| Expr::StateAt(us.clone(), Box::new(idx(c))))
            .collect(),
    };
    let write = |b: &mut Block, held: Option<Expr>| {
        for (i, r) in code.emit_rhs(b, &at, held).into_iter().enumerate() {
            b.set_at(&rate, idx(i), r);
        }
    };
    let sliding = m.stick_slip_velocity().is_some();
    let rhs = prog.function(
        &ns.name("rhs"),
        &[("t", Ty::F64), ("d", Ty::F64)],
        None,
        |b| {
            if sliding {
                let held = local("d");
                b.if_else(
                    held.clone().eq(0.0),
                    |b| write(b, None),
                    |b| write(b, Some(held.clone())),
                );
            } else {
                write(b, None);
            }
        },
    )?;
    let interpolation = match simulation.interpolation {
        InputInterpolation::Linear => InputInterpolation::Linear,
        _ => InputInterpolation::ZeroOrderHold,
    };
    Ok(Driver {
        ns: ns.clone(),
        x,
        u_prev,
        u_next,
        steps,
        xs,
        us,
        rate,
        rhs,
        ts,
        interpolation,
    })
}

/// A discrete-time model's `advance()`: x ← f(t_{k−1}, x, u_{k−1}) with the input read at
/// the start of the interval, as the library's recursion.
fn recursion(code: &dyn EmitStateSpace, d: &Driver, prog: &mut Program) -> Result<String> {
    let m = code.model();
    let (n, n_in) = (m.states().len(), m.inputs().len());
    prog.function(&d.ns.name("advance"), &[], None, |b| {
        d.input_at(b, n_in, &Expr::F64(0.0));
        copy(b, &d.xs, &d.x, n);
        let t = d.interval_start() * d.ts;
        b.call(&d.rhs, vec![t, Expr::F64(0.0)]);
        copy(b, &d.x, &d.rate, n);
    })
}

/// `to[i] = from[i]` for i < n.
pub fn copy(b: &mut Block, to: &str, from: &str, n: usize) {
    b.for_("i", idx(0), idx(n), |b, i| {
        b.set_at(to, i.clone(), Expr::StateAt(from.into(), Box::new(i)));
    });
}
