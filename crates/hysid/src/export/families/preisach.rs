//! The discrete Preisach plane (`model::operators::preisach`): the staircase memory with
//! wiping-out, the running sums of the strips' Everett integrals and the Everett function
//! from the triangle's prefix sums, transliterated with the library's order of operations;
//! G⁻¹ is the library's bounded solve on a trial copy of the memory (`Preisach`'s docs,
//! "Inverse"): bisection over the grid levels and the memory's corners, then the root of the
//! quadratic on the interval left, at most 1 + ⌈log₂ N⌉ + 6 + 1 trial steps a sample.
//!
//! **A bounded memory.** The library keeps the alternating dominant extrema in a growing
//! list. Within a cell of uniform density the output depends on where every corner of the
//! staircase lies, so no fixed-size summary (relay states on the grid, areas per cell) is
//! exact, and the number of nested extrema a continuous input can leave has no bound. The
//! generated code keeps up to [`MEMORY_POINTS`] points (the input's current value and 63
//! extrema: 31 nested minor loops inside the major one), exactly the library's list while
//! it fits; an input that would need more sets the error flag (the outputs then hold).
//! The state holds two such memories: the operator's, and the trial copy the inverse's
//! solve evaluates.

use super::oriented::EmitCore;
use crate::export::code::{call, idx, local, select, typed, Block, Expr, Ty};
use crate::export::program::{Ns, Program, DIVERGED_FIELD};
use crate::model::operators::elementary::halvings;
use crate::model::operators::preisach::{column_sums, prefix_sums, row_sums, Grid};
use crate::model::operators::{Orientation, Preisach};
use crate::Result;
use std::ops::Not;

/// The points of one staircase memory the generated code holds.
pub const MEMORY_POINTS: usize = 64;
/// The strips (running sums) of one memory: half the points.
const STRIPS: usize = MEMORY_POINTS / 2;

/// The names of the memory's fields and helpers.
struct Memory {
    pts: String,
    len: String,
    prefix: String,
    plen: String,
}

impl Memory {
    fn declare(prog: &mut Program, ns: &Ns) -> Result<Self> {
        Ok(Self {
            pts: prog.field(
                &ns.name("pts"),
                Ty::F64,
                Some(2 * MEMORY_POINTS),
                "the staircase memories (the operator's, then the trial copy): alternating extrema, the input last",
            )?,
            len: prog.field(&ns.name("len"), Ty::Index, Some(2), "the points of each memory")?,
            prefix: prog.field(
                &ns.name("prefix"),
                Ty::F64,
                Some(2 * STRIPS),
                "the running sums of the strips' Everett integrals of each memory",
            )?,
            plen: prog.field(&ns.name("plen"), Ty::Index, Some(2), "the running sums held")?,
        })
    }
    /// Point i of memory m.
    fn p(&self, m: &Expr, i: Expr) -> Expr {
        Expr::StateAt(self.pts.clone(), Box::new(m.clone() * MEMORY_POINTS + i))
    }
    fn set_p(&self, b: &mut Block, m: &Expr, i: Expr, v: Expr) {
        b.set_at(&self.pts, m.clone() * MEMORY_POINTS + i, v);
    }
    fn len(&self, m: &Expr) -> Expr {
        Expr::StateAt(self.len.clone(), Box::new(m.clone()))
    }
    fn q(&self, m: &Expr, i: Expr) -> Expr {
        Expr::StateAt(self.prefix.clone(), Box::new(m.clone() * STRIPS + i))
    }
    fn plen(&self, m: &Expr) -> Expr {
        Expr::StateAt(self.plen.clone(), Box::new(m.clone()))
    }
}

/// The names of the grid's tables and its interval function, which both Everett forms use.
struct GridTables {
    /// x_0 … x_N.
    level: String,
    /// The cell weights.
    w: String,
    /// The prefix sums over the triangle.
    q: String,
    /// `ns.interval(x)`: the interval of x, clamped to 0 … N − 1 (`Grid::interval`).
    interval: String,
}

