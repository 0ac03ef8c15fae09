//! Cell and facet types are the element kernels' (`crate::fem`): one
//! definition of node numbering and of the outward local face tables for the
//! whole program.
pub use crate::fem::{CellType, FacetType};
