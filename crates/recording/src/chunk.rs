//! Opening a chunk: its records decompressed within limits and checked against the chunk's CRC
//! before any of them is parsed or handed on. A chunk may claim at most what its compressed bytes
//! could decompress to (the codec's largest ratio) and never more than [`MAX_CHUNK_BYTES`], so a
//! flipped bit in a size is an error that costs at most one allocation of 64 MiB: a zstd chunk
//! claiming up to that is decompressed in one call into a buffer of its claimed size (a chunk is
//! ~4 MiB), past that the output buffer grows with what is actually decompressed, never with what
//! is claimed.

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

/// Above LZ4's largest ratio: a match of any length costs at least one more byte per 255 it
/// covers.
const MAX_LZ4_RATIO: u64 = 300;

/// What the output buffer starts at, before it grows with what is decompressed.
const FIRST_RESERVE: u64 = 8 << 20;

/// A chunk's records, decompressed and checked against its CRC. The bytes come back borrowed
/// from `data` when the chunk is not compressed. A CRC of 0 is "not computed" (the MCAP
/// specification); [`Opened::verified`] says whether it was checked.
pub(crate) fn open<'a>(header: &ChunkHeader, data: &'a [u8]) -> Result<Opened<'a>, Damage> {
    Unpacker::default().open(header, data)
}

/// Opens chunk after chunk with one zstd context and one output buffer: a reader's chunks
/// (about 4 MiB each, `writer.rs`) are decompressed straight into the buffer the last chunk's
/// records were in ([`Unpacker::give_back`]), not each into fresh pages through a fresh context
/// and a stream's window.
#[derive(Default)]
pub(crate) struct Unpacker {
    zstd: Option<zstd::bulk::Decompressor<'static>>,
    spare: Vec<u8>,
}

/// A zstd chunk claiming at most this much is decompressed in one call into a buffer of the
/// claimed size; a larger claim (one message bigger than a chunk, or a flipped bit in the size)
/// is streamed into a buffer that grows with what actually comes out.
const BULK_MAX_BYTES: u64 = 64 << 20;

