//! The Protobuf form of the format (docs/format.md: Encodings): the schemas as serialized
//! `FileDescriptorSet`s (the `coin_log.*` ones built with `prost-types` as protoc describes
//! `schemas/*.proto`, so no `protoc` is needed; the `foxglove.*` ones as the `foxglove` crate ships them),
//! and a decoder that reads a `coin_log.*` message field by field by the numbers of a stored descriptor.

use super::json::FieldsError;
use super::messages::{
    MessageType, FRAME_TRANSFORM, MESSAGE_TYPES, POINT_CLOUD, SCENE_UPDATE, VOXEL_GRID,
};
use prost::encoding::{decode_key, decode_varint, WireType};
use prost::Message;
use prost_types::field_descriptor_proto::{Label, Type};
use prost_types::{DescriptorProto, FieldDescriptorProto, FileDescriptorProto, FileDescriptorSet};
use std::sync::OnceLock;

/// The Protobuf package of the `coin_log.*` types.
pub const PACKAGE: &str = "coin_log";

/// The serialized `FileDescriptorSet` of a schema this tool writes in Protobuf: a `coin_log.*` type or
/// one of the `foxglove.*` types it writes (FrameTransform, SceneUpdate, and PointCloud, VoxelGrid for Rerun).
#[must_use]
pub fn descriptor_set(schema_name: &str) -> Option<&'static [u8]> {
    use foxglove::messages::{FrameTransform, PointCloud, SceneUpdate, VoxelGrid};
    use foxglove::{Encode, Schema};
    type GetSchema = fn() -> Option<Schema>;
    const FOXGLOVE: [(&str, GetSchema); 4] = [
        (FRAME_TRANSFORM, FrameTransform::get_schema),
        (SCENE_UPDATE, SceneUpdate::get_schema),
        (POINT_CLOUD, PointCloud::get_schema),
        (VOXEL_GRID, VoxelGrid::get_schema),
    ];
    static ALL: OnceLock<Vec<(&str, Vec<u8>)>> = OnceLock::new();
    let all = ALL.get_or_init(|| {
        let coin = MESSAGE_TYPES.map(|t| (t.schema, coin_descriptor_set(&t)));
        let foxglove = FOXGLOVE
            .map(|(name, get)| (name, get().map(|s| s.data.into_owned()).unwrap_or_default()));
        coin.into_iter().chain(foxglove).collect()
    });
    let (_, data) = all.iter().find(|(name, _)| *name == schema_name)?;
    Some(data)
}

/// The file name of a `coin_log.*` type's `.proto` (in `schemas/` and in its descriptor).
#[must_use]
fn proto_file_name(schema_name: &str) -> String {
    format!("{schema_name}.proto")
}

/// protoc's JSON name of a field: lowerCamelCase of its snake_case name.
fn json_name(field: &str) -> String {
    let mut out = String::with_capacity(field.len());
    let mut upper = false;
    for c in field.chars() {
        if c == '_' {
            upper = true;
        } else if upper {
            out.extend(c.to_uppercase());
            upper = false;
        } else {
            out.push(c);
        }
    }
    out
}

/// The serialized descriptor of one `coin_log.*` type: as protoc describes its `.proto` (proto3, one
/// message of `double` fields numbered in order).
fn coin_descriptor_set(t: &MessageType) -> Vec<u8> {
    let name = t
        .schema
        .strip_prefix(PACKAGE)
        .and_then(|n| n.strip_prefix('.'))
        .unwrap_or(t.schema);
    let field = t
        .fields
        .iter()
        .zip(1..)
        .map(|(f, number)| FieldDescriptorProto {
            name: Some((*f).to_string()),
            number: Some(number),
            label: Some(Label::Optional as i32),
            r#type: Some(Type::Double as i32),
            json_name: Some(json_name(f)),
            ..FieldDescriptorProto::default()
        })
        .collect();
    FileDescriptorSet {
        file: vec![FileDescriptorProto {
            name: Some(proto_file_name(t.schema)),
            package: Some(PACKAGE.to_string()),
            message_type: vec![DescriptorProto {
                name: Some(name.to_string()),
                field,
                ..DescriptorProto::default()
            }],
            syntax: Some("proto3".to_string()),
            ..FileDescriptorProto::default()
        }],
    }
    .encode_to_vec()
}

