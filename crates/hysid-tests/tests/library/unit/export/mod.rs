//! The export's modules.

mod fmu;
mod zip;
