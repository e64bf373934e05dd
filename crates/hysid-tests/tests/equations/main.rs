//! The equation language's tests, in one test binary (one link for all of them) with a
//! module per area. Run one area with a filter, e.g.
//! `cargo test --release -p hysid-equations --test equations fuzz::`.

mod bound;
mod common;
mod errors;
mod examples;
mod functions;
mod fuzz;
mod no_alloc;
