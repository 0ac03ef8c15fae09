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
//! Facets: the links formulation handles first- and second-order facets
//! (tri3, quad4, tri6, quad8, quad9; one type per surface, slave and master
//! types may differ); the mortar formulation first-order ones only (its
//! dual basis on quadratic facets is not built), and the scene refuses a
//! mortar pair on second-order facets (`scene/contact.rs`). Arrays here are
//! sized by [`MAX_FACET_NODES`] (quad9) where a facet of any order may
//! arrive, and the links kernel is instantiated for a capacity of
//! [`LINEAR_FACET_NODES`] when both of a link's facets are first-order, so
//! first-order links carry no second-order slack. [`facet_shape`] and
//! [`facet_second`] evaluate a facet's shape functions and their second
//! derivatives (`fem::shape` is their one home).
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

pub use formulation::{Census, SlipRate, Traits};
pub use outcome::{PairForce, UzawaStats};
pub use pair::ContactPair;

/// Most nodes of a contact facet (quad9).
pub const MAX_FACET_NODES: usize = crate::fem::MAX_FACET_NODES;

/// Most nodes of a first-order contact facet (quad4).
pub const LINEAR_FACET_NODES: usize = 4;

/// Shape values and first derivatives of a contact facet at one point, for
/// facets of up to `M` nodes.
pub type FacetShape<const M: usize = MAX_FACET_NODES> = crate::fem::shape::FacetShape<M>;

/// The shape functions of `facet` at `xi` in a holder of `M` nodes; a facet
/// with more than `M` nodes (which the callers' dispatch rules out) gets an
/// empty holder (`nodes = 0`, all zeros) rather than a panic.
pub fn facet_shape<const M: usize>(facet: crate::fem::FacetType, xi: [f64; 2]) -> FacetShape<M> {
    FacetShape::of(facet, xi).unwrap_or(FacetShape {
        nodes: 0,
        n: [0.0; M],
        dn: [[0.0; 2]; M],
    })
}

/// Second derivatives `[N_,11, N_,12, N_,22]` of `facet`'s shape functions
/// at `xi`, in a holder of `M` nodes (zeros past the facet's nodes, or
/// everywhere when it has more than `M`).
pub fn facet_second<const M: usize>(facet: crate::fem::FacetType, xi: [f64; 2]) -> [[f64; 3]; M] {
    FacetShape::<M>::second(facet, xi).unwrap_or([[0.0; 3]; M])
}

/// Third derivatives `[N_,112, N_,122]` of `facet`'s shape functions at
/// `xi` (`N_,111` and `N_,222` vanish on every facet type: each is at most
/// quadratic in either coordinate alone), in a holder of `M` nodes.
pub fn facet_third<const M: usize>(facet: crate::fem::FacetType, xi: [f64; 2]) -> [[f64; 2]; M] {
    FacetShape::<M>::third(facet, xi).unwrap_or([[0.0; 2]; M])
}
