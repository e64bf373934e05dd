//! Streaming passes of the hysteresis cascade over long records: the simulation written into
//! the caller's buffer, and the output sensitivities, both without allocation or division per
//! sample.
//!
//! # Equations
//!
//! The cascade of Vörös (2015) is the Coleman–Hodgdon recursion (D)
//!
//! ```text
//! v(t) = v(t−1) + α|Δx(t)|(f(x(t)) − v(t−1)) + g(x(t))Δx(t),   v(0) = 0
//! ```
//!
//! followed by the linear block A(q⁻¹)ŷ(t) = Σⱼ bⱼ v(t−k−j+1), j = 1…m. The sensitivities
//! s(t) = ∂v(t)/∂θ_h follow s(t) = (1 − α|Δx|)s(t−1) + ∂(D)/∂θ_h, and every ∂ŷ/∂θ obeys the
//! recursion of ŷ, ∂ŷ(t) = u(t) − Σ aᵢ ∂ŷ(t−i), with u = [Σⱼ bⱼ s(t−k−j+1) for θ_h,
//! v(t−k−j+1) for b_j (j ≥ 2), −ŷ(t−i) for aᵢ].
//!
//! # Why it is fast
//!
//! The linear block needs only the last k + m values of v and s and the last n of ŷ and ∂ŷ:
//! they live in rings whose length is a power of two, so a lag is a mask, not a division. On
//! long records with two or more threads, the (inherently sequential) recursion runs one block
//! ahead on a second thread while the caller's sink consumes the previous block: the caller's
//! work (the Gauss–Newton normal equations) overlaps the recursion. The rows and their order
//! are the same either way, so the results are bit-identical. For ch4/ch6 with n ≤ 3 and
//! m ≤ 3 both passes run as fixed-width instances (`fixed`: const-generic widths, rows in
//! arrays), with the same operations in the same order as the generic passes.
//!
//! Reference: I. Vörös, "Iterative identification of nonlinear dynamic systems with output
//! backlash using three-block cascade models", Nonlinear Dynamics 79, 2015 (the cascade and
//! its internal variables).

use super::hysteresis::hysteresis_sensitivities;
use super::output_error::{BlockSink, SensitivityBlock, SensitivitySink, PASS_THREADS};
use crate::model::HysteresisCascade;
use crate::{Error, Result};
use std::sync::mpsc::{sync_channel, Receiver, SyncSender};

#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub mod fixed;

/// Records at least this long are pipelined over two threads (shorter ones are not worth a
/// thread: the window fits run hundreds of them, already in parallel).
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub const PIPELINE_SAMPLES: usize = 1 << 16;

/// Rows handed from the recursion thread to the sink per block. Each hand-over can wake a
/// sleeping thread (a system call and a scheduler round trip, tens of microseconds on a
/// shared machine): 16 384 rows make 61 of them per 10⁶ samples instead of 244, and one
/// block (1 MB at p = 7) still fits the shared cache. Paired runs of the 10⁶-sample cascade:
/// 0.90–0.93 of the wall time of 4 096-row blocks.
const BLOCK_ROWS: usize = 16384;

/// Rows per block when the recursion and the sink share a thread (the block stays in the
/// first-level caches).
const SEQUENTIAL_ROWS: usize = 512;

/// Recent rows of a signal and its derivatives, in a ring of power-of-two length.
struct Ring {
    mask: usize,
    width: usize,
    values: Vec<f64>,
}

impl Ring {
    /// A ring holding at least `len` rows of `width` values.
    fn new(len: usize, width: usize) -> Self {
        let len = len.max(1).next_power_of_two();
        Self {
            mask: len - 1,
            width,
            values: vec![0.0; len * width],
        }
    }

    /// The row stored for sample `t − lag`, or None before the record starts.
    #[inline]
    fn get(&self, t: usize, lag: usize) -> Option<&[f64]> {
        let s = t.checked_sub(lag)?;
        let i = (s & self.mask) * self.width;
        Some(&self.values[i..i + self.width])
    }

