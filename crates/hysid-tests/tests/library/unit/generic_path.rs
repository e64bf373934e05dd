//! A model seen without its fixed-size path: the reference the fixed-size kernels are
//! tested against, to the bit.

use hysid::model::greybox::{JacobianScratch, StateSpaceModel};

/// A model seen without its fixed-size path, so that the generic path runs: the reference the
/// fixed-size kernels are tested against, to the bit.
pub struct GenericPath<'a>(pub &'a dyn StateSpaceModel);

impl StateSpaceModel for GenericPath<'_> {
    fn kind(&self) -> &'static str {
        self.0.kind()
    }
    fn states(&self) -> Vec<hysid::data::Channel> {
        self.0.states()
    }
    fn inputs(&self) -> Vec<hysid::data::Channel> {
        self.0.inputs()
    }
    fn outputs(&self) -> Vec<hysid::data::Channel> {
        self.0.outputs()
    }
    fn parameters(&self) -> hysid::model::ParameterSet {
        self.0.parameters()
    }
    fn rhs(&self, t: f64, x: &[f64], u: &[f64], theta: &[f64], dx: &mut [f64]) {
        self.0.rhs(t, x, u, theta, dx)
    }
    fn output(&self, x: &[f64], u: &[f64], theta: &[f64], y: &mut [f64]) {
        self.0.output(x, u, theta, y)
    }
    fn rhs_jacobians(
        &self,
        t: f64,
        x: &[f64],
        u: &[f64],
        theta: &[f64],
        fx: &mut [f64],
        ftheta: &mut [f64],
    ) -> bool {
        self.0.rhs_jacobians(t, x, u, theta, fx, ftheta)
    }
    fn output_jacobians(
        &self,
        x: &[f64],
        u: &[f64],
        theta: &[f64],
        hx: &mut [f64],
        htheta: &mut [f64],
    ) -> bool {
        self.0.output_jacobians(x, u, theta, hx, htheta)
    }
    fn discrete_time(&self) -> bool {
        self.0.discrete_time()
    }
    fn mechanical_dofs(&self) -> Option<usize> {
        self.0.mechanical_dofs()
    }
    fn stick_slip_velocity(&self) -> Option<usize> {
        self.0.stick_slip_velocity()
    }
    fn rhs_sliding(
        &self,
        t: f64,
        x: &[f64],
        u: &[f64],
        theta: &[f64],
        direction: f64,
        dx: &mut [f64],
    ) {
        self.0.rhs_sliding(t, x, u, theta, direction, dx)
    }
    #[allow(clippy::too_many_arguments)]
    fn rhs_jacobians_sliding(
        &self,
        t: f64,
        x: &[f64],
        u: &[f64],
        theta: &[f64],
        direction: f64,
        fx: &mut [f64],
        ftheta: &mut [f64],
    ) -> bool {
        self.0
            .rhs_jacobians_sliding(t, x, u, theta, direction, fx, ftheta)
    }
    fn rhs_sensitivities(
        &self,
        t: f64,
        x: &[f64],
        u: &[f64],
        theta: &[f64],
        held: Option<f64>,
        params: &[usize],
        s: &[f64],
        scratch: &mut JacobianScratch,
        dx: &mut [f64],
        ds: &mut [f64],
    ) -> bool {
        self.0
            .rhs_sensitivities(t, x, u, theta, held, params, s, scratch, dx, ds)
    }
}
