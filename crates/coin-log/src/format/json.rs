//! Reading the `coin_log.*` messages' JSON back (the writing side is [`super::messages`]). The fast path
//! takes the exact form the recorder writes (`{"t":0.001,"x":1.5,...}`: the schema's fields in order, no
//! whitespace); any other form falls back to serde_json (built with `float_roundtrip`), which accepts every
//! valid form and explains every error. Both round correctly, so values come back bit for bit.

use std::collections::BTreeMap;

/// Parses `data` as the object `{"fields[0]":n0,"fields[1]":n1,...}` into `out` (`out.len() ==
/// fields.len()`) and returns true, or returns false (with `out` partly written) if it has any other form.
#[must_use]
pub(crate) fn parse_numbers_into(data: &[u8], fields: &[&str], out: &mut [f64]) -> bool {
    if out.len() != fields.len() {
        return false;
    }
    let Some(mut rest) = data.strip_prefix(b"{") else {
        return false;
    };
    for (i, (field, value)) in fields.iter().zip(out.iter_mut()).enumerate() {
        let step = |rest: &[u8]| -> Option<(f64, usize)> {
            let r = if i > 0 {
                rest.strip_prefix(b",")?
            } else {
                rest
            };
            let r = r.strip_prefix(b"\"")?;
            let r = r.strip_prefix(field.as_bytes())?;
            let r = r.strip_prefix(b"\":")?;
            let (x, len) = number(r)?;
            Some((x, rest.len() - r.len() + len))
        };
        let Some((x, used)) = step(rest) else {
            return false;
        };
        *value = x;
        rest = &rest[used..];
    }
    rest == b"}"
}

/// A message that is not a flat JSON object with exactly the expected numeric fields.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[allow(missing_docs, reason = "each field is named in its variant's message")]
pub enum FieldsError {
    /// Not JSON, or not an object.
    #[error("is not a JSON object: {0}")]
    NotObject(String),
    /// A field of the schema is absent.
    #[error("has no field `{0}`")]
    Missing(String),
    /// Not a valid Protobuf message of its schema (cut short, or a field of another wire type).
    #[error("is not a valid Protobuf message of its schema: {0}")]
    NotProtobuf(String),
    /// A field the schema does not have.
    #[error("has a field `{0}` its schema does not declare")]
    Unknown(String),
    /// A field given twice (JSON leaves its value undefined; `verify` refuses it too).
    #[error("has the field `{0}` twice")]
    Repeated(String),
    /// A field whose value (as JSON) is not a finite number.
    #[error("has `{field}` = {value}, not a finite number")]
    NotNumber { field: String, value: String },
}

/// Reads the flat object `data` into `out` in the order of `fields` (`out.len() == fields.len()`),
/// whatever the order, spacing or escapes of the text: the fast path first, then serde_json. Every field
/// must be present, a finite number, and no other field may be.
pub fn read_fields(data: &[u8], fields: &[&str], out: &mut [f64]) -> Result<(), FieldsError> {
    if parse_numbers_into(data, fields, out) {
        return Ok(());
    }
    let Entries(entries) =
        serde_json::from_slice(data).map_err(|e| FieldsError::NotObject(e.to_string()))?;
    let mut object = BTreeMap::new();
    for (key, value) in entries {
        if object.contains_key(&key) {
            return Err(FieldsError::Repeated(key));
        }
        object.insert(key, value);
    }
    if let Some(extra) = object.keys().find(|k| !fields.contains(&k.as_str())) {
        return Err(FieldsError::Unknown(extra.clone()));
    }
    for (field, value) in fields.iter().zip(out.iter_mut()) {
        let v = object
            .get(*field)
            .ok_or_else(|| FieldsError::Missing((*field).to_string()))?;
        *value = v
            .as_f64()
            .filter(|x| x.is_finite())
            .ok_or_else(|| FieldsError::NotNumber {
                field: (*field).to_string(),
                value: v.to_string(),
            })?;
    }
    Ok(())
}