/// Emits the tables `level`, `w`, `q` and the function `ns.interval(x)`.
fn grid_tables(op: &Preisach, ns: &Ns, prog: &mut Program) -> Result<GridTables> {
    let g = *op.grid();
    let n = g.n;
    let h = (g.upper - g.lower) / n as f64;
    let levels: Vec<f64> = (0..=n).map(|k| g.level(k)).collect();
    Ok(GridTables {
        level: prog.table(&ns.table("level"), levels)?,
        w: prog.table(&ns.table("w"), op.weights().to_vec())?,
        q: prog.table(&ns.table("q"), prefix_sums(&g, op.weights()))?,
        interval: prog.function(
            &ns.name("interval"),
            &[("x", Ty::F64)],
            Some(Ty::Index),
            |b| {
                let k = ((local("x") - g.lower) / h).floor().max(0.0);
                b.ret(k.min((n - 1) as f64).to_index());
            },
        )?,
    })
}

/// Emits the Everett function `ns.everett(alpha, beta)` of the simulation
/// (`Preisach::everett`: the cut cells of one row and one column summed).
fn everett(op: &Preisach, ns: &Ns, prog: &mut Program) -> Result<String> {
    let g = *op.grid();
    let h = (g.upper - g.lower) / g.n as f64;
    let GridTables {
        level,
        w,
        q,
        interval,
    } = grid_tables(op, ns, prog)?;
    let t = |name: &str, i: Expr| Expr::Table(name.into(), Box::new(i));
    let n = g.n;
    let hh = h * h;
    let level_c = level.clone();
    let fraction = prog.function(
        &ns.name("fraction"),
        &[
            ("i", Ty::Index),
            ("j", Ty::Index),
            ("b_lo", Ty::F64),
            ("a_hi", Ty::F64),
        ],
        Some(Ty::F64),
        move |b| {
            let (i, j) = (local("i"), local("j"));
            let bl = b.let_("bl", t(&level_c, j.clone()).max(local("b_lo")));
            let bh = b.let_("bh", t(&level_c, j.clone() + idx(1)));
            let al = b.let_("al", t(&level_c, i.clone()));
            let ah = b.let_("ah", t(&level_c, i.clone() + idx(1)).min(local("a_hi")));
            b.if_(
                bl.clone().ge(bh.clone()).or(al.clone().ge(ah.clone())),
                |b| b.ret(0.0),
            );
            b.if_(i.gt(j), |b| {
                b.ret((bh.clone() - bl.clone()) * (ah.clone() - al.clone()) / hh)
            });
            b.if_(ah.clone().gt(bl.clone()), |b| {
                let tt = b.let_("t", bh.clone().min(ah.clone()));
                let d1 = b.let_("d1", ah.clone() - bl.clone());
                let d2 = b.let_("d2", ah.clone() - tt);
                b.ret((d1.clone() * d1 - d2.clone() * d2) / hh);
            });
            b.ret(0.0);
        },
    )?;
    let cell = |i: Expr, j: Expr| i.clone() * (i + idx(1)) / idx(2) + j;
    prog.function(
        &ns.name("everett"),
        &[("alpha_in", Ty::F64), ("beta_in", Ty::F64)],
        Some(Ty::F64),
        |b| {
            let alpha = b.let_("alpha", local("alpha_in").min(g.upper));
            let beta = b.let_("beta", local("beta_in").max(g.lower));
            b.if_(alpha.clone().le(beta.clone()), |b| b.ret(0.0));
            let ii = b.local("ii", Ty::Index, false, call(&interval, vec![alpha.clone()]));
            let jj = b.local("jj", Ty::Index, false, call(&interval, vec![beta.clone()]));
            let full = b.var("full", 0.0);
            b.if_((jj.clone() + idx(1)).lt(ii.clone()), |b| {
                b.set("full", t(&q, (jj.clone() + idx(1)) * n + ii.clone() - 1));
            });
            let row = b.var("row", 0.0);
            b.for_("j", jj.clone(), ii.clone() + idx(1), |b, j| {
                let f = call(
                    &fraction,
                    vec![ii.clone(), j.clone(), beta.clone(), alpha.clone()],
                );
                b.set("row", row.clone() + t(&w, cell(ii.clone(), j)) * f);
            });
            let col = b.var("col", 0.0);
            b.for_("i", jj.clone(), ii.clone(), |b, i| {
                let f = call(
                    &fraction,
                    vec![i.clone(), jj.clone(), beta.clone(), alpha.clone()],
                );
                b.set("col", col.clone() + t(&w, cell(i, jj.clone())) * f);
            });
            b.ret(full + row + col);
        },
    )
}