    #[inline]
    fn row_mut(&mut self, t: usize) -> &mut [f64] {
        let i = (t & self.mask) * self.width;
        &mut self.values[i..i + self.width]
    }
}

/// Simulates the cascade from rest over the input `x` into `y` (resized to `x.len()`), with
/// the switching `h` held fixed when given, else h(t) = (|x(t)| > d). Same operations, in the
/// same order, as the hysteresis simulation followed by [`crate::model::LinearBlock::simulate`].
pub fn simulate_into(cascade: &HysteresisCascade, x: &[f64], h: Option<&[bool]>, y: &mut Vec<f64>) {
    if fixed::simulate(cascade, x, h, y).is_none() {
        simulate_generic(cascade, x, h, y);
    }
}

/// [`simulate_into`] for any orders (lengths of A and B known only at run time).
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub fn simulate_generic(
    cascade: &HysteresisCascade,
    x: &[f64],
    h: Option<&[bool]>,
    y: &mut Vec<f64>,
) {
    let ch = &cascade.hysteresis;
    let lin = &cascade.linear;
    let (a, b, k) = (lin.a(), lin.b(), lin.delay());
    let mut v = Ring::new(k + b.len(), 1);
    y.clear();
    y.reserve(x.len());
    let mut v_prev = 0.0;
    for t in 0..x.len() {
        let vt = if t == 0 {
            0.0
        } else {
            let outside = ch.outside_at(x, t, h);
            ch.step_in(v_prev, x[t - 1], x[t], outside)
        };
        v.row_mut(t)[0] = vt;
        v_prev = vt;
        let mut acc = 0.0;
        for (i, &ai) in a.iter().enumerate() {
            if let Some(s) = t.checked_sub(i + 1) {
                acc -= ai * y[s];
            }
        }
        for (j, &bj) in b.iter().enumerate() {
            if let Some(past) = v.get(t, k + j) {
                acc += bj * past[0];
            }
        }
        y.push(acc);
    }
}

/// Simulates the cascade with its output sensitivities to the parameters `free` (see the
/// module docs) and streams them into `sink` sample by sample (the rows of
/// [`stream_sensitivity_blocks`], one at a time).
/// Fails with [`Error::Diverged`] at the first sample whose simulated output is not finite.
pub fn stream_sensitivities(
    cascade: &HysteresisCascade,
    x: &[f64],
    h: Option<&[bool]>,
    free: &[usize],
    sink: &mut SensitivitySink<'_>,
) -> Result<()> {
    stream_sensitivity_blocks(cascade, x, h, free, PASS_THREADS, &mut |block| {
        for (i, row) in block.rows.chunks_exact(block.width).enumerate() {
            // The pass runs to the end: the sink ignores what follows a Break.
            let _ = sink(block.start + i, &row[..1], &row[1..]);
        }
    })
}

/// Simulates the cascade with its output sensitivities to the parameters `free` and streams
/// them into `sink` in blocks of consecutive samples, pipelined over two threads on long
/// records when `threads` (the threads the pass may keep busy) and the machine allow.
/// Fails with [`Error::Diverged`] at the first sample whose simulated output is not finite.
pub fn stream_sensitivity_blocks(
    cascade: &HysteresisCascade,
    x: &[f64],
    h: Option<&[bool]>,
    free: &[usize],
    threads: usize,
    sink: &mut BlockSink<'_>,
) -> Result<()> {
    let two = threads >= 2 && rayon::current_num_threads() >= 2;
    let failed = if x.len() >= PIPELINE_SAMPLES && two {
        pipelined(cascade, x, h, free, sink)
    } else {
        let mut block = Block::new(free.len(), SEQUENTIAL_ROWS);
        recursion_into_blocks(cascade, x, h, free, &mut block, &mut |b| sink(&b.view()))
    };
    match failed {
        None => Ok(()),
        Some(index) => Err(Error::Diverged {
            index,
            reason: "the simulated cascade output is not finite".into(),
        }),
    }
}

