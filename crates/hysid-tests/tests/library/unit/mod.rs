//! The unit tests of the library's modules, one file per module (its path under `src/`).
//! They are here, not in `#[cfg(test)]` modules, so that `cargo test` compiles the library
//! once: a unit test inside the library makes cargo build the whole library a second time
//! with cfg(test) (before this move, 42 % of the test command's build). The few internals
//! they reach are `#[doc(hidden)] pub`, marked "reached by the white-box tests".

mod data;
mod experiments;
mod export;
mod generic_path;
mod identify;
mod model;
mod numerics;
mod report;
mod test_signals;
mod toolchain;
