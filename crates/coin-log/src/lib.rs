//! coin-log: a coin rolling without slipping on a horizontal table, simulated to many digits and recorded
//! as MCAP datasets for Foxglove. The physics is `docs/physics.md` (cited as "physics §n" and "eq (n)"), the
//! file format `docs/format.md`, and the modules' dependencies `docs/architecture.md`.

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