/// Emits the Everett function `ns.everett(alpha, beta)` of the inverse
/// (`Preisach::everett_by_sums`: O(1) from the prefix sums over the triangle and along the
/// rows and columns).
fn everett_by_sums(op: &Preisach, ns: &Ns, prog: &mut Program) -> Result<String> {
    let g = *op.grid();
    let h = (g.upper - g.lower) / g.n as f64;
    let GridTables {
        level,
        w,
        q,
        interval,
    } = grid_tables(op, ns, prog)?;
    let rows = prog.table(&ns.table("rows"), row_sums(&g, op.weights()))?;
    let columns = prog.table(&ns.table("columns"), column_sums(&g, op.weights()))?;
    let t = |name: &str, i: Expr| Expr::Table(name.into(), Box::new(i));
    let n = g.n;
    let hh = h * h;
    let cell = |i: Expr, j: Expr| i.clone() * (i + idx(1)) / idx(2) + j;
    prog.function(
        &ns.name("everett"),
        &[("alpha_in", Ty::F64), ("beta_in", Ty::F64)],
        Some(Ty::F64),
        |b| {
            let alpha = b.let_("alpha", local("alpha_in").min(g.upper));
            let beta = b.let_("beta", local("beta_in").max(g.lower));
            b.if_(alpha.clone().le(beta.clone()), |b| b.ret(0.0));
            let i = b.local("i", Ty::Index, false, call(&interval, vec![alpha.clone()]));
            let j = b.local("j", Ty::Index, false, call(&interval, vec![beta.clone()]));
            let diagonal = t(&w, cell(i.clone(), i.clone()));
            b.if_(i.clone().eq(j.clone()), |b| {
                let d = b.let_("d", alpha.clone() - beta.clone());
                b.ret(diagonal.clone() * (d.clone() * d) / hh);
            });
            let whole = b.var("whole", 0.0);
            b.if_((j.clone() + idx(1)).lt(i.clone()), |b| {
                b.set("whole", t(&q, (j.clone() + idx(1)) * n + i.clone() - 1));
            });
            let da = b.let_("da", alpha - t(&level, i.clone()));
            let db = b.let_("db", t(&level, j.clone() + idx(1)) - beta);
            let row = b.let_(
                "row",
                t(&rows, cell(i.clone(), i.clone()))
                    - t(&rows, cell(i.clone(), j.clone() + idx(1))),
            );
            let column = b.let_(
                "column",
                t(&columns, cell(i.clone(), j.clone()))
                    - t(&columns, cell(j.clone() + idx(1), j.clone())),
            );
            b.ret(
                whole
                    + t(&w, cell(i.clone(), j.clone())) * (db.clone() * da.clone()) / hh
                    + row * da.clone() / h
                    + diagonal * (da.clone() * da) / hh
                    + t(&w, cell(j.clone(), j.clone())) * (db.clone() * db.clone()) / hh
                    + column * db / h,
            );
        },
    )
}

