//! TODO
use super::Emit;
use crate::export::program::{Ns, Program};
use crate::model::operators::Dahl;
use crate::{Error, Result};

impl Emit for Dahl {
    fn emit_forward(&self, _ns: &Ns, _prog: &mut Program) -> Result<String> {
        Err(Error::Unsupported("not yet".into()))
    }
    fn emit_inverse(&self, _ns: &Ns, _prog: &mut Program) -> Result<String> {
        Err(Error::Unsupported("not yet".into()))
    }
}
