//! Tests of `hysid::model`.

mod coleman_hodgdon;
mod compensate;
mod greybox;
mod kinds;
mod linear;
mod operator_cascade;
mod operators;
mod record_filters;
mod saved;
