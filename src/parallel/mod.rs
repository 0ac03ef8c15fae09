//! Where rank-local outcomes become one decision of all ranks.
//!
//! A rank that acts on something only it has seen (an inverted cell, a
//! failed write, a per-rank solver choice) leaves the others waiting in the
//! next collective call, or makes them take another branch. Every such
//! outcome goes through this module before any rank acts on it:
//! [`agree`] and [`agree_failure`] turn a rank-local result into the same
//! result on every rank, carrying the lowest failing rank's message, and
//! [`any_rank`], [`all_ranks`], [`sum`] and [`max`] are the reductions the
//! run loop steers by; [`gather_all`] concatenates every rank's slice on
//! every rank ([`gather_equal`] when all slices have one length,
//! [`gather_root`] on rank 0 only), and
//! [`all_to_all`] sends each rank its own array; [`from_root`] hands the
//! outcome of work only one rank does (success or error) to every rank.
//! [`fault`] makes one rank fail on purpose (tests only).
pub mod agree;
pub mod fault;
mod gather;
mod relay;

pub use crate::exchange::all_to_all;
pub use agree::{
    agree, agree_failure, all_ranks, any_rank, broadcast_text, lowest_rank, max, sum, sum_usize,
    RankFailure,
};
pub use gather::{gather_all, gather_equal, gather_root};
pub use relay::from_root;