/// A JSON object's entries in text order, a repeated key kept (a map would keep only its last value).
struct Entries(Vec<(String, serde_json::Value)>);

impl<'de> serde::Deserialize<'de> for Entries {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Object;
        impl<'de> serde::de::Visitor<'de> for Object {
            type Value = Entries;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("a map")
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(
                self,
                mut m: A,
            ) -> Result<Entries, A::Error> {
                let mut entries = Vec::new();
                while let Some(entry) = m.next_entry()? {
                    entries.push(entry);
                }
                Ok(Entries(entries))
            }
        }
        d.deserialize_map(Object)
    }
}

/// Exact powers of ten as f64 (10²² is the largest).
const POWERS_OF_TEN: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];
/// Integers up to 2⁵³ are exact in f64.
const EXACT_INTEGER: u64 = 1 << 53;

/// The finite JSON number at the start of `s` and its length, or `None` if `s` does not start with one
/// (grammar `-?(0|[1-9][0-9]*)(\.[0-9]+)?([eE][+-]?[0-9]+)?`) or it overflows f64.
///
/// Clinger's fast path when the digits form an integer m < 2⁵³ and the power of ten is at most 10²²:
/// m and 10ᵏ are exact, so one IEEE multiplication or division rounds correctly. Otherwise the standard
/// library's correctly rounded parser reads the text (alone, it costs `verify` 6 % more CPU, measured).
fn number(s: &[u8]) -> Option<(f64, usize)> {
    let mut i = usize::from(s.first() == Some(&b'-'));
    let mut mantissa: u64 = 0;
    let mut digits = 0_usize;
    let mut scale: i64 = 0;
    let mut take = |i: &mut usize, fraction: bool| -> usize {
        let start = *i;
        while let Some(d) = s.get(*i).filter(|b| b.is_ascii_digit()) {
            if digits < 19 {
                mantissa = mantissa * 10 + u64::from(d - b'0');
                if mantissa > 0 {
                    digits += 1;
                }
                scale -= i64::from(fraction);
            } else {
                digits += 1;
                scale += i64::from(!fraction);
            }
            *i += 1;
        }
        *i - start
    };
    match s.get(i) {
        Some(b'0') => i += 1,
        Some(b'1'..=b'9') => {
            take(&mut i, false);
        }
        _ => return None,
    }
    if s.get(i) == Some(&b'.') {
        i += 1;
        if take(&mut i, true) == 0 {
            return None;
        }
    }
    let mut exponent: i64 = 0;
    if matches!(s.get(i), Some(b'e' | b'E')) {
        i += 1;
        let negative = s.get(i) == Some(&b'-');
        if matches!(s.get(i), Some(b'+' | b'-')) {
            i += 1;
        }
        let start = i;
        while let Some(d) = s.get(i).filter(|b| b.is_ascii_digit()) {
            exponent = (exponent * 10 + i64::from(d - b'0')).min(1 << 32);
            i += 1;
        }
        if i == start {
            return None;
        }
        if negative {
            exponent = -exponent;
        }
    }
    let power = scale + exponent;
    let x = if digits <= 19 && mantissa < EXACT_INTEGER && power.unsigned_abs() < 23 {
        #[allow(clippy::cast_precision_loss, clippy::cast_possible_truncation)]
        let (m, p) = (
            mantissa as f64,
            POWERS_OF_TEN[power.unsigned_abs() as usize],
        );
        let x = if power < 0 { m / p } else { m * p };
        if s.first() == Some(&b'-') {
            -x
        } else {
            x
        }
    } else {
        std::str::from_utf8(&s[..i]).ok()?.parse().ok()?
    };
    x.is_finite().then_some((x, i))
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    const F: [&str; 3] = ["t", "x", "y"];

    fn parse_numbers(data: &[u8]) -> Option<[f64; 3]> {
        let mut out = [0.0; 3];
        parse_numbers_into(data, &F, &mut out).then_some(out)
    }

    #[test]
    fn the_recorders_form_parses_bit_for_bit() {
        for x in [0.1, -2.5e-300, 1e21, 5e-324, f64::MAX, -0.0, 0.3 + 0.6] {
            let text = format!(
                "{{\"t\":1,\"x\":{},\"y\":{}}}",
                ryu::Buffer::new().format_finite(x),
                ryu::Buffer::new().format_finite(-x)
            );
            let v = parse_numbers(text.as_bytes()).unwrap();
            assert_eq!(v[1].to_bits(), x.to_bits(), "{text}");
            assert_eq!(v[2].to_bits(), (-x).to_bits(), "{text}");
        }
    }

    #[test]
    fn every_other_form_is_left_to_serde() {
        for text in [
            r#"{"t":1,"x":2}"#,
            r#"{"t":1,"x":2,"y":3,"z":4}"#,
            r#"{"t":1,"y":2,"x":3}"#,
            r#"{ "t":1,"x":2,"y":3}"#,
            r#"{"t":1,"x":2,"y":3} "#,
            r#"{"t":01,"x":2,"y":3}"#,
            r#"{"t":1.,"x":2,"y":3}"#,
            r#"{"t":.5,"x":2,"y":3}"#,
            r#"{"t":+1,"x":2,"y":3}"#,
            r#"{"t":1e,"x":2,"y":3}"#,
            r#"{"t":inf,"x":2,"y":3}"#,
            r#"{"t":NaN,"x":2,"y":3}"#,
            r#"{"t":1e999,"x":2,"y":3}"#,
            r#"{"t":"1","x":2,"y":3}"#,
            r#"{"t":null,"x":2,"y":3}"#,
            r#"{"\u0074":1,"x":2,"y":3}"#,
            r#"{"t":1,"x":2,"y":3"#,
            "",
        ] {
            assert!(parse_numbers(text.as_bytes()).is_none(), "{text}");
        }
        assert_eq!(
            parse_numbers(br#"{"t":-0.5E+2,"x":0,"y":12e-1}"#),
            Some([-50.0, 0.0, 1.2])
        );
    }

    #[test]
    fn read_fields_accepts_any_valid_form_exactly_and_names_what_is_wrong() {
        let fields = ["t", "x", "y"];
        let mut out = [0.0; 3];
        // Another order, spaces, an escaped key and a 17-digit number: the slow path, bit for bit.
        let x: f64 = 0.1 + 0.2;
        let text = format!(
            "{{ \"y\" : -1e-300, \"\\u0074\": 2.5, \"x\": {} }}",
            ryu::Buffer::new().format_finite(x)
        );
        read_fields(text.as_bytes(), &fields, &mut out).unwrap();
        assert_eq!(out[0].to_bits(), 2.5_f64.to_bits());
        assert_eq!(out[1].to_bits(), x.to_bits(), "{text}");
        assert_eq!(out[2].to_bits(), (-1e-300_f64).to_bits());
        for (text, expected) in [
            (r#"{"t":1,"x":2}"#, FieldsError::Missing("y".into())),
            (
                r#"{"t":1,"x":2,"y":3,"w":4}"#,
                FieldsError::Unknown("w".into()),
            ),
            (
                r#"{"t":1,"x":5,"x":2,"y":3}"#,
                FieldsError::Repeated("x".into()),
            ),
            (
                r#"{"t":1,"x":2,"y":3,"\u0074":1}"#,
                FieldsError::Repeated("t".into()),
            ),
            (
                r#"{"t":1,"x":"2","y":3}"#,
                FieldsError::NotNumber {
                    field: "x".into(),
                    value: "\"2\"".into(),
                },
            ),
        ] {
            assert_eq!(
                read_fields(text.as_bytes(), &fields, &mut out),
                Err(expected),
                "{text}"
            );
        }
        assert!(matches!(
            read_fields(b"[1,2,3]", &fields, &mut out),
            Err(FieldsError::NotObject(_))
        ));
    }
}
