//! Reading the numeric fields of a `coin_log.*` message whatever its encoding: the one entry point of the
//! readers that take any coin-log file (`export`, `plot`). `verify` uses the same two decoders with its
//! typed messages.

use super::json::{read_fields, FieldsError};
use super::protobuf::{MessageDecoder, SchemaError};
use super::Encoding;

/// How to read a channel's messages into f64s, from its schema.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FieldReader {
    /// JSON objects (strict: every field, no other, each a finite number).
    Json,
    /// Protobuf messages, by the field numbers of the stored descriptor.
    Protobuf(MessageDecoder),
}

/// A schema whose messages cannot be read as numbers.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ReaderError {
    /// Neither `jsonschema` nor `protobuf`.
    #[error("its schema encoding {0:?} is neither \"jsonschema\" nor \"protobuf\"")]
    Encoding(String),
    /// A Protobuf descriptor that does not describe the fields.
    #[error("its Protobuf schema {0}")]
    Descriptor(#[from] SchemaError),
}

impl FieldReader {
    /// The reader of a channel whose schema is `schema_name`, stored with `schema_encoding` and bytes
    /// `schema_data`, for `fields`.
    ///
    /// # Errors
    /// [`ReaderError`] for another schema encoding, or a descriptor without the type or a field.
    pub fn new(
        schema_encoding: &str,
        schema_name: &str,
        schema_data: &[u8],
        fields: &[&'static str],
    ) -> Result<Self, ReaderError> {
        match Encoding::from_schema_encoding(schema_encoding) {
            Some(Encoding::Json) => Ok(Self::Json),
            Some(Encoding::Protobuf) => Ok(Self::Protobuf(MessageDecoder::new(
                schema_data,
                schema_name,
                fields,
            )?)),
            None => Err(ReaderError::Encoding(schema_encoding.to_string())),
        }
    }

    /// The encoding it reads.
    #[must_use]
    pub fn encoding(&self) -> Encoding {
        match self {
            Self::Json => Encoding::Json,
            Self::Protobuf(_) => Encoding::Protobuf,
        }
    }

    /// Reads one message into `out` in the order of `fields` (`out.len() == fields.len()`, the fields the
    /// reader was made for).
    ///
    /// # Errors
    /// [`FieldsError`] naming what is wrong with the message.
    pub fn read(&self, data: &[u8], fields: &[&str], out: &mut [f64]) -> Result<(), FieldsError> {
        match self {
            Self::Json => read_fields(data, fields, out),
            Self::Protobuf(d) => d.read(data, out),
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::format::messages::Position;
    use crate::format::schema_data;

    #[test]
    fn both_encodings_of_a_message_read_the_same_numbers() {
        let m = Position {
            t: 0.25,
            x: -1.0 / 3.0,
            y: 1e-300,
            z: -0.0,
        };
        let mut outs = Vec::new();
        for &e in Encoding::ALL {
            let schema = schema_data(Position::SCHEMA, e).unwrap();
            let r = FieldReader::new(
                e.schema_encoding(),
                Position::SCHEMA,
                schema,
                Position::FIELDS,
            )
            .unwrap();
            assert_eq!(r.encoding(), e);
            let mut buf = Vec::new();
            m.write(e, &mut buf).unwrap();
            let mut out = [0.0; 4];
            r.read(&buf, Position::FIELDS, &mut out).unwrap();
            outs.push(out.map(f64::to_bits));
        }
        assert_eq!(outs[0], outs[1]);
        assert_eq!(
            FieldReader::new("ros2msg", Position::SCHEMA, b"", Position::FIELDS)
                .unwrap_err()
                .to_string(),
            "its schema encoding \"ros2msg\" is neither \"jsonschema\" nor \"protobuf\""
        );
    }
}
