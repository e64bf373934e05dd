//! The `hysid` command line end to end, in one test binary (one link and one copy of the
//! shared code for all of them) with a module per area.

mod common;

mod actuator_cli;
mod commands;
#[cfg(unix)] // SIGKILL
mod crash_safety;
mod envelope_cli;
mod equations_cli;
mod exit_codes;
mod export_cli;
mod hardening;
mod hold_check_cli;
#[cfg(unix)] // symbolic links
mod initial_state_cli;
mod inputs_sacred;
mod limits_cli;
#[cfg(target_os = "linux")] // the C route of equation files
mod native_cache;
mod nist_cli;
mod operator_cascade_cli;
mod orientation_cli;
mod outputs;
mod report_schema;
mod tutorial_cli;
mod work_budget;
mod zoo_cli;
