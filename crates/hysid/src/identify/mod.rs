pub mod operators;