/// Emits `ns.apply(m, x) -> index` (`Memory::apply` on memory m: the first point that
/// changed) and `ns.advance(m, x) -> f64` (`State::advance`: the integral over S⁺, by the
/// Everett function `everett`).
fn advance(
    op: &Preisach,
    ns: &Ns,
    prog: &mut Program,
    mem: &Memory,
    everett: &str,
) -> Result<String> {
    let g = *op.grid();
    let m = local("m");
    let apply = prog.function(
        &ns.name("apply"),
        &[("m", Ty::Index), ("x", Ty::F64)],
        Some(Ty::Index),
        |b| {
            let v = b.let_("v", local("x").clamp(g.lower, g.upper));
            let len = b.local("n0", Ty::Index, false, mem.len(&m));
            let cur = b.let_("cur", mem.p(&m, len.clone() - idx(1)));
            b.if_(v.clone().eq(cur.clone()), |b| b.ret(len.clone()));
            let continuing = len.clone().ge(idx(2)).and(
                cur.clone()
                    .gt(mem.p(&m, len.clone() - idx(2)))
                    .eq(v.clone().gt(cur.clone())),
            );
            let first = b.local("first", Ty::Index, true, len.clone());
            b.if_else(
                continuing,
                |b| {
                    mem.set_p(b, &m, len.clone() - idx(1), v.clone());
                    b.set("first", len.clone() - idx(1));
                },
                |b| {
                    b.if_(len.clone().ge(idx(MEMORY_POINTS)), |b| {
                        b.set_state(DIVERGED_FIELD, Expr::Flag(true));
                        b.ret(len.clone());
                    });
                    mem.set_p(b, &m, len.clone(), v.clone());
                    b.set_at(&mem.len, m.clone(), len.clone() + idx(1));
                },
            );
            b.while_(mem.len(&m).ge(idx(3)), |b| {
                let n = b.local("n", Ty::Index, false, mem.len(&m));
                let rising = b.local(
                    "rising",
                    Ty::Flag,
                    false,
                    mem.p(&m, n.clone() - idx(1))
                        .gt(mem.p(&m, n.clone() - idx(2))),
                );
                let older = mem.p(&m, n.clone() - idx(3));
                let passes = select(
                    rising.clone(),
                    v.clone().ge(older.clone()),
                    v.clone().le(older),
                );
                b.if_(passes.not(), |b| b.break_());
                b.if_(n.clone().eq(idx(3)).and(rising.clone().not()), |b| {
                    b.set_at(&mem.len, m.clone(), idx(1));
                    b.set("first", idx(1));
                    b.break_();
                });
                mem.set_p(b, &m, n.clone() - idx(3), mem.p(&m, n.clone() - idx(1)));
                b.set_at(&mem.len, m.clone(), n.clone() - idx(2));
                b.if_((n.clone() - idx(3)).lt(first.clone()), |b| {
                    b.set("first", n.clone() - idx(3))
                });
            });
            b.ret(first);
        },
    )?;
    prog.function(
        &ns.name("advance"),
        &[("m", Ty::Index), ("x", Ty::F64)],
        Some(Ty::F64),
        |b| {
            let first = b.local(
                "first",
                Ty::Index,
                false,
                call(&apply, vec![m.clone(), local("x")]),
            );
            let keep = select(
                first.clone().ge(idx(2)),
                (first.clone() - idx(2)) / idx(2),
                idx(0),
            );
            b.if_(keep.clone().lt(mem.plen(&m)), |b| {
                b.set_at(&mem.plen, m.clone(), keep)
            });
            let strips = mem.len(&m) / idx(2);
            b.for_("strip", mem.plen(&m), strips, |b, s| {
                let k = b.local("k", Ty::Index, false, s * idx(2) + idx(1));
                let next = select(
                    (k.clone() + idx(1)).lt(mem.len(&m)),
                    mem.p(&m, k.clone() + idx(1)),
                    mem.p(&m, k.clone()),
                );
                let m_next = b.let_("m_next", next);
                let big = b.let_("big", mem.p(&m, k.clone()));
                let m_prev = b.let_("m_prev", mem.p(&m, k - idx(1)));
                let a = b.let_(
                    "a",
                    call(everett, vec![big.clone(), m_prev]) - call(everett, vec![big, m_next]),
                );
                let pl = b.local("pl", Ty::Index, false, mem.plen(&m));
                let before = select(pl.clone().gt(idx(0)), mem.q(&m, pl.clone() - idx(1)), 0.0);
                b.set_at(&mem.prefix, m.clone() * STRIPS + pl.clone(), before + a);
                b.set_at(&mem.plen, m.clone(), pl + idx(1));
            });
            let pl = b.local("pl", Ty::Index, false, mem.plen(&m));
            b.ret(select(pl.clone().gt(idx(0)), mem.q(&m, pl - idx(1)), 0.0));
        },
    )
}

