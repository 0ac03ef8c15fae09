//! Contact: the ContactLink3D condition (docs/formulation.md §2–§5, §9).
//!
//! - `surfaces`: the slave and master sides as one rank sees them;
//! - `held_master`: the master facets of a links pair one rank holds, and
//!   the bounding-box exchange that decides them at every search;
//! - `search`: spatial index, outer and inner search;
//! - `projection`: closest-point projection onto a master facet;
//! - `kernel`: the kernel of one link: gap, normal, contact pressure
//!   pN = ⟨λN − εN gN⟩, Coulomb friction (trial traction, stick/slip, return
//!   map), residual and consistent tangent;
//! - `multipliers`: λN and the friction state (λT, slip origin, stick/slip)
//!   at the slave points, the Uzawa update rule, halo exchange;
//! - `outcome`: what a pair's evaluation reports (Uzawa statistics, force),
//!   shared by both formulations;
//! - `pair_state`: a pair at run time ([`ContactPair`]: search per step,
//!   assembly, Uzawa update, snapshots and restart, output values);
//! - `mortar`: the mortar formulation (nodal dual multipliers, segment-based
//!   integration of the slave–master overlap).
//!
//! Nothing here calls the solver: `solve` drives the Uzawa loop around SNES.
pub mod autodiff;
pub mod held_master;
pub mod kernel;
pub mod mortar;
pub mod multipliers;
pub mod outcome;
pub mod pair_state;
pub mod projection;
pub mod search;
pub mod surfaces;

pub use outcome::{PairForce, UzawaStats};
pub use pair_state::ContactPair;
