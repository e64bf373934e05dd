//! Initial states of an equation-file model: its `[initial]` table on the existing
//! initial-state machinery ([`InitialStates`]).

use super::structure::InitialStates;
use crate::model::greybox::equation_model::EquationStateSpace;

impl InitialStates {
    /// x(t₀) of every one of `n_experiments` experiments as the file's `[initial]` declares
    /// it (0 for a state not listed); a state is estimated (separately per experiment, as
    /// MATLAB's `InitialStates(i).Fixed = false`) when the file says `fixed = false` or
    /// `also_estimated` (per state, e.g. from `--estimate-x0`; may be empty) says so.
    pub fn of_equations(
        model: &EquationStateSpace,
        n_experiments: usize,
        also_estimated: &[bool],
    ) -> Self {
        let estimated = model
            .initial_estimated()
            .iter()
            .enumerate()
            .map(|(i, &e)| e || also_estimated.get(i).copied().unwrap_or(false))
            .collect();
        Self {
            values: vec![model.initial_values(); n_experiments],
            estimated,
        }
    }
}