/// Rows `[ŷ, ∂ŷ/∂θ_free]` of consecutive samples, one after the other: the storage behind
/// a [`SensitivityBlock`].
struct Block {
    start: usize,
    len: usize,
    capacity: usize,
    width: usize,
    rows: Vec<f64>,
}

impl Block {
    /// An empty block of `capacity` rows of `width` sensitivities.
    fn new(width: usize, capacity: usize) -> Self {
        Self {
            start: 0,
            len: 0,
            capacity,
            width: 1 + width,
            rows: vec![0.0; capacity * (1 + width)],
        }
    }

    /// Appends the row of sample `t`; true when the block is then full.
    #[inline]
    fn push(&mut self, t: usize, yhat: f64, row: &[f64]) -> bool {
        if self.len == 0 {
            self.start = t;
        }
        let at = self.len * self.width;
        self.rows[at] = yhat;
        self.rows[at + 1..at + self.width].copy_from_slice(row);
        self.len += 1;
        self.len == self.capacity
    }

    /// Calls `on_row(t, ŷ(t), ∂ŷ(t)/∂θ_free)` for every row held.
    fn each_row(&self, on_row: &mut impl FnMut(usize, f64, &[f64])) {
        let rows = self.rows[..self.len * self.width].chunks_exact(self.width);
        for (i, row) in rows.enumerate() {
            on_row(self.start + i, row[0], &row[1..]);
        }
    }

    fn view(&self) -> SensitivityBlock<'_> {
        SensitivityBlock {
            start: self.start,
            rows: &self.rows[..self.len * self.width],
            width: self.width,
        }
    }
}

/// The recursion on a second thread, its rows handed over in blocks; the sink runs on the
/// calling thread. Three blocks circulate, so neither side allocates.
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub fn pipelined(
    cascade: &HysteresisCascade,
    x: &[f64],
    h: Option<&[bool]>,
    free: &[usize],
    sink: &mut BlockSink<'_>,
) -> Option<usize> {
    let width = free.len();
    let (full_tx, full_rx) = sync_channel::<Block>(2);
    let (empty_tx, empty_rx) = sync_channel::<Block>(3);
    std::thread::scope(|scope| {
        let producer = scope.spawn(move || {
            let fresh = || Block::new(width, BLOCK_ROWS);
            let mut block = empty_rx.recv().unwrap_or_else(|_| fresh());
            recursion_into_blocks(cascade, x, h, free, &mut block, &mut |full| {
                let next = empty_rx.recv().unwrap_or_else(|_| fresh());
                // A send fails only when the consumer is gone; the rows are then unwanted.
                let _ = full_tx.send(std::mem::replace(full, next));
            })
        });
        consume(full_rx, empty_tx, width, sink);
        match producer.join() {
            Ok(failed) => failed,
            Err(panic) => std::panic::resume_unwind(panic),
        }
    })
}

/// The sink's side of [`pipelined`]. It owns its ends of both channels, so leaving (by a
/// panic of the sink too) drops them and releases a recursion blocked on either.
fn consume(
    full: Receiver<Block>,
    empty: SyncSender<Block>,
    width: usize,
    sink: &mut BlockSink<'_>,
) {
    for _ in 0..3 {
        // Cannot block: the channel has room for all three.
        let _ = empty.send(Block::new(width, BLOCK_ROWS));
    }
    for mut block in full {
        sink(&block.view());
        block.len = 0;
        let _ = empty.send(block);
    }
}

/// The sensitivity recursion of the module docs, calling `on_row(t, ŷ(t), ∂ŷ(t)/∂θ_free)`
/// for every sample; returns the first sample whose output is not finite.
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub fn recursion(
    cascade: &HysteresisCascade,
    x: &[f64],
    h: Option<&[bool]>,
    free: &[usize],
    mut on_row: impl FnMut(usize, f64, &[f64]),
) -> Option<usize> {
    let mut block = Block::new(free.len(), SEQUENTIAL_ROWS);
    recursion_into_blocks(cascade, x, h, free, &mut block, &mut |b| {
        b.each_row(&mut on_row)
    })
}

