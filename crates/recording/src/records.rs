//! Walking the records of MCAP bytes (a file, or a chunk's decompressed records) without trusting
//! them: a record's length is checked against the bytes left before it is sliced, its length
//! fields against its own end (`fields.rs`) before the mcap crate parses it, and a panic inside
//! mcap is caught and turned into [`Damage`]. Every reader of the crate parses records through
//! here.

use std::panic::{AssertUnwindSafe, catch_unwind};

use mcap::records::{Record, op};

use crate::damage::Damage;

/// A record's opcode (1 byte) and length (8 bytes, little-endian) before its body.
pub(crate) const OPCODE_AND_LENGTH: usize = 1 + 8;

/// One record of a byte range, its length checked.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Raw<'a> {
    /// Where it starts in the walked bytes.
    pub offset: usize,
    pub opcode: u8,
    pub body: &'a [u8],
    /// Where the next record starts.
    pub end: usize,
}

impl<'a> Raw<'a> {
    /// The record parsed by mcap, once its length fields are checked.
    pub fn parse(&self) -> Result<Record<'a>, Damage> {
        parse(self.opcode, self.body)
    }
}

/// The record at `offset` of `bytes`: an error when fewer bytes are left than its opcode and
/// length need, or than its length claims.
pub(crate) fn record_at(bytes: &[u8], offset: usize) -> Result<Raw<'_>, Damage> {
    let rest = bytes.get(offset..).unwrap_or_default();
    let left = rest.len() as u64;
    let (Some(&opcode), Some(length)) = (rest.first(), rest.get(1..OPCODE_AND_LENGTH)) else {
        return Err(Damage::Cut { left });
    };
    let mut le = [0u8; 8];
    le.copy_from_slice(length);
    let claims = u64::from_le_bytes(le);
    let body_left = left - OPCODE_AND_LENGTH as u64;
    if claims > body_left {
        return Err(Damage::PastEnd { opcode, claims, left: body_left });
    }
    // `claims` is at most what is left of a slice, so it fits a usize.
    let start = offset + OPCODE_AND_LENGTH;
    let end = start + claims as usize;
    Ok(Raw { offset, opcode, body: &bytes[start..end], end })
}

/// Parses a record body with mcap, after checking that its length fields stay inside it (so that
/// no length makes mcap allocate more than the record holds); a panic inside mcap is damage.
pub(crate) fn parse(opcode: u8, body: &[u8]) -> Result<Record<'_>, Damage> {
    crate::fields::check(opcode, body)?;
    match catch_unwind(|| mcap::parse_record(opcode, body)) {
        Ok(Ok(record)) => Ok(record),
        Ok(Err(cause)) => Err(Damage::Parse { opcode, cause }),
        Err(panic) => Err(Damage::Panicked { opcode, message: panic_message(panic.as_ref()) }),
    }
}

/// Runs `f` (a call into a decoder) with its panics turned into [`Damage`] by `on_panic`.
pub(crate) fn guarded<T>(
    f: impl FnOnce() -> Result<T, Damage>,
    on_panic: impl FnOnce(String) -> Damage,
) -> Result<T, Damage> {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or_else(|panic| Err(on_panic(panic_message(panic.as_ref()))))
}

/// What a caught panic said.
fn panic_message(panic: &(dyn std::any::Any + Send)) -> String {
    panic
        .downcast_ref::<&str>()
        .map(|s| (*s).to_owned())
        .or_else(|| panic.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "a panic".to_owned())
}

/// The top-level records of the data section, in order, up to its data end record (included);
/// a record that runs past the file ends them with its offset and damage.
pub(crate) struct DataSection<'a> {
    bytes: &'a [u8],
    at: usize,
    done: bool,
}

impl<'a> DataSection<'a> {
    pub fn new(bytes: &'a [u8]) -> Self {
        Self { bytes, at: mcap::MAGIC.len(), done: false }
    }
}

impl<'a> Iterator for DataSection<'a> {
    type Item = Result<Raw<'a>, (usize, Damage)>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        let at = self.at;
        if at >= self.bytes.len() {
            self.done = true;
            return Some(Err((at, Damage::NoDataEnd)));
        }
        match record_at(self.bytes, at) {
            Ok(raw) => {
                self.at = raw.end;
                self.done = raw.opcode == op::DATA_END;
                Some(Ok(raw))
            }
            Err(what) => {
                self.done = true;
                Some(Err((at, what)))
            }
        }
    }
}

/// Checks the data section's CRC (in its data end record; 0 is "not computed"): what vouches for
/// the records without a CRC of their own (metadata, message indexes).
pub(crate) fn check_data_crc(bytes: &[u8]) -> Result<(), (usize, Damage)> {
    for raw in DataSection::new(bytes) {
        let raw = raw?;
        if raw.opcode == op::DATA_END {
            let Record::DataEnd(end) = raw.parse().map_err(|what| (raw.offset, what))? else { continue };
            let (saved, calculated) = (end.data_section_crc, crc32fast::hash(&bytes[..raw.offset]));
            if saved != 0 && saved != calculated {
                return Err((raw.offset, Damage::DataCrc { saved, calculated }));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(opcode: u8, claims: u64, body: &[u8]) -> Vec<u8> {
        let mut out = vec![opcode];
        out.extend_from_slice(&claims.to_le_bytes());
        out.extend_from_slice(body);
        out
    }

    #[test]
    fn a_length_past_the_bytes_left_is_damage_not_a_slice() {
        let ok = record(op::DATA_END, 4, &[1, 2, 3, 4]);
        let raw = record_at(&ok, 0).expect("fits");
        assert_eq!((raw.opcode, raw.body, raw.end), (op::DATA_END, &[1u8, 2, 3, 4][..], 13));
        let long = record(op::MESSAGE, 8_900_000_000_000_000_000, &[0; 30]);
        let e = record_at(&long, 0).expect_err("claims too much").to_string();
        assert_eq!(e, "record 0x05 claims 8900000000000000000 bytes, 30 are left");
        assert!(matches!(record_at(&ok[..5], 0), Err(Damage::Cut { left: 5 })));
        assert!(matches!(record_at(&ok, 13), Err(Damage::Cut { left: 0 })));
        assert!(matches!(record_at(&ok, 99), Err(Damage::Cut { left: 0 })));
    }

    #[test]
    fn an_attachment_too_short_for_its_crc_is_damage_where_mcap_would_panic() {
        // Name and media type empty, data length 0, and no room for the CRC: mcap slices
        // `body[header_len..body.len() - 4]` with the start past the end.
        let mut body = vec![0u8; 16];
        body.extend_from_slice(&[0; 8]); // two empty strings
        body.extend_from_slice(&0u64.to_le_bytes());
        assert!(matches!(parse(op::ATTACHMENT, &body), Err(Damage::Field { opcode: op::ATTACHMENT, .. })));
        body.extend_from_slice(&[0; 4]);
        assert!(matches!(parse(op::ATTACHMENT, &body), Ok(Record::Attachment { .. })));
    }

    #[test]
    fn a_caught_panic_is_damage_naming_what_it_said() {
        let e = guarded::<()>(|| panic!("boom"), Damage::Decompress).expect_err("caught");
        assert_eq!(e.to_string(), "chunk does not decompress: boom");
    }
}
