//! The linear block A(q⁻¹)y = q⁻ᵏB(q⁻¹)v one sample at a time, and its inverse.
//!
//! The forward step is [`LinearBlock::output_at`] on a fixed window of the past: y_t =
//! −a₁y_{t−1} − … − a_ny_{t−n} + b₁v_{t−k} + … + b_mv_{t−k−m+1}, the terms in that order and
//! those before the first sample left out (as the batch leaves them out), so the two give the
//! same bits. The inverse is that of [`OperatorCascade::compensate`](crate::model::OperatorCascade::compensate):
//! with ρ_s = r_{s+k} the reference k samples ahead (0 before the delay),
//! v_s = ρ_s + a₁ρ_{s−1} + … + a_nρ_{s−n} − b₂v_{s−1} − … − b_mv_{s−m+1}, stable when B is
//! minimum phase.

use crate::model::LinearBlock;

/// The window of the past a linear block's step reads, newest first.
#[derive(Clone, Debug, PartialEq)]
struct Window {
    values: Vec<f64>,
}

impl Window {
    fn new(len: usize) -> Self {
        Self {
            values: vec![0.0; len],
        }
    }

    /// Shifts the window by one sample and puts `v` in front.
    fn push(&mut self, v: f64) {
        if !self.values.is_empty() {
            self.values.rotate_right(1);
            self.values[0] = v;
        }
    }

    /// The value `lag` samples back (0: the newest).
    fn get(&self, lag: usize) -> f64 {
        self.values[lag]
    }

    fn clear(&mut self) {
        self.values.iter_mut().for_each(|v| *v = 0.0);
    }
}

/// The linear block streamed: y_t for v_t.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct LinearStream {
    block: LinearBlock,
    /// v_t, v_{t−1}, … (k + m values).
    v: Window,
    /// y_{t−1}, y_{t−2}, … (n values).
    y: Window,
    /// Samples seen (t), saturating: which terms exist yet.
    t: usize,
}

impl LinearStream {
    pub(super) fn new(block: LinearBlock) -> Self {
        Self {
            v: Window::new(block.delay() + block.nb()),
            y: Window::new(block.na()),
            t: 0,
            block,
        }
    }

    pub(super) fn reset(&mut self) {
        self.v.clear();
        self.y.clear();
        self.t = 0;
    }

    /// y_t for v_t = `v`.
    pub(super) fn step(&mut self, v: f64) -> f64 {
        self.v.push(v);
        let t = self.t;
        let mut acc = 0.0;
        for (i, &ai) in self.block.a().iter().enumerate() {
            if i < t {
                acc -= ai * self.y.get(i);
            }
        }
        for (j, &bj) in self.block.b().iter().enumerate() {
            let lag = self.block.delay() + j;
            if lag <= t {
                acc += bj * self.v.get(lag);
            }
        }
        self.y.push(acc);
        self.t = self.t.saturating_add(1);
        acc
    }
}

/// The linear block's inverse streamed: v_s for ρ_s = r_{s+k}.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct LinearInverse {
    block: LinearBlock,
    /// ρ_{s−1}, ρ_{s−2}, … (n values; 0 before the delay, as the batch's).
    rho: Window,
    /// v_{s−1}, v_{s−2}, … (m − 1 values).
    v: Window,
    /// Samples given (s), saturating.
    s: usize,
}

impl LinearInverse {
    pub(super) fn new(block: LinearBlock) -> Self {
        Self {
            rho: Window::new(block.na()),
            v: Window::new(block.nb().saturating_sub(1)),
            s: 0,
            block,
        }
    }

    pub(super) fn reset(&mut self) {
        self.rho.clear();
        self.v.clear();
        self.s = 0;
    }

    /// v_s for the reference ρ_s = r_{s+k} (see the module doc).
    pub(super) fn step(&mut self, rho: f64) -> f64 {
        let mut acc = rho;
        for (i, &a) in self.block.a().iter().enumerate() {
            acc += a * self.rho.get(i);
        }
        for (j, &b) in self.block.b().iter().enumerate().skip(1) {
            if j <= self.s {
                acc -= b * self.v.get(j - 1);
            }
        }
        self.rho.push(rho);
        self.v.push(acc);
        self.s = self.s.saturating_add(1);
        acc
    }
}
