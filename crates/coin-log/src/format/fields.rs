//! Reading the numeric fields of a `coin_log.*` message whatever its encoding and its schema's version:
//! the one decoder of `verify`, `export` and `plot`.

use super::json::{parse_numbers_into, read_fields, FieldsError};
use super::messages::{Message, MessageType};
use super::protobuf::{MessageDecoder, SchemaError};
use super::{schema_data, Encoding};

/// How to read a channel's messages into f64s, from its schema.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FieldReader {
    fields: &'static [&'static str],
    /// It reads a schema of its type's first version (without the fields added since).
    first: bool,
    /// The decoder of a Protobuf schema; `None` reads JSON (strict: every field, no other, each a finite
    /// number).
    protobuf: Option<MessageDecoder>,
}

/// Which version of its type a stored `coin_log.*` schema is.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Version {
    /// This tool's.
    Ours,
    /// Another that declares the current fields.
    Other,
    /// The type's first, without the fields added since: its messages are read with the first fields.
    First,
    /// A JSON Schema the messages cannot conform to (why); they are read with the current fields.
    Nonconforming(String),
}

/// A schema whose messages cannot be read as numbers.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ReaderError {
    #[error("its schema encoding {0:?} is neither \"jsonschema\" nor \"protobuf\"")]
    Encoding(String),
    #[error("its Protobuf schema {0}")]
    Descriptor(#[from] SchemaError),
}

impl FieldReader {
    /// The reader of JSON messages of type `t`, of its first version if `first`.
    #[must_use]
    pub fn json(t: &MessageType, first: bool) -> Self {
        Self {
            fields: if first { t.first_fields } else { t.fields },
            first,
            protobuf: None,
        }
    }

    /// The reader of a channel of type `t` whose schema is stored with `schema_encoding` and bytes
    /// `data`, and the schema's version.
    pub fn new(
        schema_encoding: &str,
        t: &MessageType,
        data: &[u8],
    ) -> Result<(Self, Version), ReaderError> {
        let encoding = Encoding::from_schema_encoding(schema_encoding)
            .ok_or_else(|| ReaderError::Encoding(schema_encoding.to_string()))?;
        let ours = schema_data(t.schema, encoding) == Some(data);
        let added = t.fields != t.first_fields;
        if encoding == Encoding::Json {
            let version = if ours {
                Version::Ours
            } else {
                match validates(data, t.fields) {
                    Ok(()) => Version::Other,
                    Err(_) if added && validates(data, t.first_fields).is_ok() => Version::First,
                    Err(e) => Version::Nonconforming(e),
                }
            };
            return Ok((Self::json(t, version == Version::First), version));
        }
        let reader = |first: bool| {
            let json = Self::json(t, first);
            MessageDecoder::new(data, t.schema, json.fields).map(|d| Self {
                protobuf: Some(d),
                ..json
            })
        };
        match reader(false) {
            Ok(r) if ours => Ok((r, Version::Ours)),
            Ok(r) => Ok((r, Version::Other)),
            Err(e) => match reader(true) {
                Ok(r) if added => Ok((r, Version::First)),
                _ => Err(e.into()),
            },
        }
    }

    #[must_use]
    pub fn fields(&self) -> &'static [&'static str] {
        self.fields
    }

    /// Reads one message into `out` in the order of [`Self::fields`] (`out.len()` = their number).
    pub fn read(&self, data: &[u8], out: &mut [f64]) -> Result<(), FieldsError> {
        match &self.protobuf {
            Some(d) => d.read(data, out),
            None => read_fields(data, self.fields, out),
        }
    }

    /// Reads one message strictly into its type `M`: the recorder's own JSON form on the fast path, any
    /// other (or an error) by serde_json. `Err` says what is wrong with it, also when it does not have
    /// exactly the fields of its schema's version.
    pub fn read_message<M: Message>(&self, data: &[u8]) -> Result<M, String> {
        let mut v = [0.0; 8];
        let v_fields = &mut v[..self.fields.len()];
        let m = match &self.protobuf {
            Some(d) => {
                d.read(data, v_fields)
                    .map_err(|e| format!("does not parse: the message {e}"))?;
                M::from_values(&v, self.first)
            }
            None if parse_numbers_into(data, self.fields, v_fields) => {
                M::from_values(&v, self.first)
            }
            None => serde_json::from_slice(data).map_err(|e| format!("does not parse: {e}"))?,
        };
        if m.is_complete() == self.first {
            return Err(if self.first {
                "has fields its schema (the first version) does not declare".into()
            } else {
                "lacks fields its schema requires".into()
            });
        }
        Ok(m)
    }
}

/// Whether a JSON schema of another version validates the messages of a type with `fields`: a message
/// read strictly has exactly `fields`, each a number, so it conforms to the schema when the schema
/// requires none but `fields`, types each of them (where it types it) as a number, and does not forbid
/// (`additionalProperties: false`) one it leaves out.
fn validates(data: &[u8], fields: &[&str]) -> Result<(), String> {
    use serde_json::Value;
    let v: Value = serde_json::from_slice(data).map_err(|e| format!("is not JSON: {e}"))?;
    if let Some(t) = v.get("type").filter(|t| t.as_str() != Some("object")) {
        return Err(format!("types the messages as {t}, not an object"));
    }
    let props = v.get("properties").and_then(Value::as_object);
    let required = v.get("required").and_then(Value::as_array);
    for r in required.into_iter().flatten() {
        let r = r
            .as_str()
            .ok_or("has a `required` entry that is not a string")?;
        if !fields.contains(&r) {
            return Err(format!("requires `{r}`, which the messages lack"));
        }
    }
    let closed = v.get("additionalProperties") == Some(&Value::Bool(false));
    for f in fields {
        match props.and_then(|p| p.get(*f)) {
            Some(p) => match p.get("type") {
                None => {}
                Some(t) if t.as_str() == Some("number") => {}
                Some(t) => return Err(format!("types `{f}` as {t}, the messages have a number")),
            },
            None if closed => return Err(format!("forbids `{f}`, which the messages have")),
            None => {}
        }
    }
    Ok(())
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
            let schema = schema_data(Position::TYPE.schema, e).unwrap();
            let (r, version) =
                FieldReader::new(e.schema_encoding(), &Position::TYPE, schema).unwrap();
            assert_eq!(version, Version::Ours);
            assert_eq!(r.protobuf.is_some(), e == Encoding::Protobuf);
            let mut buf = Vec::new();
            m.write(e, &mut buf).unwrap();
            let mut out = [0.0; 4];
            r.read(&buf, &mut out).unwrap();
            outs.push(out.map(f64::to_bits));
        }
        assert_eq!(outs[0], outs[1]);
        assert_eq!(
            FieldReader::new("ros2msg", &Position::TYPE, b"")
                .unwrap_err()
                .to_string(),
            "its schema encoding \"ros2msg\" is neither \"jsonschema\" nor \"protobuf\""
        );
    }
}
