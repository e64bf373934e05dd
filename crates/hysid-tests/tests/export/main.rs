//! The generated code against the library: every operator family of the registry and every
//! exportable model kind, forward and inverse, compiled as C99 (`cc -std=c99 -Wall -Wextra
//! -Werror -pedantic -O2`) and as `no_std` Rust crates, run on a seeded signal with minor
//! loops, equal to `FittedModel::simulate` (and to the batch `compensate`) to 1e-12 of the
//! signal's range. Also the API's refusals and the determinism of the files.

mod api;
mod c_target;
mod cases;
mod greybox;
mod hostile;
mod newmark_lu;
mod rust_target;
mod single;
mod vectors;
