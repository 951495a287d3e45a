//! Foxglove's 3D view of the coin: `/tf` (world → table → coin) and `/scene` (the coin as a cylinder with a
//! mark, the contact track), as CONTRACT and FOXGLOVE.md describe.
//!
//! INTERFACE FIXED FOR THE RECORDER; the message bodies are being written (issue 6).

use super::channels::Channel;
use super::messages::NonFiniteField;
use crate::model::{Coin, State};
use std::ops::Range;

/// The Foxglove messages due at one sample, in one reused buffer.
#[derive(Debug, Default)]
pub struct FoxgloveBatch {
    bytes: Vec<u8>,
    messages: Vec<(Channel, Range<usize>)>,
}

impl FoxgloveBatch {
    /// Empties the batch, keeping its capacity.
    pub fn clear(&mut self) {
        self.bytes.clear();
        self.messages.clear();
    }

    /// Appends one message on `channel`, written by `write`.
    ///
    /// # Errors
    /// Whatever `write` returns; the batch is then left without the message.
    pub fn push(
        &mut self,
        channel: Channel,
        write: impl FnOnce(&mut Vec<u8>) -> Result<(), NonFiniteField>,
    ) -> Result<(), NonFiniteField> {
        let start = self.bytes.len();
        match write(&mut self.bytes) {
            Ok(()) => {
                self.messages.push((channel, start..self.bytes.len()));
                Ok(())
            }
            Err(e) => {
                self.bytes.truncate(start);
                Err(e)
            }
        }
    }

    /// The messages, in the order they were pushed.
    pub fn iter(&self) -> impl Iterator<Item = (Channel, &[u8])> + '_ {
        self.messages
            .iter()
            .map(|(c, r)| (*c, &self.bytes[r.clone()]))
    }
}

/// State of the 3D output across samples (display rate, the contact track published so far).
#[derive(Debug, Clone)]
pub struct Foxglove3d {
    #[allow(dead_code)]
    coin: Coin,
    #[allow(dead_code)]
    thickness: f64,
    tf: bool,
    scene: bool,
}

impl Foxglove3d {
    /// Output for `coin` drawn `thickness` (fraction of a) thick; `tf` and `scene` say which channels are on.
    #[must_use]
    pub fn new(coin: &Coin, thickness: f64, tf: bool, scene: bool) -> Self {
        Self {
            coin: *coin,
            thickness,
            tf,
            scene,
        }
    }

    /// True when neither `/tf` nor `/scene` is recorded (nothing to compute).
    #[must_use]
    pub fn is_off(&self) -> bool {
        !self.tf && !self.scene
    }

    /// Appends to `out` the messages due at the sample (t, s), whose log time is `log_time` ns; `last` marks
    /// the run's final sample (so the scene shows the final state).
    ///
    /// # Errors
    /// [`NonFiniteField`] if a value is not finite.
    pub fn sample(
        &mut self,
        _t: f64,
        _log_time: u64,
        _s: &State,
        _last: bool,
        _out: &mut FoxgloveBatch,
    ) -> Result<(), NonFiniteField> {
        Ok(())
    }
}
