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
