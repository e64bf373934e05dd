//! Tests of `hysid::identify::greybox`.

mod structure;
