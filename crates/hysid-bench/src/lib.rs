//! Criterion benchmarks of `hysid` and `hysid-equations`, one file per subject in `benches/`
//! (`cargo bench -p hysid-bench --bench greybox`, …; `docs/performance.md` lists them with
//! their figures).
//!
//! They live in a crate of their own so that `cargo test` of the library crates does not
//! compile criterion and its dependencies; this library is empty.
