//! The mortar formulation: multipliers at the slave nodes with dual
//! (biorthogonal) shape functions, integrated segment by segment over the
//! slave–master overlaps (docs/formulation.md §13).
//!
//! The pair at run time:
//! - `pair`: [`MortarPair`], the search, and everything per node (the
//!   Uzawa update, census, multipliers, commit); `formulation`: its duties
//!   as a `contact::formulation::Formulation`; `setup` builds it on a
//!   rank; `share` decides what the rank holds (its slave facets and those
//!   around their nodes, the master facets near them) and numbers the
//!   nodes it does not see (the tail, `holding`);
//! - `master`: the master side (`Master`: master facets or a rigid
//!   surface), each variant's run-time duties in its own module:
//!   `facet_side` (candidate facet pairs, the segment evaluation, residual
//!   and tangent), `rigid_side` (candidate slave facets, the integrals
//!   over them);
//! - `output`: the pair's point and nodal fields and force; `restart`:
//!   taking a step over from a result file;
//! - `tangential`: a frictional pair's nodal λT, slip origin and stick/slip
//!   state; `rows`: the tangent as the solver gets it (entries merged into
//!   matrix rows, active-set signature).
//!
//! The integrals:
//! - `geometry`: auxiliary plane, projection, polygon clipping,
//!   triangulation, quadrature points mapped back to both facets
//!   (`bilinear`: a facet's planar map and its inversion in f64);
//! - `segment`: dual basis of a slave facet and the integrals of one segment
//!   (weighted gap, mortar matrices `D` and `M`); `coverage`: the slave
//!   facets the master covers whole, whose `D` is their exact diagonal;
//! - `system`: nodal weighted gaps and pressures, residual and consistent
//!   tangent of a set of segments; `main_part`: the tangent without the
//!   derivatives of `D`, `M`, `ν` (the first Uzawa iteration from no
//!   contact);
//! - `friction`: Coulomb friction on the nodal multipliers (weighted slip,
//!   return map, tangential residual and tangent);
//! - `rigid`, `rigid_friction`: the same against a rigid analytic master
//!   (integrals over the slave facets alone).
mod bilinear;
pub mod coverage;
mod facet_side;
mod formulation;
pub mod friction;
pub mod geometry;
mod holding;
mod main_part;
mod master;
mod output;
pub mod pair;
mod restart;
pub mod rigid;
pub mod rigid_friction;
mod rigid_side;
mod rows;
pub mod segment;
mod setup;
mod share;
pub mod system;
mod tangential;

pub use pair::MortarPair;

/// Most nodes of a mortar facet (quad4): the mortar formulation is
/// first-order (the scene refuses second-order facets for it), so its
/// arrays stay sized for first-order facets.
pub const MAX_FACET_NODES: usize = crate::contact::LINEAR_FACET_NODES;

/// The first-order shape functions of a mortar facet at one point.
pub type FacetShape = crate::fem::shape::FacetShape<MAX_FACET_NODES>;

pub use crate::fem::shape::linear_facet_shape as facet_shape;

#[cfg(test)]
mod friction_tests;
#[cfg(test)]
mod rigid_tests;
#[cfg(test)]
mod rule_tests;
#[cfg(test)]
mod tests;
