//! Mortar contact: multipliers at the slave nodes with dual (biorthogonal)
//! shape functions, integrated segment by segment over the slave–master
//! overlaps.
//!
//! - `geometry`: auxiliary plane, projection, polygon clipping,
//!   triangulation, quadrature points mapped back to both facets
//!   (`bilinear`: a facet's planar map and its inversion in f64);
//! - `segment`: dual basis of a slave facet and the integrals of one segment
//!   (weighted gap, mortar matrices `D` and `M`); `coverage`: the slave
//!   facets the master covers whole, whose `D` is their exact diagonal;
//! - `friction`: Coulomb friction on the nodal multipliers (weighted slip,
//!   return map, tangential residual and tangent);
//! - `pair`: a mortar pair at run time (search, assembly, Uzawa update);
//!   `pair_setup` builds it on a rank, `halo` decides what the rank holds
//!   (its slave facets and those around their nodes, the master facets
//!   near them) and numbers the nodes it does not see;
//! - `main_part`: the tangent without the derivatives of `D`, `M`, `ν`
//!   (the first Uzawa iteration from no contact);
//! - `rows`: the tangent as the solver gets it (entries merged into matrix
//!   rows, active-set signature);
//! - `tangential`: a frictional pair's nodal λT, slip origin and stick/slip
//!   state at run time;
//! - `system`: nodal weighted gaps and pressures, residual and consistent
//!   tangent of a set of segments;
//! - `rigid`, `rigid_friction`: the same against a rigid analytic master
//!   (integrals over the slave facets alone), `rigid_master` the surface
//!   and its motion, `rigid_pair` their run-time side;
//! - `pair_output`: the pair's nodal fields, force and point values;
//!   `pair_restart`: taking them over from a result file.
mod bilinear;
pub mod coverage;
mod facet_search;
mod formulation;
pub mod friction;
pub mod geometry;
mod halo;
mod holding;
mod main_part;
pub mod pair;
mod pair_output;
mod pair_restart;
mod pair_setup;
pub mod rigid;
pub mod rigid_friction;
mod rigid_master;
mod rigid_pair;
mod rows;
pub mod segment;
pub mod system;
mod tangential;

pub use pair::MortarPair;

#[cfg(test)]
mod friction_tests;
#[cfg(test)]
mod rigid_tests;
#[cfg(test)]
mod rule_tests;
#[cfg(test)]
mod tests;
