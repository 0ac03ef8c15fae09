//! Contact: the ContactLink3D condition and its mortar counterpart
//! (docs/formulation.md §2–§5, §9, §13).
//!
//! The solver holds a [`ContactPair`] per pair and asks it the duties of
//! [`formulation::Formulation`]; each formulation is one module:
//! - `links`: one link per slave quadrature point (its kernel, multipliers
//!   per point, slip history);
//! - `mortar`: dual multipliers at the slave nodes, segment-based
//!   integration of the slave–master overlap.
//!
//! What they share:
//! - `pair`: [`ContactPair`], a pair at run time (its specification,
//!   reported penalty, slip rate, and its formulation);
//! - `penalty`: the normal law pN = ⟨λN − εN gN⟩, the default penalty and
//!   the policy that raises or softens it within a step;
//! - `fields`: the fields a pair writes to and reads back from a result
//!   file, and their names;
//! - `outcome`: what an evaluation reports (Uzawa statistics, force);
//! - `surfaces`: the slave side as one rank sees it; `master`: the master
//!   side (held facets of a deformable body, or a rigid surface);
//!   `held_master`: the facets a rank holds and the exchange that decides
//!   them;
//! - `search`, `projection`: spatial index and closest-point projection;
//! - `autodiff`: dual numbers for the exact tangents.
//!
//! Nothing here calls the solver or PETSc: `solve` drives the Uzawa loop
//! around SNES.
//!
//! Contact handles first-order facets (tri3, quad4) only: the scene refuses
//! a pair whose facet sets hold second-order facets or mix facet types
//! (`scene/contact.rs`), and the arrays and dual numbers here are sized by
//! [`MAX_FACET_NODES`], not by `fem`'s, so they do not grow with the element
//! library. [`facet_shape`] evaluates a facet's first-order shape
//! functions.
pub mod autodiff;
pub mod fields;
pub mod formulation;
pub mod held_master;
pub mod links;
pub mod master;
pub mod mortar;
pub mod outcome;
pub mod pair;
pub mod penalty;
pub mod projection;
pub mod search;
pub mod surfaces;

pub use crate::fem::shape::linear_facet_shape as facet_shape;
pub use formulation::{Census, SlipRate, Traits};
pub use outcome::{PairForce, UzawaStats};
pub use pair::ContactPair;

/// Most nodes of a contact facet (quad4).
pub const MAX_FACET_NODES: usize = 4;

/// The first-order shape functions of a contact facet at one point.
pub type FacetShape = crate::fem::shape::FacetShape<MAX_FACET_NODES>;
