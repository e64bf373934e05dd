//! Tests of `hysid::numerics::integrate`.

mod rk4;
