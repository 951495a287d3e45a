//! Writing MCAP logs (CONTRACT: Channels, Metadata records).

pub mod channels;
pub mod messages;

pub use channels::{schema_bytes, Channel, UnknownChannel, MESSAGE_ENCODING, SCHEMA_ENCODING};
