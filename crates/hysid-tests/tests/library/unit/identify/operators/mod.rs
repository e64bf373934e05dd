//! Tests of `hysid::identify::operators`.

mod backlash;
mod bouc_wen;
mod compare;
mod dahl;
mod differential_fit;
mod duhem;
mod family;
mod gpi;
mod initial_state;
mod jiles_atherton;
mod kp;
mod maxwell_slip;
mod model_size;
mod pi;
mod preisach;
