//! Tests of `hysid::model::operators`.

mod backlash;
mod bouc_wen;
mod dahl;
mod differential;
mod duhem;
mod elementary;
mod envelope;
mod gpi;
mod initial_state;
mod jiles_atherton;
mod kp;
mod maxwell_slip;
mod orientation;
mod pi;
mod preisach;
mod registry;