impl Unpacker {
    /// [`open`], reusing this unpacker's context and buffer.
    pub fn open<'a>(&mut self, header: &ChunkHeader, data: &'a [u8]) -> Result<Opened<'a>, Damage> {
        let (claims, compressed) = (header.uncompressed_size, data.len() as u64);
        let records: Cow<'a, [u8]> = match header.compression.as_str() {
            "" if claims == compressed => Cow::Borrowed(data),
            "" => return Err(Damage::ChunkSize { claims, got: compressed }),
            "zstd" => {
                within(claims, compressed, MAX_ZSTD_RATIO)?;
                Cow::Owned(guarded(|| self.unzstd(data, claims), Damage::Decompress)?)
            }
            "lz4" => {
                within(claims, compressed, MAX_LZ4_RATIO)?;
                Cow::Owned(guarded(|| unlz4(data, claims), Damage::Decompress)?)
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

    /// Takes back the buffer of a chunk's records read out, for the next chunk.
    pub fn give_back(&mut self, records: Vec<u8>) {
        // A buffer a streamed chunk grew past the one-call limit is not kept.
        let fits = records.capacity() as u64 <= BULK_MAX_BYTES + 1;
        if fits && records.capacity() > self.spare.capacity() {
            self.spare = records;
        }
    }

    /// Decompresses zstd `data`, which must come to exactly `claims` bytes: in one call when the
    /// claim is small enough to allocate, else (or to tell how much more there is) streamed.
    fn unzstd(&mut self, data: &[u8], claims: u64) -> Result<Vec<u8>, Damage> {
        if claims > BULK_MAX_BYTES {
            return unzstd(data, claims);
        }
        let mut out = std::mem::take(&mut self.spare);
        out.clear();
        out.reserve_exact(claims as usize + 1);
        let zstd = match &mut self.zstd {
            Some(z) => z,
            None => self
                .zstd
                .insert(zstd::bulk::Decompressor::new().map_err(|e| Damage::Decompress(e.to_string()))?),
        };
        match zstd.decompress_to_buffer(data, &mut out) {
            Ok(got) if got as u64 == claims => Ok(out),
            Ok(got) => Err(Damage::ChunkSize { claims, got: got as u64 }),
            // More than the buffer holds, or damage: the stream says which, and how much.
            Err(_) => unzstd(data, claims),
        }
    }
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

/// Refuses a claimed size that `compressed` bytes of a codec of `max_ratio` cannot reach.
fn within(claims: u64, compressed: u64, max_ratio: u64) -> Result<(), Damage> {
    let cap = MAX_CHUNK_BYTES.min(compressed.saturating_mul(max_ratio));
    if claims > cap {
        return Err(Damage::ChunkTooLarge { claims, compressed, cap });
    }
    Ok(())
}

/// Decompresses zstd `data`, which must come to exactly `claims` bytes.
fn unzstd(data: &[u8], claims: u64) -> Result<Vec<u8>, Damage> {
    let decoder =
        zstd::stream::read::Decoder::with_buffer(data).map_err(|e| Damage::Decompress(e.to_string()))?;
    read_exactly(decoder, claims)
}

/// Decompresses an LZ4 frame, which must come to exactly `claims` bytes.
fn unlz4(data: &[u8], claims: u64) -> Result<Vec<u8>, Damage> {
    let decoder = lz4::Decoder::new(data).map_err(|e| Damage::Decompress(e.to_string()))?;
    read_exactly(decoder, claims)
}

/// Reads `decoder` out, which must give exactly `claims` bytes (at most `claims + 1` are
/// decompressed, to tell).
fn read_exactly(decoder: impl Read, claims: u64) -> Result<Vec<u8>, Damage> {
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
        assert!(matches!(open(&header("brotli", 1, b"x"), b"x"), Err(Damage::Compression(_))));
        let plain = open(&header("", 3, b"abc"), b"abc").expect("uncompressed");
        assert!(matches!(plain.records, Cow::Borrowed(b"abc")));
    }

    #[test]
    fn one_unpacker_opens_chunk_after_chunk_in_the_buffer_it_was_given_back() {
        let mut u = Unpacker::default();
        let big: Vec<u8> = (0..300_000u32).map(|i| (i % 253) as u8).collect();
        let small: Vec<u8> = (0..5_000u32).map(|i| (i % 7) as u8).collect();
        let (zb, zs) =
            (zstd::encode_all(&big[..], 3).expect("big"), zstd::encode_all(&small[..], 3).expect("small"));
        let opened = u.open(&header("zstd", big.len() as u64, &big), &zb).expect("big chunk");
        assert_eq!(&opened.records[..], &big[..]);
        let Cow::Owned(records) = opened.records else { panic!("decompressed into its own buffer") };
        let reused = records.as_ptr();
        u.give_back(records);
        let opened = u.open(&header("zstd", small.len() as u64, &small), &zs).expect("small chunk");
        assert_eq!(&opened.records[..], &small[..]);
        assert_eq!(opened.records.as_ptr(), reused, "the buffer given back");
        // The buffer holds more than the claim: what comes out beyond it is still caught.
        let Cow::Owned(records) = opened.records else { panic!("owned") };
        u.give_back(records);
        let short = header("zstd", small.len() as u64 - 1, &small);
        assert!(matches!(u.open(&short, &zs), Err(Damage::ChunkSize { got: 5_000, .. })));
        assert!(u.open(&header("zstd", 10, &small), &zs[..zs.len() / 2]).is_err(), "a cut frame");
        let again = u.open(&header("zstd", big.len() as u64, &big), &zb).expect("big again");
        assert_eq!(&again.records[..], &big[..]);
    }

    fn lz4(records: &[u8]) -> Vec<u8> {
        let mut enc = lz4::EncoderBuilder::new().build(Vec::new()).expect("lz4 encoder");
        std::io::Write::write_all(&mut enc, records).expect("compress");
        let (data, result) = enc.finish();
        result.expect("lz4 frame");
        data
    }

    #[test]
    fn an_lz4_chunk_opens_within_the_same_limits() {
        let records: Vec<u8> = (0..100_000u32).map(|i| (i % 251) as u8).collect();
        let data = lz4(&records);
        let h = header("lz4", records.len() as u64, &records);
        assert_eq!(&open(&h, &data).expect("intact").records[..], &records[..]);
        let zeros = vec![0u8; 4 << 20];
        let packed = lz4(&zeros);
        assert!(open(&header("lz4", zeros.len() as u64, &zeros), &packed).is_ok(), "its best ratio");
        let huge = ChunkHeader { uncompressed_size: 1 << 29, ..h.clone() };
        assert!(matches!(open(&huge, &data), Err(Damage::ChunkTooLarge { .. })));
        let long = ChunkHeader { uncompressed_size: records.len() as u64 + 1, ..h.clone() };
        assert!(matches!(open(&long, &data), Err(Damage::ChunkSize { .. })));
        assert!(open(&h, &data[..data.len() / 2]).is_err(), "a cut frame");
    }

    #[test]
    fn recordings_of_every_compression_read_back_alike() {
        let dir = std::env::temp_dir().join(format!("harvey-chunk-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("dir");
        let mut seen = Vec::new();
        use crate::ChunkCompression as C;
        for (k, c) in [C::Zstd, C::ZstdFast, C::Lz4, C::None].into_iter().enumerate() {
            let path = dir.join(format!("c{k}.mcap"));
            let mut r = crate::Recorder::create_with(&path, c).expect("create");
            let ch = r.image_channel("camera/frame").expect("channel");
            for seq in 0..20u64 {
                let h = harvey_msgs::FrameHeader::new(seq, seq * 1000, 64, 48, harvey_msgs::Encoding::Mono8);
                let px: Vec<u8> = (0..64 * 48).map(|i| ((i as u64 * 7 + seq) % 256) as u8).collect();
                r.record_frame(ch, &h, &px).expect("frame");
            }
            r.finish().expect("finish");
            let rec = crate::Recording::open(&path).expect("open");
            let data: Vec<Vec<u8>> =
                rec.messages().expect("messages").map(|m| m.expect("message").data().to_vec()).collect();
            assert_eq!(data.len(), 20, "{c:?}");
            seen.push(data);
        }
        assert!(seen.windows(2).all(|w| w[0] == w[1]));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