/// Initialises both memories to negative saturation (one point, the grid's lower end).
fn init(prog: &mut Program, mem: &Memory, lower: f64) {
    prog.init(|b| {
        for m in 0..2 {
            mem.set_p(b, &idx(m), idx(0), lower.into());
            b.set_at(&mem.len, idx(m), idx(1));
        }
    });
}

impl EmitCore for Preisach {
    fn orientation(&self) -> Orientation {
        Preisach::orientation(self)
    }

    fn emit_core(&self, ns: &Ns, prog: &mut Program) -> Result<String> {
        prog.bound(format!(
            "The Preisach memory ({MEMORY_POINTS} points) takes at most {} wipe-outs and \
             recomputes at most {STRIPS} strips a step, each two Everett integrals over at \
             most {} cut cells.",
            MEMORY_POINTS / 2 - 1,
            2 * self.levels()
        ));
        let mem = Memory::declare(prog, ns)?;
        init(prog, &mem, self.lower());
        let everett = everett(self, ns, prog)?;
        let advance = advance(self, ns, prog, &mem, &everett)?;
        let (c, a0, q_last) = (self.offset(), self.a0(), last_prefix(self));
        prog.function(&ns.name("g"), &[("x", Ty::F64)], Some(Ty::F64), |b| {
            let up = b.let_("up", call(&advance, vec![idx(0), local("x")]));
            b.ret(c + a0 * local("x") + 2.0 * up - q_last);
        })
    }

    fn emit_core_inverse(&self, ns: &Ns, prog: &mut Program) -> Result<(String, Option<String>)> {
        let n = self.levels();
        // ⌈log₂(N + 1)⌉ bisections over the levels, ⌈log₂(STRIPS + 1)⌉ over the corners.
        prog.bound(format!(
            "The Preisach inverse takes at most {} trial steps a step (1 at the grid's end, {} \
             over its {n} levels, {} over the memory's corners, 1 at the last interval's \
             midpoint), each a copy of the memory ({MEMORY_POINTS} points, {STRIPS} sums), at \
             most {} wipe-outs and {STRIPS} strips of two O(1) Everett integrals, then one \
             advance.",
            2 + halvings(n + 1) + halvings(STRIPS),
            halvings(n + 1),
            halvings(STRIPS),
            MEMORY_POINTS / 2 - 1,
        ));
        let mem = Memory::declare(prog, ns)?;
        init(prog, &mem, self.lower());
        let everett = everett_by_sums(self, ns, prog)?;
        let advance = advance(self, ns, prog, &mem, &everett)?;
        let (c, a0, q_last) = (self.offset(), self.a0(), last_prefix(self));
        let one = idx(1);
        let trial = prog.function(&ns.name("trial"), &[("x", Ty::F64)], Some(Ty::F64), |b| {
            b.set_at(&mem.len, one.clone(), mem.len(&idx(0)));
            b.for_("i", idx(0), mem.len(&idx(0)), |b, i| {
                mem.set_p(b, &one, i.clone(), mem.p(&idx(0), i));
            });
            b.set_at(&mem.plen, one.clone(), mem.plen(&idx(0)));
            b.for_("i", idx(0), mem.plen(&idx(0)), |b, i| {
                b.set_at(
                    &mem.prefix,
                    one.clone() * STRIPS + i.clone(),
                    mem.q(&idx(0), i),
                );
            });
            let up = b.let_("up", call(&advance, vec![one.clone(), local("x")]));
            b.ret(c + a0 * local("x") + 2.0 * up - q_last);
        })?;
        let name = bounded_inverse(self, ns, prog, &mem, &trial, &advance)?;
        Ok((name, Some(ns.name("clipped"))))
    }
}

