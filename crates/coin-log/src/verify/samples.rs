//! Samples: the messages of all `coin_log.*` channels that share one log time, assembled while streaming.
//!
//! Messages of one time usually arrive together, so the queue holds one or two samples; it is capped so that
//! a file whose channels are far apart in time still verifies in bounded memory (samples are then judged
//! with the channels that had arrived).

use crate::format::messages::{
    Angles, AngularVelocity, EnergyMessage, InvariantsMessage, Position, QuaternionMessage,
    ReactionMessage, WorkMessage,
};
use crate::model::State;
use std::collections::VecDeque;

/// Most samples waiting for their other channels.
const MAX_PENDING: usize = 4096;

/// Index of each `coin_log.*` channel in a sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Slot {
    /// `/coin/omega`.
    Omega = 0,
    /// `/coin/angles`.
    Angles = 1,
    /// `/coin/quaternion`.
    Quaternion = 2,
    /// `/coin/position`.
    Position = 3,
    /// `/coin/contact`.
    Contact = 4,
    /// `/coin/reaction`.
    Reaction = 5,
    /// `/coin/energy`.
    Energy = 6,
    /// `/coin/invariants`.
    Invariants = 7,
    /// `/coin/work` (dissipative runs).
    Work = 8,
}

/// Number of slots.
pub const SLOTS: usize = 9;

/// A parsed message of one slot.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Value {
    /// ω.
    Omega(AngularVelocity),
    /// θ, φ, ψ.
    Angles(Angles),
    /// q.
    Quaternion(QuaternionMessage),
    /// Centre.
    Position(Position),
    /// Contact point.
    Contact(Position),
    /// R, F, N.
    Reaction(ReactionMessage),
    /// E.
    Energy(EnergyMessage),
    /// C1, C2.
    Invariants(InvariantsMessage),
    /// W, E + W.
    Work(WorkMessage),
}

/// The stored values at one log time.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Sample {
    /// Log time \[ns\].
    pub log_time: u64,
    /// Simulation time (of the first message of the sample).
    pub t: f64,
    /// ω.
    pub omega: Option<AngularVelocity>,
    /// θ, φ, ψ.
    pub angles: Option<Angles>,
    /// q.
    pub quaternion: Option<QuaternionMessage>,
    /// Centre.
    pub position: Option<Position>,
    /// Contact point.
    pub contact: Option<Position>,
    /// R, F, N.
    pub reaction: Option<ReactionMessage>,
    /// E.
    pub energy: Option<EnergyMessage>,
    /// C1, C2.
    pub invariants: Option<InvariantsMessage>,
    /// W, E + W.
    pub work: Option<WorkMessage>,
    present: u16,
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

    fn set(&mut self, value: Value) {
        match value {
            Value::Omega(m) => self.omega = Some(m),
            Value::Angles(m) => self.angles = Some(m),
            Value::Quaternion(m) => self.quaternion = Some(m),
            Value::Position(m) => self.position = Some(m),
            Value::Contact(m) => self.contact = Some(m),
            Value::Reaction(m) => self.reaction = Some(m),
            Value::Energy(m) => self.energy = Some(m),
            Value::Invariants(m) => self.invariants = Some(m),
            Value::Work(m) => self.work = Some(m),
        }
    }
}

/// Groups messages by log time and hands out complete samples in time order.
#[derive(Debug, Default)]
pub struct Assembler {
    pending: VecDeque<Sample>,
    last: [Option<u64>; SLOTS],
    declared: u16,
}

impl Assembler {
    /// Marks a slot as present in the file (its channel record was read).
    pub fn declare(&mut self, slot: Slot) {
        self.declared |= 1 << slot as u16;
    }

    /// True when the slot's channel is in the file.
    #[must_use]
    pub fn declared(&self, slot: Slot) -> bool {
        self.declared & (1 << slot as u16) != 0
    }

    /// Adds one message; calls `out` with every sample that can no longer grow.
    pub fn push(
        &mut self,
        slot: Slot,
        log_time: u64,
        t: f64,
        value: Value,
        out: &mut impl FnMut(&Sample),
    ) {
        let bit = 1u16 << slot as u16;
        self.declared |= bit;
        self.last[slot as usize] = Some(log_time);
        let position = self.pending.iter().rposition(|s| s.log_time <= log_time);
        match position {
            Some(i) if self.pending[i].log_time == log_time => {
                let s = &mut self.pending[i];
                if s.present & bit == 0 {
                    s.present |= bit;
                    s.set(value);
                }
            }
            _ => {
                let mut s = Sample {
                    log_time,
                    t,
                    present: bit,
                    ..Sample::default()
                };
                s.set(value);
                let at = position.map_or(0, |i| i + 1);
                self.pending.insert(at, s);
            }
        }
        self.flush_ready(out);
    }

    fn flush_ready(&mut self, out: &mut impl FnMut(&Sample)) {
        // A sample is final when every declared slot has moved past it (each channel's log times
        // increase), or when all declared slots are in and a later sample has begun (a channel record
        // may be written just before its first message, so "all declared" alone can be premature).
        let horizon = (0..SLOTS)
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
