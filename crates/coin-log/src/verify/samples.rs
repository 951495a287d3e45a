//! Samples (format.md: verify): the messages of all `coin_log.*` channels that share one log time,
//! assembled while streaming. Messages of one time usually arrive together, so the queue holds one or two
//! samples; its cap bounds the memory where a file's channels lie far apart.

use crate::format::messages::{
    Angles, AngularVelocity, EnergyMessage, InvariantsMessage, Position, QuaternionMessage,
    ReactionMessage, WorkMessage,
};
use crate::format::Channel;
use crate::model::State;
use std::collections::VecDeque;

/// Most samples waiting for their other channels.
pub(super) const MAX_PENDING: usize = 4096;

/// The stored values at one log time \[ns\]; `t` is the first message's.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Sample {
    pub log_time: u64,
    pub t: f64,
    pub omega: Option<AngularVelocity>,
    pub angles: Option<Angles>,
    pub quaternion: Option<QuaternionMessage>,
    pub position: Option<Position>,
    pub contact: Option<Position>,
    pub reaction: Option<ReactionMessage>,
    pub energy: Option<EnergyMessage>,
    pub invariants: Option<InvariantsMessage>,
    pub work: Option<WorkMessage>,
    pub(super) present: u16,
}

impl Sample {
    /// The state θ, φ, ψ, ω (and x, z when the position is stored, else 0), if ω and the angles are.
    #[must_use]
    pub fn state(&self) -> Option<State> {
        let (w, a) = (self.omega?, self.angles?);
        let (x, z) = self.position.map_or((0.0, 0.0), |p| (p.x, p.z));
        Some(State {
            theta: a.theta,
            phi: a.phi,
            psi: a.psi,
            omega_x: w.x,
            omega_y: w.y,
            omega_z: w.z,
            x,
            z,
        })
    }

    /// Takes the messages of `o` (one channel's) that `self` lacks.
    fn merge(&mut self, o: &Sample) {
        self.omega = self.omega.or(o.omega);
        self.angles = self.angles.or(o.angles);
        self.quaternion = self.quaternion.or(o.quaternion);
        self.position = self.position.or(o.position);
        self.contact = self.contact.or(o.contact);
        self.reaction = self.reaction.or(o.reaction);
        self.energy = self.energy.or(o.energy);
        self.invariants = self.invariants.or(o.invariants);
        self.work = self.work.or(o.work);
    }
}

/// Groups messages by log time and hands out complete samples in time order.
#[derive(Debug, Default)]
pub struct Assembler {
    pending: VecDeque<Sample>,
    last: [Option<u64>; Channel::ALL.len()],
    declared: u16,
    /// Samples handed out by the cap before all declared channels had arrived.
    cut: u64,
}

impl Assembler {
    /// Marks a channel as one whose message each sample waits for: its channel record was read, or the
    /// stored scene records it (a scene that validates lists `work` only with dissipation).
    pub fn declare(&mut self, channel: Channel) {
        self.declared |= 1 << channel as u16;
    }

    /// An empty assembler waiting for the same channels.
    #[must_use]
    pub fn afresh(&self) -> Self {
        Self {
            declared: self.declared,
            ..Self::default()
        }
    }

    /// How many samples the cap ([`MAX_PENDING`]) handed out before all their channels had arrived: the
    /// file's channels lie far apart in it.
    #[must_use]
    pub fn cut(&self) -> u64 {
        self.cut
    }

    /// True when the channel was declared or a message of it was pushed.
    #[must_use]
    pub fn declared(&self, channel: Channel) -> bool {
        self.declared & (1 << channel as u16) != 0
    }

    /// Adds `one`, a sample of `channel`'s message alone; calls `out` with every sample that can no
    /// longer grow.
    pub fn push(&mut self, channel: Channel, one: &Sample, out: &mut impl FnMut(&Sample)) {
        let (bit, log_time) = (1u16 << channel as u16, one.log_time);
        self.declared |= bit;
        self.last[channel as usize] = Some(log_time);
        let position = self.pending.iter().rposition(|s| s.log_time <= log_time);
        match position {
            Some(i) if self.pending[i].log_time == log_time => {
                let s = &mut self.pending[i];
                if s.present & bit == 0 {
                    s.present |= bit;
                    s.merge(one);
                }
            }
            _ => {
                let at = position.map_or(0, |i| i + 1);
                self.pending.insert(
                    at,
                    Sample {
                        present: bit,
                        ..*one
                    },
                );
            }
        }
        self.flush_ready(out);
    }

    fn flush_ready(&mut self, out: &mut impl FnMut(&Sample)) {
        // A sample is final when every declared channel has moved past it (each channel's log times
        // increase), or when all declared channels are in and a later sample has begun (a channel record
        // may be written just before its first message, so "all declared" alone can be premature).
        let horizon = (0..Channel::ALL.len())
            .filter(|i| self.declared & (1 << i) != 0)
            .map(|i| self.last[i].unwrap_or(0))
            .min()
            .unwrap_or(0);
        while let Some(front) = self.pending.front() {
            let done = (front.present == self.declared && self.pending.len() > 1)
                || front.log_time < horizon
                || self.pending.len() > MAX_PENDING;
            if !done {
                break;
            }
            if let Some(s) = self.pending.pop_front() {
                self.cut += u64::from(s.present != self.declared && s.log_time >= horizon);
                out(&s);
            }
        }
    }

    /// Hands out every remaining sample (end of file).
    pub fn finish(&mut self, out: &mut impl FnMut(&Sample)) {
        while let Some(s) = self.pending.pop_front() {
            out(&s);
        }
    }
}
