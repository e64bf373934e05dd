//! Tests of `hysid::identify::output_error`.

mod gram;
