//! Newton on the condensed contact system, as the residual sees it: on
//! either path the SNES vector then holds the true x on the contact DOFs C
//! and one scalar for the rest, and the iterates are those Newton on the
//! whole vector would take. The one-rank Schur path's state is
//! `schur::newton`'s, the several-rank low-rank path's `low_rank::newton`'s
//! (their step's life is `armed`); the residual asks both the same
//! questions.
use super::low_rank::Reduced;
use super::schur::Condensation;
use crate::petsc::{Result, Vector};
use std::cell::RefCell;
use std::rc::Rc;

/// The condensed Newton state the residual reads: the one-rank Schur
/// path's or the several-rank low-rank path's.
#[derive(Clone)]
pub enum Condensed {
    One(Rc<RefCell<Condensation>>),
    Several(Rc<RefCell<Reduced>>),
}

impl Condensed {
    /// The SNES vector is the condensed one.
    pub fn is_active(&self) -> bool {
        match self {
            Condensed::One(c) => c.borrow().is_active(),
            Condensed::Several(c) => c.borrow().is_active(),
        }
    }

    /// Before the first condensed residual: a copy of the state whose
    /// contact residual the condensed form needs.
    pub fn base_wanted(&self) -> Option<Result<Vector>> {
        let copy = |x0: &Vector| -> Result<Vector> {
            let mut c = x0.duplicate()?;
            c.copy_from(x0)?;
            Ok(c)
        };
        match self {
            Condensed::One(c) => c.borrow().base_wanted().map(copy),
            Condensed::Several(c) => c.borrow().base_wanted().map(copy),
        }
    }

    /// Gives the condensed form the contact residual `rc0` at the step's
    /// start. Collective.
    pub fn set_base_contact(&self, rc0: &Vector) -> Result<()> {
        match self {
            Condensed::One(c) => c.borrow_mut().set_base_contact(rc0),
            Condensed::Several(c) => c.borrow_mut().set_base_contact(rc0),
        }
    }

    /// The residual at the condensed vector `x` from the contact residual
    /// `rc` there. Collective.
    pub fn residual(&self, x: &Vector, rc: &Vector, out: &mut Vector) -> Result<()> {
        match self {
            Condensed::One(c) => c.borrow().residual(x, rc, out),
            Condensed::Several(c) => c.borrow_mut().residual(x, rc, out),
        }
    }
}
