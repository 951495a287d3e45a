//! The helpers of the integration tests.

pub mod newton_euler;
pub mod physics;
pub mod record;
pub mod vectors;
pub mod verify_files;
pub mod writers;
