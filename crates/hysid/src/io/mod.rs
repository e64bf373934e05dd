//! Writing results safely: all-or-nothing output sets and checks of what is written.

pub mod atomic;
