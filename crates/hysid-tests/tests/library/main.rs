//! The library's integration tests, in one test binary (one link and one copy of the shared
//! code for all of them) with a module per area. Run one area with a filter, e.g.
//! `cargo test --release -p hysid --test library fuzz_readers::`.

mod actuator;
mod atomic_outputs;
mod cascade_examples;
mod cascade_statistics;
mod docs_paths;
mod emps;
mod equations;
mod fuzz_readers;
mod greybox;
mod hysteresis_alone;
mod model_files;
mod nist;
mod preprocessing;
mod properties;
mod report_covariance;
mod stream;
mod unit;
