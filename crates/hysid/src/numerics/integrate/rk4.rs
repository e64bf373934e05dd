//! The classical fourth-order Runge–Kutta step (Kutta 1901):
//!
//! ```text
//! k₁ = f(t, x)
//! k₂ = f(t + h/2, x + h/2·k₁)
//! k₃ = f(t + h/2, x + h/2·k₂)
//! k₄ = f(t + h,   x + h·k₃)
//! x ← x + h/6·(k₁ + 2k₂ + 2k₃ + k₄)
//! ```
//!
//! The right-hand side is any closure over a flat state, so forward sensitivities
//! S = ∂x/∂θ are propagated by the *same* stages when the state is the augmented
//! z = [x, S] and the closure returns [f, f_x·S + f_θ]: the result is the exact derivative of
//! the discrete RK4 map (the "discretise-then-differentiate" sensitivities, Hairer, Nørsett &
//! Wanner, *Solving Ordinary Differential Equations I*, 2nd ed., §II.1 and §I.14).
//!
//! Stages are evaluated at three nodes of the step, its start, middle and end. A caller that
//! tabulates the input at the half-step grid once per data set reads it by
//! [`Stage::node`] instead of interpolating at every stage; a step that does not lie on that
//! grid (a step cut at an event) reports no node and the caller interpolates at
//! [`Stage::dt`].
//!
//! Reference: W. Kutta, "Beitrag zur näherungsweisen Integration totaler
//! Differentialgleichungen", Z. Math. Phys. 46, 1901.

/// Where a stage evaluates the right-hand side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stage {
    /// Seconds after the reference time of the step (its start, plus the offset the caller
    /// passed to [`Rk4::step`]).
    pub dt: f64,
    /// On a grid step, the half-step node: 0 the start, 1 the middle, 2 the end; None when the
    /// step does not lie on the caller's half-step grid.
    pub node: Option<u8>,
}

/// The working buffers of RK4 steps on a state of fixed dimension (allocated once, reused by
/// every step).
#[derive(Clone, Debug)]
pub struct Rk4 {
    k: [Vec<f64>; 4],
    stage: Vec<f64>,
}

impl Rk4 {
    /// Buffers for states of dimension `dim`.
    pub fn new(dim: usize) -> Self {
        Self {
            k: std::array::from_fn(|_| vec![0.0; dim]),
            stage: vec![0.0; dim],
        }
    }

    /// The state dimension the buffers hold.
    pub fn dim(&self) -> usize {
        self.stage.len()
    }

    /// One classical RK4 step of length `h` in place (see the module docs). The stages are
    /// evaluated at `t0`, `t0 + h/2` and `t0 + h` seconds after the caller's reference time,
    /// reported in [`Stage::dt`]; `on_grid` says whether the step is one of the caller's grid
    /// steps (then [`Stage::node`] is 0, 1, 2). A state whose length differs from
    /// [`dim`](Self::dim) is integrated over the common length only.
    pub fn step<F>(&mut self, rate: &mut F, x: &mut [f64], t0: f64, h: f64, on_grid: bool)
    where
        F: FnMut(Stage, &[f64], &mut [f64]),
    {
        let node = |i: u8| on_grid.then_some(i);
        let [k1, k2, k3, k4] = &mut self.k;
        let stage = &mut self.stage;
        let half = 0.5 * h;
        rate(
            Stage {
                dt: t0,
                node: node(0),
            },
            x,
            k1,
        );
        for ((s, xi), k) in stage.iter_mut().zip(x.iter()).zip(k1.iter()) {
            *s = xi + half * k;
        }
        let middle = Stage {
            dt: t0 + half,
            node: node(1),
        };
        rate(middle, stage, k2);
        for ((s, xi), k) in stage.iter_mut().zip(x.iter()).zip(k2.iter()) {
            *s = xi + half * k;
        }
        rate(middle, stage, k3);
        for ((s, xi), k) in stage.iter_mut().zip(x.iter()).zip(k3.iter()) {
            *s = xi + h * k;
        }
        let end = Stage {
            dt: t0 + h,
            node: node(2),
        };
        rate(end, stage, k4);
        let sixth = h / 6.0;
        for ((((xi, a), b), c), d) in x
            .iter_mut()
            .zip(k1.iter())
            .zip(k2.iter())
            .zip(k3.iter())
            .zip(k4.iter())
        {
            *xi += increment(sixth, *a, *b, *c, *d);
        }
    }
}

/// The classical RK4 increment (h/6)·(k₁ + 2k₂ + 2k₃ + k₄) of one element, given h/6:
/// the one place its weights are written, shared by [`Rk4::step`] and the fixed-size
/// sensitivity path of the grey-box models (which must agree with it to the last bit).
#[inline(always)]
pub fn increment(sixth: f64, k1: f64, k2: f64, k3: f64, k4: f64) -> f64 {
    sixth * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
}
