//! Bounds-checked parsing of MCAP record bodies (<https://mcap.dev/spec>), without allocation.
//!
//! The mcap crate's record parsers trust length prefixes inside a record (a string may claim 4 GB and the
//! parser reserves it before reading); these read only what the record holds and borrow from it, so a
//! crafted record can never make the reader allocate more than the record's own bytes.

use std::fmt;

/// The MCAP magic, at the start and at the end of every file.
pub(crate) const MAGIC: [u8; 8] = [0x89, b'M', b'C', b'A', b'P', b'0', b'\r', b'\n'];

/// A record body that ends before a field it declares.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct WireError {
    /// The field being read.
    pub(crate) field: &'static str,
    /// Bytes it needed.
    pub(crate) needed: u64,
    /// Bytes left in the record.
    pub(crate) available: u64,
}

impl fmt::Display for WireError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "field `{}` needs {} bytes but the record has {} left",
            self.field, self.needed, self.available
        )
    }
}

/// A cursor over one record body.
#[derive(Debug, Clone)]
pub(crate) struct Cursor<'a> {
    data: &'a [u8],
}

impl<'a> Cursor<'a> {
    /// A cursor at the start of `data`.
    #[must_use]
    pub(crate) fn new(data: &'a [u8]) -> Self {
        Self { data }
    }

    /// Bytes not read yet.
    #[must_use]
    pub(crate) fn rest(&self) -> &'a [u8] {
        self.data
    }

    /// Takes `n` bytes.
    ///
    /// # Errors
    /// [`WireError`] if fewer are left.
    pub(crate) fn take(&mut self, n: u64, field: &'static str) -> Result<&'a [u8], WireError> {
        let err = WireError {
            field,
            needed: n,
            available: self.data.len() as u64,
        };
        let n = usize::try_from(n).map_err(|_| err)?;
        if n > self.data.len() {
            return Err(err);
        }
        let (head, tail) = self.data.split_at(n);
        self.data = tail;
        Ok(head)
    }

    fn array<const N: usize>(&mut self, field: &'static str) -> Result<[u8; N], WireError> {
        let bytes = self.take(N as u64, field)?;
        let mut out = [0u8; N];
        out.copy_from_slice(bytes);
        Ok(out)
    }

    /// A little-endian u8.
    ///
    /// # Errors
    /// [`WireError`] at the end of the record.
    pub(crate) fn u8(&mut self, field: &'static str) -> Result<u8, WireError> {
        Ok(self.array::<1>(field)?[0])
    }

    /// A little-endian u16.
    ///
    /// # Errors
    /// [`WireError`] at the end of the record.
    pub(crate) fn u16(&mut self, field: &'static str) -> Result<u16, WireError> {
        Ok(u16::from_le_bytes(self.array(field)?))
    }

    /// A little-endian u32.
    ///
    /// # Errors
    /// [`WireError`] at the end of the record.
    pub(crate) fn u32(&mut self, field: &'static str) -> Result<u32, WireError> {
        Ok(u32::from_le_bytes(self.array(field)?))
    }

    /// A little-endian u64.
    ///
    /// # Errors
    /// [`WireError`] at the end of the record.
    pub(crate) fn u64(&mut self, field: &'static str) -> Result<u64, WireError> {
        Ok(u64::from_le_bytes(self.array(field)?))
    }

    /// A u32-length-prefixed byte string.
    ///
    /// # Errors
    /// [`WireError`] if the prefix claims more than the record holds.
    pub(crate) fn bytes(&mut self, field: &'static str) -> Result<&'a [u8], WireError> {
        let len = self.u32(field)?;
        self.take(u64::from(len), field)
    }

    /// A u32-length-prefixed string; invalid UTF-8 is replaced by `None`.
    ///
    /// # Errors
    /// [`WireError`] if the prefix claims more than the record holds.
    pub(crate) fn string(&mut self, field: &'static str) -> Result<Option<&'a str>, WireError> {
        Ok(std::str::from_utf8(self.bytes(field)?).ok())
    }
}

/// The fixed part of a message record (the data follows it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MessageHeader {
    /// Channel id.
    pub channel_id: u16,
    /// Sequence number.
    pub sequence: u32,
    /// Log time \[ns\].
    pub log_time: u64,
    /// Publish time \[ns\].
    pub publish_time: u64,
}

/// Splits a message record into its header and data.
///
/// # Errors
/// [`WireError`] if the record is shorter than a message header.
pub(crate) fn message(body: &[u8]) -> Result<(MessageHeader, &[u8]), WireError> {
    let mut c = Cursor::new(body);
    let header = MessageHeader {
        channel_id: c.u16("channel_id")?,
        sequence: c.u32("sequence")?,
        log_time: c.u64("log_time")?,
        publish_time: c.u64("publish_time")?,
    };
    Ok((header, c.rest()))
}

/// The header of a chunk record.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct ChunkHeader<'a> {
    /// Earliest message log time.
    pub(crate) message_start_time: u64,
    /// Latest message log time.
    pub(crate) message_end_time: u64,
    /// Size of the records once decompressed.
    pub(crate) uncompressed_size: u64,
    /// CRC-32 of the decompressed records (0: none).
    pub(crate) uncompressed_crc: u32,
    /// Compression name ("" for none).
    pub(crate) compression: &'a [u8],
    /// Size of the compressed records.
    pub(crate) compressed_size: u64,
}

/// Parses a chunk header and checks that the compressed records fit in the record.
///
/// # Errors
/// [`WireError`] if a field or the compressed records run past the record.
pub(crate) fn chunk_header(body: &[u8]) -> Result<ChunkHeader<'_>, WireError> {
    let mut c = Cursor::new(body);
    let header = ChunkHeader {
        message_start_time: c.u64("message_start_time")?,
        message_end_time: c.u64("message_end_time")?,
        uncompressed_size: c.u64("uncompressed_size")?,
        uncompressed_crc: c.u32("uncompressed_crc")?,
        compression: c.bytes("compression")?,
        compressed_size: c.u64("compressed_size")?,
    };
    c.take(header.compressed_size, "records")?;
    Ok(header)
}

/// Iterates over a u32-byte-length-prefixed map or array whose entries `read` parses.
///
/// # Errors
/// [`WireError`] if the prefix or an entry runs past the record.
pub(crate) fn for_each_entry<'a>(
    c: &mut Cursor<'a>,
    field: &'static str,
    mut read: impl FnMut(&mut Cursor<'a>) -> Result<(), WireError>,
) -> Result<(), WireError> {
    let mut inner = Cursor::new(c.bytes(field)?);
    while !inner.rest().is_empty() {
        read(&mut inner)?;
    }
    Ok(())
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn a_string_claiming_more_than_the_record_is_an_error_not_an_allocation() {
        let mut body = u32::MAX.to_le_bytes().to_vec();
        body.extend_from_slice(b"abc");
        let err = Cursor::new(&body).string("name").unwrap_err();
        assert_eq!((err.needed, err.available), (u64::from(u32::MAX), 3));
    }

    #[test]
    fn a_message_header_is_split_from_its_data() {
        let mut body = vec![7, 0, 1, 0, 0, 0];
        body.extend_from_slice(&5u64.to_le_bytes());
        body.extend_from_slice(&6u64.to_le_bytes());
        body.extend_from_slice(b"{}");
        let (h, data) = message(&body).unwrap();
        assert_eq!(
            (h.channel_id, h.sequence, h.log_time, h.publish_time),
            (7, 1, 5, 6)
        );
        assert_eq!(data, b"{}");
    }
}