/// Emits `ns.g_inv(v)`, the library's `Preisach::solve` and the advance of the operator's
/// memory with its root (`Preisach::backward_step`), with the same comparisons and order of
/// operations; `trial(x)` is the output after x from a copy of the memory. Sets the flag
/// `ns.clipped`. Returns the function's name.
fn bounded_inverse(
    op: &Preisach,
    ns: &Ns,
    prog: &mut Program,
    mem: &Memory,
    trial: &str,
    advance: &str,
) -> Result<String> {
    let g = *op.grid();
    let n = g.n;
    let (c, a0, q_last) = (op.offset(), op.a0(), last_prefix(op));
    let clipped = crate::export::solve::clipped_field(prog, ns)?;
    let command = prog.field(&ns.name("command"), Ty::F64, None, "the last command")?;
    let output = prog.field(
        &ns.name("output"),
        Ty::F64,
        None,
        "the output of the last command (the branch's start)",
    )?;
    let initial = c + a0 * g.lower + 2.0 * 0.0 - q_last;
    prog.init(|b| {
        b.set_state(&command, g.lower);
        b.set_state(&output, initial);
    });
    let level = ns.table("level");
    let lv = |k: Expr| Expr::Table(level.clone(), Box::new(k));
    let interval = ns.name("interval");
    let f = |x: Expr| call(trial, vec![x]);
    let solve = prog.function(&ns.name("solve"), &[("v", Ty::F64)], Some(Ty::F64), |b| {
        let v = local("v");
        let tol = typed(1e-12, 16.0 * f32::EPSILON as f64) * (1.0 + v.clone().abs());
        b.set_state(&clipped, Expr::Flag(false));
        let u = b.let_("u", Expr::State(command.clone()));
        let y = b.let_("y", Expr::State(output.clone()));
        b.if_(v.clone().eq(y.clone()), |b| b.ret(u.clone()));
        let rising = b.local("rising", Ty::Flag, false, v.clone().gt(y.clone()));
        let end = b.let_("end", select(rising.clone(), g.upper, g.lower));
        // Beyond the grid only a0 x moves: from (x0, f0) the root is linear.
        let linear = |b: &mut Block, x0: Expr, f0: Expr| {
            if a0 > 0.0 {
                let x = b.let_("x_lin", x0.clone() + (v.clone() - f0.clone()) / a0);
                b.if_(x.clone().is_finite(), |b| b.ret(x));
            }
            b.set_state(&clipped, (v.clone() - f0).abs().gt(tol.clone()));
            b.ret(x0);
        };
        let beyond = select(
            rising.clone(),
            u.clone().ge(end.clone()),
            u.clone().le(end.clone()),
        );
        b.if_(beyond, |b| linear(b, u.clone(), y.clone()));
        let f_end = b.let_("f_end", f(end.clone()));
        let short = select(
            rising.clone(),
            f_end.clone().lt(v.clone()),
            f_end.clone().gt(v.clone()),
        );
        b.if_(short, |b| linear(b, end.clone(), f_end.clone()));
        let a = b.var("a", select(rising.clone(), u.clone(), end.clone()));
        let fa = b.var("fa", select(rising.clone(), y.clone(), f_end.clone()));
        let bb = b.var("b", select(rising.clone(), end.clone(), u.clone()));
        let fb = b.var("fb", select(rising.clone(), f_end.clone(), y.clone()));
        // The grid levels strictly inside (a, b): k_lo <= k < k_end.
        let k_lo = b.local(
            "k_lo",
            Ty::Index,
            true,
            select(
                a.clone().lt(g.lower),
                idx(0),
                call(&interval, vec![a.clone()]) + idx(1),
            ),
        );
        b.if_(lv(k_lo.clone()).le(a.clone()), |b| {
            b.set("k_lo", k_lo.clone() + idx(1))
        });
        let k_end = b.local(
            "k_end",
            Ty::Index,
            true,
            select(
                bb.clone().gt(g.upper),
                idx(n + 1),
                call(&interval, vec![bb.clone()]) + idx(1),
            ),
        );
        b.if_(lv(k_end.clone() - idx(1)).ge(bb.clone()), |b| {
            b.set("k_end", k_end.clone() - idx(1))
        });
        let narrow = |b: &mut Block, x: Expr| {
            crate::export::solve::narrow(b, f(x.clone()), x, v.clone(), |_| {})
        };
        b.while_(k_lo.clone().lt(k_end.clone()), |b| {
            let mid = b.local(
                "mid",
                Ty::Index,
                false,
                k_lo.clone() + (k_end.clone() - k_lo.clone()) / idx(2),
            );
            let fx = narrow(b, lv(mid.clone()));
            b.if_else(
                fx.lt(v.clone()),
                |b| b.set("k_lo", mid.clone() + idx(1)),
                |b| b.set("k_end", mid.clone()),
            );
        });
        // The memory's points strictly inside (a, b): p[first], p[first + 2], ...
        let zero = idx(0);
        let len = b.local("len", Ty::Index, false, mem.len(&zero));
        let first = b.local("first", Ty::Index, true, len.clone());
        let last = b.local("last", Ty::Index, true, idx(0));
        b.for_("i", idx(0), len.clone() - idx(1), |b, i| {
            let p = b.let_("p", mem.p(&zero, i.clone()));
            b.if_(p.clone().gt(a.clone()).and(p.lt(bb.clone())), |b| {
                b.if_(i.clone().lt(first.clone()), |b| b.set("first", i.clone()));
                b.set("last", i.clone());
            });
        });
        let j_lo = b.local("j_lo", Ty::Index, true, idx(0));
        let j_end = b.local(
            "j_end",
            Ty::Index,
            true,
            select(
                first.clone().le(last.clone()),
                (last.clone() - first.clone()) / idx(2) + idx(1),
                idx(0),
            ),
        );
        b.while_(j_lo.clone().lt(j_end.clone()), |b| {
            let mid = b.local(
                "mid",
                Ty::Index,
                false,
                j_lo.clone() + (j_end.clone() - j_lo.clone()) / idx(2),
            );
            let fx = narrow(b, mem.p(&zero, first.clone() + idx(2) * mid.clone()));
            b.if_else(
                fx.lt(v.clone()).eq(rising.clone()),
                |b| b.set("j_end", mid.clone()),
                |b| b.set("j_lo", mid.clone() + idx(1)),
            );
        });
        b.if_(fa.clone().eq(v.clone()), |b| b.ret(a.clone()));
        b.if_(fb.clone().eq(v.clone()), |b| b.ret(bb.clone()));
        let m = b.let_("m", 0.5 * (a.clone() + bb.clone()));
        let fm = b.let_("fm", f(m));
        let qa = b.let_("qa", 2.0 * (fb.clone() - 2.0 * fm.clone() + fa.clone()));
        let qb = b.let_("qb", 4.0 * fm - 3.0 * fa.clone() - fb.clone());
        let qc = b.let_("qc", fa - v.clone());
        let disc = b.let_(
            "disc",
            (qb.clone() * qb.clone() - 4.0 * qa * qc.clone()).max(0.0),
        );
        let den = b.let_("den", qb + disc.sqrt());
        let t = b.var("t", 0.0);
        b.if_(den.clone().gt(0.0), |b| {
            let ratio = b.let_("ratio", -2.0 * qc / den);
            b.set("t", ratio.clamp(0.0, 1.0));
        });
        let x = b.let_("x", a.clone() + t * (bb.clone() - a.clone()));
        b.ret(x.clamp(a, bb));
    })?;
    prog.function(&ns.name("g_inv"), &[("v", Ty::F64)], Some(Ty::F64), |b| {
        let x = b.let_("u", call(&solve, vec![local("v")]));
        let up = b.let_("up", call(advance, vec![idx(0), x.clone()]));
        b.set_state(&command, x.clone());
        b.set_state(&output, c + a0 * x.clone() + 2.0 * up - q_last);
        b.ret(x);
    })
}

/// q\[N − 1\] = Σ w: the output's constant −Σ w (all relays down).
fn last_prefix(op: &Preisach) -> f64 {
    let g: Grid = *op.grid();
    prefix_sums(&g, op.weights())[g.n - 1]
}
