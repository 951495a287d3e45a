//! coin-log: a coin rolling without slipping on a horizontal table, simulated to many digits and recorded
//! as MCAP datasets for Foxglove.
//!
//! The physics is that of `docs/physics.md` (cited as "physics §n" and "eq (n)"): a thin axisymmetric body in
//! rim contact with a flat table, no slip. The file format is `docs/format.md`. Dependencies point one way
//! (docs/architecture.md): [`model`] → [`integrate`] → [`simulation`] → [`format`](mod@format) → [`scene`] →
//! [`record`] / [`verify`] / [`analyse`] / [`inspect`] → `live` (cargo feature `live`); files are read and
//! written through the `coin-log-mcap` crate below them all, and the `coin-log-bench` crate and the `coin-log`
//! binary sit on top. [`files`] (what an input path may be, how an output is written) and [`csv`] use
//! nothing of the crate.

pub use coin_log_ode as integrate;

pub mod analyse;
pub mod csv;
pub mod files;
pub mod format;
pub mod inspect;
#[cfg(feature = "live")]
pub mod live;
pub mod model;
pub mod palette;
pub mod record;
pub mod scene;
pub mod simulation;
pub mod sweep;
pub mod verify;
