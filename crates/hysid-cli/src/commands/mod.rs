//! One module per subcommand.

mod actuator;
mod benchmark;
mod cascade;
mod compare;
mod compensate;
mod demo;
mod export;
mod generate;
mod greybox;
mod identify;
mod operator;
mod operator_cascade;
mod present;
mod rigid_body;
mod simulate;
mod zoo;

use crate::cli::{Actuator, Benchmark, Cli, Command, Demo, Generate, Greybox, Identify, RigidBody};
use anyhow::Result;

/// Runs the parsed command line.
pub fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Demo(Demo::Voros(args)) => demo::voros(&args),
        Command::Identify(Identify::Cascade(args)) => identify::cascade(&args),
        Command::Identify(Identify::Hysteresis(args)) => identify::hysteresis(&args),
        Command::Simulate(args) => simulate::run(&args),
        Command::Generate(Generate::Voros(args)) => generate::voros(&args),
        Command::Greybox(Greybox::Fit(args)) => greybox::fit(&args),
        Command::Benchmark(Benchmark::BoucWen(args)) => benchmark::bouc_wen(&args),
        Command::Demo(Demo::Actuator(args)) => actuator::demo(&args),
        Command::Actuator(Actuator::Rig(args)) => actuator::rig(&args),
        Command::Actuator(Actuator::Identify(args)) => actuator::identify(&args),
        Command::RigidBody(RigidBody::Ls(args)) => rigid_body::ls(&args),
        Command::Identify(Identify::Operator(args)) => operator::run(&args),
        Command::Compare(args) => compare::run(&args),
        Command::Compensate(args) => compensate::run(&args),
        Command::Export(args) => export::run(&args),
    }
}

/// The warning of `compensate` and `export --inverse` for a model (read from `path`) whose
/// compensator does not run its declared history (`FittedModel::history_beyond_the_inverse`).
fn warn_history_beyond_the_inverse(
    model: &hysid::model::saved::FittedModel,
    path: &std::path::Path,
) {
    if let Some(state) = model.history_beyond_the_inverse() {
        tell!(
            "warning: {} starts after a declared {} history without its turn (history_turn, a file of an earlier version), which the compensator does not run: its first commands follow the operator's own initial state until the reference's excursions have made the history irrelevant; fit the model again to save the turn",
            path.display(),
            state.name()
        );
    }
}
