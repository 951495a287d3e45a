//! The two message encodings of a file (docs/format.md: Encodings): JSON with JSON Schemas (the default), and
//! Protobuf with `FileDescriptorSet` schemas. Both carry the same fields with the same f64 values.

coin_log_names::named_enum! {
    /// How the messages of a file are encoded; the name is the one of `--encoding`.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
    pub enum Encoding: "encoding" {
        /// JSON messages, `jsonschema` schemas (`schemas/*.json`).
        #[default]
        Json = "json",
        /// Protobuf messages, `protobuf` schemas: a serialized `FileDescriptorSet` (`schemas/*.proto` for the
        /// `coin_log.*` types, Foxglove's own descriptors for `foxglove.*`).
        Protobuf = "protobuf",
    }
}

impl Encoding {
    /// The MCAP schema encoding of its schemas.
    #[must_use]
    pub const fn schema_encoding(self) -> &'static str {
        match self {
            Self::Json => "jsonschema",
            Self::Protobuf => "protobuf",
        }
    }

    /// The MCAP message encoding of its channels.
    #[must_use]
    pub const fn message_encoding(self) -> &'static str {
        match self {
            Self::Json => "json",
            Self::Protobuf => "protobuf",
        }
    }

    /// The encoding whose MCAP schema encoding is `name`.
    #[must_use]
    pub fn from_schema_encoding(name: &str) -> Option<Self> {
        Self::ALL
            .iter()
            .copied()
            .find(|e| e.schema_encoding() == name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_unknown_names_are_refused() {
        for &e in Encoding::ALL {
            assert_eq!(e.name().parse::<Encoding>(), Ok(e));
            assert_eq!(Encoding::from_schema_encoding(e.schema_encoding()), Some(e));
        }
        assert_eq!(
            "cbor".parse::<Encoding>().unwrap_err().to_string(),
            "unknown encoding `cbor`; valid: json, protobuf"
        );
        assert_eq!(Encoding::from_schema_encoding("ros2msg"), None);
    }
}
