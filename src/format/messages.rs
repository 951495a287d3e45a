//! The `coin_log.*` message types (format.md: Channels and fields). Each type deserialises strictly (unknown or missing
//! fields rejected) for `verify`, and writes itself as compact JSON straight into a reused buffer for the
//! recorder's hot path: shortest round-trip floats (ryu), fields in the schema's order, no allocation.
//!
//! Hand-written rather than `serde_json::to_writer` because the recorder formats tens of millions of
//! messages and must refuse non-finite numbers (JSON has no NaN) instead of writing `null`.

use serde::Deserialize;

/// A number that JSON cannot carry.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error(
    "field `{field}` of a `{schema}` message is {value}; JSON messages carry finite numbers only"
)]
pub struct NonFiniteField {
    /// Schema name.
    pub schema: &'static str,
    /// Field name.
    pub field: &'static str,
    /// The value.
    pub value: f64,
}

/// Appends the shortest round-trip decimal form of a finite `value` to `buf`.
#[inline]
pub fn push_number(buf: &mut Vec<u8>, value: f64, formatter: &mut ryu::Buffer) {
    buf.extend_from_slice(formatter.format_finite(value).as_bytes());
}

macro_rules! message {
    ($(#[$doc:meta])* $name:ident, $schema:literal, { $($(#[$fdoc:meta])* $field:ident),+ $(,)? }) => {
        $(#[$doc])*
        #[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
        #[serde(deny_unknown_fields)]
        pub struct $name {
            $($(#[$fdoc])* pub $field: f64,)+
        }

        impl $name {
            /// Schema name of this message type.
            pub const SCHEMA: &'static str = $schema;
            /// Field names in schema order.
            pub const FIELDS: &'static [&'static str] = &[$(stringify!($field)),+];

            /// Appends this message as one compact JSON object to `buf`.
            ///
            /// # Errors
            /// [`NonFiniteField`] if a field is NaN or infinite; `buf` is then left as it was.
            pub fn write_json(&self, buf: &mut Vec<u8>) -> Result<(), NonFiniteField> {
                $(
                    if !self.$field.is_finite() {
                        return Err(NonFiniteField { schema: $schema, field: stringify!($field), value: self.$field });
                    }
                )+
                let mut formatter = ryu::Buffer::new();
                let mut first = true;
                buf.push(b'{');
                $(
                    if !first {
                        buf.push(b',');
                    }
                    first = false;
                    buf.extend_from_slice(concat!("\"", stringify!($field), "\":").as_bytes());
                    push_number(buf, self.$field, &mut formatter);
                )+
                let _ = first;
                buf.push(b'}');
                Ok(())
            }

            /// Simulation time of the message.
            #[must_use]
            pub fn time(&self) -> f64 {
                self.t
            }
        }
    };
}

message!(
    /// `/coin/omega`: ω in the lean frame [rad/time].
    AngularVelocity, "coin_log.AngularVelocity", {
    /// Simulation time.
    t,
    /// ω_X.
    x,
    /// ω_Y.
    y,
    /// ω_Z.
    z,
});

message!(
    /// `/coin/angles`: θ, φ, ψ \[rad\], φ and ψ unwrapped.
    Angles, "coin_log.Angles", {
    /// Simulation time.
    t,
    /// θ, lean.
    theta,
    /// φ, heading.
    phi,
    /// ψ, spin.
    psi,
});

message!(
    /// `/coin/quaternion`: q of physics §1.
    QuaternionMessage, "coin_log.Quaternion", {
    /// Simulation time.
    t,
    /// Vector part x.
    x,
    /// Vector part y.
    y,
    /// Vector part z.
    z,
    /// Scalar part.
    w,
});

message!(
    /// `/coin/position` (centre) and `/coin/contact` (contact point), world frame, y up \[length\].
    Position, "coin_log.Position", {
    /// Simulation time.
    t,
    /// x.
    x,
    /// y (height).
    y,
    /// z.
    z,
});

message!(
    /// `/coin/reaction`: R (world frame), F and N \[force\].
    ReactionMessage, "coin_log.Reaction", {
    /// Simulation time.
    t,
    /// R_x.
    x,
    /// R_y.
    y,
    /// R_z.
    z,
    /// F = √(R_x² + R_z²).
    friction,
    /// N = R_y.
    normal,
});

message!(
    /// `/coin/energy` [mass·length²/time²].
    EnergyMessage, "coin_log.Energy", {
    /// Simulation time.
    t,
    /// Total energy.
    total,
    /// Kinetic energy.
    kinetic,
    /// Potential energy.
    potential,
});

message!(
    /// `/coin/invariants`: C1, C2 of physics §6.
    InvariantsMessage, "coin_log.Invariants", {
    /// Simulation time.
    t,
    /// C1.
    c1,
    /// C2.
    c2,
});

message!(
    /// `/coin/work`: the dissipated work and the energy balance (physics §11) [mass·length²/time²].
    WorkMessage, "coin_log.Work", {
    /// Simulation time.
    t,
    /// W, the energy dissipated since t = 0.
    dissipated,
    /// E + W, constant for an exact solution.
    balance,
});

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_round_trip_bit_for_bit_through_json() {
        let m = EnergyMessage {
            t: 0.01,
            total: 1.0 / 3.0,
            kinetic: -0.0,
            potential: 1e-300,
        };
        let mut buf = Vec::new();
        m.write_json(&mut buf).unwrap();
        let back: EnergyMessage = serde_json::from_slice(&buf).unwrap();
        assert_eq!(format!("{back:?}"), format!("{m:?}"));
        assert_eq!(back.total.to_bits(), m.total.to_bits());
    }

    #[test]
    fn non_finite_numbers_are_refused_and_leave_the_buffer_alone() {
        let mut buf = b"x".to_vec();
        let err = AngularVelocity {
            t: 0.0,
            x: f64::NAN,
            y: 0.0,
            z: 0.0,
        }
        .write_json(&mut buf)
        .unwrap_err();
        assert_eq!(err.field, "x");
        assert_eq!(buf, b"x");
    }

    #[test]
    fn unknown_and_missing_fields_are_rejected() {
        assert!(
            serde_json::from_str::<InvariantsMessage>(r#"{"t":0,"c1":1,"c2":2,"c3":3}"#).is_err()
        );
        assert!(serde_json::from_str::<InvariantsMessage>(r#"{"t":0,"c1":1}"#).is_err());
    }
}
