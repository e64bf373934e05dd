//! Tests of `hysid::experiments`.

mod actuator_rig;
