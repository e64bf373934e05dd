//! Nothing to link: this package holds the hysid library's tests (`tests/library`), built as
//! one integration-test binary without optimisation while the library stays optimised. See
//! its `Cargo.toml`.
