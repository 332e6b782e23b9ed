//! Opening a chunk: its records decompressed within limits and checked against the chunk's CRC
//! before any of them is parsed or handed on. A chunk may claim at most what its compressed bytes
//! could decompress to (zstd's largest ratio) and never more than [`MAX_CHUNK_BYTES`], so a
//! flipped bit in a size is an error, not an allocation; the output buffer grows with what is
//! actually decompressed, never with what is claimed.

use std::borrow::Cow;
use std::io::Read;

use mcap::records::ChunkHeader;

use crate::damage::Damage;
use crate::records::guarded;

/// The most a chunk may decompress to, whatever it claims: a chunk is ~4 MiB
/// (`writer.rs`), one bigger only holds one message bigger than that.
pub const MAX_CHUNK_BYTES: u64 = 1 << 30;

/// zstd's largest ratio: a 128 KiB block from 4 bytes (an RLE block's header and byte).
const MAX_ZSTD_RATIO: u64 = 32 * 1024;

/// What the output buffer starts at, before it grows with what is decompressed.
const FIRST_RESERVE: u64 = 8 << 20;

/// A chunk's records, decompressed and checked against its CRC. The bytes come back borrowed
/// from `data` when the chunk is not compressed. A CRC of 0 is "not computed" (the MCAP
/// specification); [`Opened::verified`] says whether it was checked.
pub(crate) fn open<'a>(header: &ChunkHeader, data: &'a [u8]) -> Result<Opened<'a>, Damage> {
    let (claims, compressed) = (header.uncompressed_size, data.len() as u64);
    let records: Cow<'a, [u8]> = match header.compression.as_str() {
        "" if claims == compressed => Cow::Borrowed(data),
        "" => return Err(Damage::ChunkSize { claims, got: compressed }),
        "zstd" => {
            let cap = MAX_CHUNK_BYTES.min(compressed.saturating_mul(MAX_ZSTD_RATIO));
            if claims > cap {
                return Err(Damage::ChunkTooLarge { claims, compressed, cap });
            }
            Cow::Owned(guarded(|| unzstd(data, claims), Damage::Decompress)?)
        }
        other => return Err(Damage::Compression(other.to_owned())),
    };
    let saved = header.uncompressed_crc;
    if saved != 0 {
        let calculated = crc32fast::hash(&records);
        if calculated != saved {
            return Err(Damage::ChunkCrc { saved, calculated });
        }
    }
    Ok(Opened { records, verified: saved != 0 })
}

/// A chunk's records, and whether a CRC vouched for them.
pub(crate) struct Opened<'a> {
    pub records: Cow<'a, [u8]>,
    pub verified: bool,
}

impl Opened<'_> {
    pub fn into_owned(self) -> Opened<'static> {
        Opened { records: Cow::Owned(self.records.into_owned()), verified: self.verified }
    }
}

/// Decompresses `data`, which must come to exactly `claims` bytes (at most `claims + 1` are
/// decompressed, to tell).
fn unzstd(data: &[u8], claims: u64) -> Result<Vec<u8>, Damage> {
    let decoder =
        zstd::stream::read::Decoder::with_buffer(data).map_err(|e| Damage::Decompress(e.to_string()))?;
    let mut out = Vec::with_capacity(claims.min(FIRST_RESERVE) as usize);
    decoder.take(claims + 1).read_to_end(&mut out).map_err(|e| Damage::Decompress(e.to_string()))?;
    let got = out.len() as u64;
    if got != claims {
        return Err(Damage::ChunkSize { claims, got });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header(compression: &str, uncompressed_size: u64, records: &[u8]) -> ChunkHeader {
        ChunkHeader {
            message_start_time: 0,
            message_end_time: 0,
            uncompressed_size,
            uncompressed_crc: crc32fast::hash(records),
            compression: compression.into(),
            compressed_size: 0,
        }
    }

    #[test]
    fn a_chunk_opens_only_as_the_size_and_crc_it_claims() {
        let records = vec![7u8; 10_000];
        let data = zstd::encode_all(&records[..], 3).expect("compress");
        let h = header("zstd", 10_000, &records);
        let opened = open(&h, &data).expect("intact");
        assert_eq!((&opened.records[..], opened.verified), (&records[..], true));

        let flipped = ChunkHeader { uncompressed_crc: h.uncompressed_crc ^ 1, ..h.clone() };
        assert!(matches!(open(&flipped, &data), Err(Damage::ChunkCrc { .. })));
        let unchecked = ChunkHeader { uncompressed_crc: 0, ..h.clone() };
        assert!(!open(&unchecked, &data).expect("no CRC to check").verified);
        let short = ChunkHeader { uncompressed_size: 9_999, ..h.clone() };
        assert!(matches!(open(&short, &data), Err(Damage::ChunkSize { claims: 9_999, got: 10_000 })));
        let long = ChunkHeader { uncompressed_size: 10_001, ..h.clone() };
        assert!(matches!(open(&long, &data), Err(Damage::ChunkSize { claims: 10_001, got: 10_000 })));
        let huge = ChunkHeader { uncompressed_size: 8_900_000_000_000_000_000, ..h.clone() };
        assert!(matches!(open(&huge, &data), Err(Damage::ChunkTooLarge { .. })));
        assert!(matches!(
            open(&h, &data[..data.len() / 2]),
            Err(Damage::Decompress(_) | Damage::ChunkSize { .. })
        ));
        assert!(matches!(open(&header("lz4", 1, b"x"), b"x"), Err(Damage::Compression(_))));
        let plain = open(&header("", 3, b"abc"), b"abc").expect("uncompressed");
        assert!(matches!(plain.records, Cow::Borrowed(b"abc")));
    }
}
