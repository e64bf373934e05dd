//! Maxwell-slip friction (`model::operators::maxwell_slip`): rate-independently the PI
//! operator a₀ = k₀ + Σkᵢ, aᵢ = −kᵢ, rᵢ = δᵢ (the library simulates and inverts it as that PI),
//! so its code is the PI's ([`super::pi`]): the analytic inverse when k₀ > 0, the per-sample
//! solve with clipping at c ± ΣWᵢ otherwise.

use super::oriented::EmitCore;
use super::pi;
use crate::export::program::{Ns, Program};
use crate::model::operators::{MaxwellSlip, Orientation};
use crate::Result;

impl EmitCore for MaxwellSlip {
    fn orientation(&self) -> Orientation {
        MaxwellSlip::orientation(self)
    }
    fn emit_core(&self, ns: &Ns, prog: &mut Program) -> Result<String> {
        pi::emit_forward(self.as_pi(), ns, prog)
    }
    fn emit_core_inverse(&self, ns: &Ns, prog: &mut Program) -> Result<(String, Option<String>)> {
        pi::emit_inverse(self.as_pi(), ns, prog)
    }
}
