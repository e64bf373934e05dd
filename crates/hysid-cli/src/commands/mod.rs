//! One module per subcommand.

mod cascade;
mod demo;
mod generate;
mod identify;
mod simulate;

use crate::cli::{Cli, Command, Demo, Generate, Identify};
use anyhow::Result;

/// Runs the parsed command line.
pub fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Demo(Demo::Voros(args)) => demo::voros(&args),
        Command::Identify(Identify::Cascade(args)) => identify::cascade(&args),
        Command::Identify(Identify::Hysteresis(args)) => identify::hysteresis(&args),
        Command::Simulate(args) => simulate::run(&args),
        Command::Generate(Generate::Voros(args)) => generate::voros(&args),
    }
}
