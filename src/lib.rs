//! coin-log: a coin rolling without slipping on a horizontal table, simulated to many digits and recorded
//! as MCAP datasets for Foxglove.
//!
//! The physics is that of `shared/physics/NOTES.md` (cited as "NOTES §n" and "eq (n)"): a thin axisymmetric
//! body in rim contact with a flat table, no slip, no dissipation. Dependencies point one way:
//! [`model`] → [`integrate`] → scene → record / verify → the `coin-log` binary; record and verify read and
//! write files through [`mcap_io`], which depends on nothing else in the crate.

pub mod bench;
pub mod integrate;
pub mod mcap_io;
pub mod model;
pub mod record;
pub mod scene;
pub mod simulation;
pub mod units;
pub mod verify;
