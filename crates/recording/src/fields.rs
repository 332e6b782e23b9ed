//! The length fields inside an MCAP record, checked against the record's own end before the mcap
//! crate parses it: mcap reserves a string's claimed length before reading it (a flipped bit in
//! one is a 4 GiB allocation) and slices an attachment's CRC without checking that it is there.
//! The walk follows the MCAP specification's layout of each record, field by field, in the order
//! mcap reads them; records without length fields need no check.

use mcap::records::op;

use crate::damage::Damage;

/// A cursor over a record body that never reads past it.
struct Fields<'a> {
    body: &'a [u8],
    at: usize,
    opcode: u8,
}

impl Fields<'_> {
    fn damage(&self) -> Damage {
        Damage::Field { opcode: self.opcode, at: self.at }
    }

    /// Steps over `n` bytes, which must be there.
    fn skip(&mut self, n: u64) -> Result<(), Damage> {
        let left = (self.body.len() - self.at) as u64;
        if n > left {
            return Err(self.damage());
        }
        self.at += n as usize;
        Ok(())
    }

    fn int<const N: usize>(&mut self) -> Result<u64, Damage> {
        let bytes = self.body.get(self.at..self.at + N).ok_or_else(|| self.damage())?;
        let mut le = [0u8; 8];
        le[..N].copy_from_slice(bytes);
        self.at += N;
        Ok(u64::from_le_bytes(le))
    }

    /// A `uint32` length and that many bytes (a string, or a schema's data).
    fn bytes_u32(&mut self) -> Result<(), Damage> {
        let field = self.at;
        let n = self.int::<4>()?;
        self.skip(n).map_err(|_| Damage::Field { opcode: self.opcode, at: field })
    }

    /// A `uint64` length and that many bytes (a chunk's records, an attachment's data).
    fn bytes_u64(&mut self) -> Result<(), Damage> {
        let field = self.at;
        let n = self.int::<8>()?;
        self.skip(n).map_err(|_| Damage::Field { opcode: self.opcode, at: field })
    }

    /// A map of strings to strings: its `uint32` byte length, then pairs while the pairs read so
    /// far are shorter than it (as mcap reads it).
    fn string_map(&mut self) -> Result<(), Damage> {
        let length = self.int::<4>()?;
        let start = self.at;
        while ((self.at - start) as u64) < length {
            self.bytes_u32()?;
            self.bytes_u32()?;
        }
        Ok(())
    }

    /// A map of fixed-size keys to fixed-size values (`pair` bytes each), as [`Self::string_map`].
    fn int_map(&mut self, pair: u64) -> Result<(), Damage> {
        let length = self.int::<4>()?;
        let start = self.at;
        while ((self.at - start) as u64) < length {
            self.skip(pair)?;
        }
        Ok(())
    }
}

/// Checks that every length field of the `opcode` record `body` stays inside it.
pub(crate) fn check(opcode: u8, body: &[u8]) -> Result<(), Damage> {
    let mut f = Fields { body, at: 0, opcode };
    match opcode {
        op::HEADER => {
            f.bytes_u32()?; // profile
            f.bytes_u32()?; // library
        }
        op::SCHEMA => {
            f.skip(2)?; // id
            f.bytes_u32()?; // name
            f.bytes_u32()?; // encoding
            f.bytes_u32()?; // data
        }
        op::CHANNEL => {
            f.skip(2 + 2)?; // id, schema id
            f.bytes_u32()?; // topic
            f.bytes_u32()?; // message encoding
            f.string_map()?; // metadata
        }
        op::CHUNK => {
            f.skip(8 + 8 + 8 + 4)?; // start and end times, uncompressed size and CRC
            f.bytes_u32()?; // compression
            f.bytes_u64()?; // records
        }
        op::CHUNK_INDEX => {
            f.skip(8 + 8 + 8 + 8)?; // times, chunk start offset and length
            f.int_map(2 + 8)?; // message index offsets
            f.skip(8)?; // message index length
            f.bytes_u32()?; // compression
            f.skip(8 + 8)?; // compressed and uncompressed sizes
        }
        op::ATTACHMENT => {
            f.skip(8 + 8)?; // log and create times
            f.bytes_u32()?; // name
            f.bytes_u32()?; // media type
            f.bytes_u64()?; // data
            f.skip(4)?; // CRC
        }
        op::ATTACHMENT_INDEX => {
            f.skip(8 + 8 + 8 + 8 + 8)?; // offset, length, times, data size
            f.bytes_u32()?; // name
            f.bytes_u32()?; // media type
        }
        op::STATISTICS => {
            f.skip(8 + 2 + 4 * 4 + 8 + 8)?; // counts, start and end times
            f.int_map(2 + 8)?; // channel message counts
        }
        op::METADATA => {
            f.bytes_u32()?; // name
            f.string_map()?; // metadata
        }
        op::METADATA_INDEX => {
            f.skip(8 + 8)?; // offset, length
            f.bytes_u32()?; // name
        }
        // Fixed-size fields, or arrays read element by element (message indexes): a short
        // record is an error of mcap's, never an allocation.
        _ => {}
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn string(s: &str) -> Vec<u8> {
        let mut out = (s.len() as u32).to_le_bytes().to_vec();
        out.extend_from_slice(s.as_bytes());
        out
    }

    #[test]
    fn a_string_longer_than_its_record_is_caught_before_mcap_reserves_it() {
        let mut header = [string("ros2"), string("harvey")].concat();
        assert!(check(op::HEADER, &header).is_ok());
        header[8..12].copy_from_slice(&u32::MAX.to_le_bytes()); // the library's length
        let e = check(op::HEADER, &header).expect_err("past the end").to_string();
        assert_eq!(e, "record 0x01: a length field at byte 8 of it runs past its end");
    }

    #[test]
    fn a_map_is_walked_pair_by_pair_as_mcap_reads_it() {
        let pairs = [string("k"), string("v")].concat();
        let map = |length: u32| [string("name"), length.to_le_bytes().to_vec(), pairs.clone()].concat();
        assert!(check(op::METADATA, &map(pairs.len() as u32)).is_ok());
        assert!(check(op::METADATA, &map(0)).is_ok(), "an empty map, then bytes mcap does not read");
        assert!(check(op::METADATA, &map(pairs.len() as u32 + 1)).is_err(), "a pair past the end");
        assert!(check(op::METADATA, &map(7)[..12]).is_err(), "cut inside the map");
    }
}
