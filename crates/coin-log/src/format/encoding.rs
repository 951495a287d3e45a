//! The two message encodings of a file (docs/format.md: Encodings): JSON with JSON Schemas (the default), and
//! Protobuf with `FileDescriptorSet` schemas. Both carry the same fields with the same f64 values.

use std::fmt;
use std::str::FromStr;

/// How the messages of a file are encoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Encoding {
    /// JSON messages, `jsonschema` schemas (`schemas/*.json`).
    #[default]
    Json,
    /// Protobuf messages, `protobuf` schemas: a serialized `FileDescriptorSet` (`schemas/*.proto` for the
    /// `coin_log.*` types, Foxglove's own descriptors for `foxglove.*`).
    Protobuf,
}

impl Encoding {
    /// Every encoding.
    pub const ALL: [Encoding; 2] = [Self::Json, Self::Protobuf];

    /// The name on the command line (`--encoding`).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Json => "json",
            Self::Protobuf => "protobuf",
        }
    }

    /// The MCAP schema encoding of its schemas.
    #[must_use]
    pub fn schema_encoding(self) -> &'static str {
        match self {
            Self::Json => "jsonschema",
            Self::Protobuf => "protobuf",
        }
    }

    /// The MCAP message encoding of its channels.
    #[must_use]
    pub fn message_encoding(self) -> &'static str {
        match self {
            Self::Json => "json",
            Self::Protobuf => "protobuf",
        }
    }

    /// The encoding whose MCAP schema encoding is `name`.
    #[must_use]
    pub fn from_schema_encoding(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|e| e.schema_encoding() == name)
    }

    /// The encoding whose MCAP message encoding is `name`.
    #[must_use]
    pub fn from_message_encoding(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|e| e.message_encoding() == name)
    }
}

impl fmt::Display for Encoding {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// An encoding name that is not `json` or `protobuf`.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown encoding `{0}`; use json or protobuf")]
pub struct UnknownEncoding(pub String);

impl FromStr for Encoding {
    type Err = UnknownEncoding;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|e| e.name() == s)
            .ok_or_else(|| UnknownEncoding(s.to_string()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_unknown_names_are_refused() {
        for e in Encoding::ALL {
            assert_eq!(e.name().parse::<Encoding>(), Ok(e));
            assert_eq!(Encoding::from_schema_encoding(e.schema_encoding()), Some(e));
            assert_eq!(
                Encoding::from_message_encoding(e.message_encoding()),
                Some(e)
            );
        }
        assert_eq!(
            "cbor".parse::<Encoding>().unwrap_err().to_string(),
            "unknown encoding `cbor`; use json or protobuf"
        );
        assert_eq!(Encoding::from_schema_encoding("ros2msg"), None);
    }
}
