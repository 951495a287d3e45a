//! coin-log: a coin rolling without slipping on a horizontal table, simulated to many digits and recorded
//! as MCAP datasets for Foxglove.
//!
//! The physics is that of `docs/physics.md` (cited as "physics §n" and "eq (n)"): a thin axisymmetric body in
//! rim contact with a flat table, no slip. The file format is `docs/format.md`. Dependencies point one way
//! (docs/architecture.md): [`model`], [`mcap_io`] → [`integrate`] → [`simulation`] → [`format`](mod@format) → [`scene`] →
//! [`record`] / [`verify`] / [`analyse`] / [`inspect`] → `live` (cargo feature `live`) → [`bench`](mod@bench) → the
//! `coin-log` binary.

pub mod analyse;
pub mod bench;
pub mod format;
pub mod inspect;
pub mod integrate;
#[cfg(feature = "live")]
pub mod live;
pub mod mcap_io;
pub mod model;
pub mod record;
pub mod scene;
pub mod simulation;
pub mod verify;
