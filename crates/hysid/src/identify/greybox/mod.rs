//! Output-error estimation of continuous-time grey-box models (MATLAB's `nlgreyest`).
//!
//! * [`structure`]: a model ([`crate::model::greybox::StateSpaceModel`]), its simulation
//!   settings and its initial states per experiment, bound to data as an
//!   [`OutputErrorModel`](crate::identify::OutputErrorModel).
//! * [`estimate`]: output-error estimation with multi-start.
//! * [`hold_check`](mod@hold_check): whether the default zero-order hold of the input misleads the fit.

pub mod equations;
pub mod estimate;
pub mod hold_check;
pub mod structure;

pub use estimate::{GreyBoxEstimation, GreyBoxFit};
pub use hold_check::{hold_check, HoldCheck};
pub use structure::{GreyBox, InitialStates};