/// A stored descriptor that cannot describe a `coin_log.*` type's messages.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[allow(missing_docs, reason = "each field is named in its variant's message")]
pub enum SchemaError {
    /// Not a serialized `FileDescriptorSet`.
    #[error("is not a serialized FileDescriptorSet: {0}")]
    NotDescriptor(String),
    /// No message type of that full name.
    #[error("declares no message `{0}`")]
    NoMessage(String),
    /// A field of the type is not declared.
    #[error("does not declare field `{0}`")]
    Missing(String),
    /// A field declared with another type or as repeated (`what` it is declared as).
    #[error("declares `{field}` as {what}, the messages have one double")]
    WrongType { field: String, what: String },
}

/// Reads `coin_log.*` messages into f64 slices by the field numbers a stored descriptor gives.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MessageDecoder {
    /// (field number, index in the field list) of the wanted fields.
    wanted: Vec<(u32, usize)>,
    /// Numbers of declared fields the messages may carry but the reader does not want (skipped).
    other: Vec<u32>,
    fields: Vec<&'static str>,
}

impl MessageDecoder {
    /// A decoder for the messages of `schema_name` as `descriptor_set` declares it, reading `fields`
    /// (which it must declare as singular doubles; it may declare more).
    pub fn new(
        descriptor_set: &[u8],
        schema_name: &str,
        fields: &[&'static str],
    ) -> Result<Self, SchemaError> {
        let set = FileDescriptorSet::decode(descriptor_set)
            .map_err(|e| SchemaError::NotDescriptor(e.to_string()))?;
        let message = set
            .file
            .iter()
            .flat_map(|f| {
                let package = f.package.as_deref().unwrap_or("");
                f.message_type.iter().map(move |m| (package, m))
            })
            .find(|(package, m)| {
                let name = m.name.as_deref().unwrap_or("");
                let full = if package.is_empty() {
                    name.to_string()
                } else {
                    format!("{package}.{name}")
                };
                full == schema_name
            })
            .map(|(_, m)| m)
            .ok_or_else(|| SchemaError::NoMessage(schema_name.to_string()))?;
        let mut wanted = Vec::with_capacity(fields.len());
        for (index, field) in fields.iter().enumerate() {
            let d = message
                .field
                .iter()
                .find(|d| d.name.as_deref() == Some(field))
                .ok_or_else(|| SchemaError::Missing((*field).to_string()))?;
            let wrong = |what: String| SchemaError::WrongType {
                field: (*field).to_string(),
                what,
            };
            if d.r#type() != Type::Double || d.label() == Label::Repeated {
                return Err(wrong(
                    format!("{:?} {:?}", d.label(), d.r#type()).to_lowercase(),
                ));
            }
            let number = u32::try_from(d.number())
                .map_err(|_| wrong(format!("field number {}", d.number())))?;
            wanted.push((number, index));
        }
        let other = message
            .field
            .iter()
            .filter_map(|d| u32::try_from(d.number()).ok())
            .filter(|n| !wanted.iter().any(|(w, _)| w == n))
            .collect();
        Ok(Self {
            wanted,
            other,
            fields: fields.to_vec(),
        })
    }

    /// Reads one message into `out` (`out.len()` = the number of fields). A field the message leaves out is
    /// 0 (proto3: a writer may omit zeros); a declared field it does not read is skipped.
    pub fn read(&self, data: &[u8], out: &mut [f64]) -> Result<(), FieldsError> {
        let bad = |what: String| FieldsError::NotProtobuf(what);
        out.iter_mut().for_each(|v| *v = 0.0);
        let mut buf = data;
        // The writer's order (1, 2, …, each once) makes the lookup start where the last one ended.
        let mut next = 0;
        while !buf.is_empty() {
            let (number, wire) = decode_key(&mut buf).map_err(|e| bad(e.to_string()))?;
            let slot = (next..self.wanted.len())
                .chain(0..next)
                .find(|&i| self.wanted[i].0 == number);
            match slot {
                Some(i) => {
                    if wire != WireType::SixtyFourBit {
                        return Err(bad(format!(
                            "field `{}` (number {number}) has wire type {wire:?}, not a 64-bit double",
                            self.fields[self.wanted[i].1]
                        )));
                    }
                    let Some((bytes, rest)) = buf.split_first_chunk::<8>() else {
                        return Err(bad(format!("ends inside field number {number}")));
                    };
                    buf = rest;
                    let v = f64::from_le_bytes(*bytes);
                    let index = self.wanted[i].1;
                    if !v.is_finite() {
                        return Err(FieldsError::NotNumber {
                            field: self.fields[index].to_string(),
                            value: v.to_string(),
                        });
                    }
                    out[index] = v;
                    next = i + 1;
                }
                None if self.other.contains(&number) => {
                    skip(wire, &mut buf).map_err(|e| bad(format!("field number {number}: {e}")))?
                }
                None => return Err(FieldsError::Unknown(format!("number {number}"))),
            }
        }
        Ok(())
    }
}

/// Skips one field value of wire type `wire`.
fn skip(wire: WireType, buf: &mut &[u8]) -> Result<(), String> {
    let take = |buf: &mut &[u8], n: usize| -> Result<(), String> {
        if buf.len() < n {
            return Err("the message ends inside it".into());
        }
        *buf = &buf[n..];
        Ok(())
    };
    match wire {
        WireType::Varint => decode_varint(buf).map(|_| ()).map_err(|e| e.to_string()),
        WireType::SixtyFourBit => take(buf, 8),
        WireType::ThirtyTwoBit => take(buf, 4),
        WireType::LengthDelimited => {
            let n = decode_varint(buf).map_err(|e| e.to_string())?;
            take(buf, usize::try_from(n).unwrap_or(usize::MAX))
        }
        WireType::StartGroup | WireType::EndGroup => Err("groups are not supported".into()),
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::format::messages::{put_double, Angles, EnergyMessage};

    /// The `.proto` text of a `coin_log.*` type from its JSON Schema: its title, description and fields in
    /// order, each a double numbered from 1.
    fn proto_text(json_schema: &[u8]) -> String {
        let v: serde_json::Value = serde_json::from_slice(json_schema).unwrap();
        let title = v["title"].as_str().unwrap();
        let name = title.strip_prefix("coin_log.").unwrap();
        let mut s = format!(
            "// {title}: the Protobuf form of schemas/{title}.json (docs/format.md: Encodings).\n\
             // Field numbers follow the JSON Schema's field order; every field is written, zeros included.\n\
             syntax = \"proto3\";\n\npackage coin_log;\n\n// {}\nmessage {name} {{\n",
            v["description"].as_str().unwrap()
        );
        let props = v["properties"].as_object().unwrap();
        let required = v["required"].as_array().unwrap();
        for (number, key) in required.iter().enumerate() {
            let key = key.as_str().unwrap();
            let doc = props[key]["description"].as_str().unwrap();
            // The JSON files' version note does not apply: every Protobuf file has every field.
            let doc = doc.replace(
                " Files written before this field was added lack it (docs/format.md: Channels and fields).",
                "",
            );
            s += &format!("  // {doc}\n  double {key} = {};\n", number + 1);
        }
        s + "}\n"
    }

    #[test]
    fn the_proto_files_in_schemas_declare_the_json_schemas_fields_in_order() {
        for t in MESSAGE_TYPES {
            let (schema, fields) = (t.schema, t.fields);
            let expected = proto_text(t.json_schema);
            let path = format!(
                "{}/../../schemas/{}",
                env!("CARGO_MANIFEST_DIR"),
                proto_file_name(schema)
            );
            if std::env::var_os("COIN_LOG_BLESS").is_some() {
                std::fs::write(&path, &expected).unwrap();
            }
            let text = std::fs::read_to_string(&path).unwrap_or_default();
            assert_eq!(
                text, expected,
                "{path} differs from its JSON Schema (COIN_LOG_BLESS=1 rewrites it)"
            );
            for (number, f) in fields.iter().enumerate() {
                assert!(
                    text.contains(&format!("  double {f} = {};\n", number + 1)),
                    "{path}: {f}"
                );
            }
        }
    }

    #[test]
    fn descriptors_decode_and_describe_every_field_as_a_numbered_double() {
        for t in MESSAGE_TYPES {
            let (schema, fields) = (t.schema, t.fields);
            let set = FileDescriptorSet::decode(descriptor_set(schema).unwrap()).unwrap();
            let file = &set.file[0];
            assert_eq!(file.syntax(), "proto3");
            assert_eq!(file.package(), PACKAGE);
            let m = &file.message_type[0];
            assert_eq!(format!("{PACKAGE}.{}", m.name()), schema);
            let names: Vec<&str> = m.field.iter().map(|f| f.name()).collect();
            assert_eq!(names, fields);
            for (f, n) in m.field.iter().zip(1..) {
                assert_eq!((f.number(), f.r#type()), (n, Type::Double), "{schema}");
            }
        }
        assert_eq!(json_name("drift_eps"), "driftEps");
        assert_eq!(json_name("t"), "t");
        for name in [FRAME_TRANSFORM, SCENE_UPDATE, POINT_CLOUD, VOXEL_GRID] {
            let set = FileDescriptorSet::decode(descriptor_set(name).unwrap()).unwrap();
            let declared = set.file.iter().any(|f| {
                f.message_type
                    .iter()
                    .any(|m| format!("{}.{}", f.package(), m.name()) == name)
            });
            assert!(declared, "{name}");
        }
        assert_eq!(descriptor_set("coin_log.Nothing"), None);
    }

    fn energy() -> MessageDecoder {
        MessageDecoder::new(
            descriptor_set(EnergyMessage::TYPE.schema).unwrap(),
            EnergyMessage::TYPE.schema,
            EnergyMessage::TYPE.fields,
        )
        .unwrap()
    }

    #[test]
    fn a_written_message_reads_back_bit_for_bit() {
        let m = EnergyMessage {
            t: 0.1,
            total: -0.0,
            kinetic: 5e-324,
            potential: f64::MAX,
            change: Some(0.0),
            drift_eps: Some(-1.5),
        };
        let mut buf = Vec::new();
        m.write_protobuf(&mut buf).unwrap();
        assert_eq!(buf.len(), 6 * 9, "every field written, zeros included");
        let mut out = [1.0; 6];
        energy().read(&buf, &mut out).unwrap();
        let back = [m.t, m.total, m.kinetic, m.potential, 0.0, -1.5];
        assert_eq!(out.map(f64::to_bits), back.map(f64::to_bits));
    }

    #[test]
    fn other_writers_forms_read_and_bad_messages_are_named() {
        let d = energy();
        let mut out = [0.0; 6];
        // Another order, zeros left out (proto3), a declared field the reader skips is absent here.
        let mut buf = Vec::new();
        put_double(&mut buf, 3, 2.0);
        put_double(&mut buf, 1, 0.5);
        d.read(&buf, &mut out).unwrap();
        assert_eq!(out, [0.5, 0.0, 2.0, 0.0, 0.0, 0.0]);
        // An undeclared field number.
        let mut extra = buf.clone();
        put_double(&mut extra, 9, 1.0);
        assert_eq!(
            d.read(&extra, &mut out),
            Err(FieldsError::Unknown("number 9".into()))
        );
        // A NaN.
        let mut nan = Vec::new();
        put_double(&mut nan, 2, f64::NAN);
        assert!(
            matches!(d.read(&nan, &mut out), Err(FieldsError::NotNumber { field, .. }) if field == "total")
        );
        // Cut inside a value, and a varint where a double belongs.
        assert!(matches!(
            d.read(&buf[..5], &mut out),
            Err(FieldsError::NotProtobuf(_))
        ));
        assert!(matches!(
            d.read(&[0x08, 0x01], &mut out),
            Err(FieldsError::NotProtobuf(_))
        ));
    }

    #[test]
    fn a_descriptor_without_the_type_or_a_field_is_refused_by_name() {
        let energy = EnergyMessage::TYPE;
        let d = descriptor_set(energy.schema).unwrap();
        assert_eq!(
            MessageDecoder::new(d, "coin_log.Angles", Angles::TYPE.fields),
            Err(SchemaError::NoMessage("coin_log.Angles".into()))
        );
        assert_eq!(
            MessageDecoder::new(d, energy.schema, &["t", "energy"]),
            Err(SchemaError::Missing("energy".into()))
        );
        assert!(matches!(
            MessageDecoder::new(b"\xff\xff", energy.schema, &["t"]),
            Err(SchemaError::NotDescriptor(_))
        ));
        // The first version's fields alone: the later ones are skipped.
        let first = MessageDecoder::new(d, energy.schema, energy.first_fields).unwrap();
        let mut buf = Vec::new();
        put_double(&mut buf, 6, 3.0);
        put_double(&mut buf, 2, 1.0);
        let mut out = [0.0; 4];
        first.read(&buf, &mut out).unwrap();
        assert_eq!(out, [0.0, 1.0, 0.0, 0.0]);
    }
}
