//! Identification recipes.

pub mod operators;