/// The sensitivity recursion written into `block`, every full block (and the last one)
/// handed to `on_block`, which may replace it by an empty one; returns the first sample
/// whose output is not finite.
fn recursion_into_blocks(
    cascade: &HysteresisCascade,
    x: &[f64],
    h: Option<&[bool]>,
    free: &[usize],
    block: &mut Block,
    on_block: &mut dyn FnMut(&mut Block),
) -> Option<usize> {
    if let Some(failed) = fixed::recursion_blocks(cascade, x, h, free, block, on_block) {
        return failed;
    }
    let failed = recursion_generic(cascade, x, h, free, |t, yhat, row| {
        if block.push(t, yhat, row) {
            on_block(block);
            block.len = 0;
        }
    });
    if block.len > 0 {
        on_block(block);
    }
    failed
}

/// [`recursion`] for any shape (widths known only at run time).
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub fn recursion_generic(
    cascade: &HysteresisCascade,
    x: &[f64],
    h: Option<&[bool]>,
    free: &[usize],
    mut on_row: impl FnMut(usize, f64, &[f64]),
) -> Option<usize> {
    let lin = &cascade.linear;
    let (k, m) = (lin.delay(), lin.nb());
    let nh = cascade.hysteresis.form().n_params();
    let p = nh + m - 1 + lin.na();
    // v(t) and s(t) = ∂v/∂θ_h are needed at lags k … k+m−1; ŷ and ∂ŷ at lags 1 … n.
    let mut hyst = Ring::new(k + m, 1 + nh);
    let mut out = Ring::new(lin.na() + 1, 1 + p);
    let mut u = vec![0.0; p];
    let mut row = vec![0.0; free.len()];
    let mut failed = None;
    hysteresis_sensitivities(&cascade.hysteresis, x, 0.0, h, |t, v, s| {
        let slot = hyst.row_mut(t);
        slot[0] = v;
        slot[1..].copy_from_slice(s);
        // ŷ(t) as the simulation computes it (A's terms, then B's): the same bits.
        let mut yhat = 0.0;
        for (i, &ai) in lin.a().iter().enumerate() {
            if let Some(past) = out.get(t, i + 1) {
                yhat -= ai * past[0];
            }
        }
        for (j, &bj) in lin.b().iter().enumerate() {
            if let Some(past) = hyst.get(t, k + j) {
                yhat += bj * past[0];
            }
        }
        u.iter_mut().for_each(|ui| *ui = 0.0);
        for (j, &bj) in lin.b().iter().enumerate() {
            if let Some(past) = hyst.get(t, k + j) {
                for (ui, si) in u[..nh].iter_mut().zip(&past[1..]) {
                    *ui += bj * si;
                }
                if j > 0 {
                    u[nh + j - 1] = past[0];
                }
            }
        }
        // u becomes ∂ŷ(t) in place: ∂ŷ(t) = u(t) − Σ aᵢ ∂ŷ(t−i).
        let dy = &mut u;
        for (i, &ai) in lin.a().iter().enumerate() {
            if let Some(past) = out.get(t, i + 1) {
                dy[nh + m - 1 + i] -= past[0];
                for (d, pd) in dy.iter_mut().zip(&past[1..]) {
                    *d -= ai * pd;
                }
            }
        }
        if !yhat.is_finite() && failed.is_none() {
            failed = Some(t);
        }
        let slot = out.row_mut(t);
        slot[0] = yhat;
        slot[1..].copy_from_slice(dy);
        for (r, &i) in row.iter_mut().zip(free) {
            *r = dy[i];
        }
        on_row(t, yhat, &row);
    });
    failed
}
