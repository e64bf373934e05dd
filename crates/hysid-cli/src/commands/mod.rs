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
