//! The damage the mutation harness does to a valid recording, drawn from a seeded [`Rng`]: a cut
//! at a random length, 1–8 random bit flips, a length field rewritten (huge, zero, off by a bit or
//! by one), a CRC edited (a chunk's, mostly). Where the length and CRC fields are is read from the
//! intact file's layout, walked here independently of the crate's readers.

use harvey_geometry::Rng;

/// A kind of damage.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Kind {
    Truncate,
    BitFlips,
    Length,
    Crc,
}

pub const KINDS: [Kind; 4] = [Kind::Truncate, Kind::BitFlips, Kind::Length, Kind::Crc];

/// Where an intact file keeps its length fields (offset, width in bytes) and CRCs.
#[derive(Debug, Default)]
pub struct Layout {
    pub lengths: Vec<(usize, usize)>,
    pub chunk_crcs: Vec<usize>,
    pub other_crcs: Vec<usize>,
}

fn u32_at(b: &[u8], at: usize) -> usize {
    u32::from_le_bytes(b[at..at + 4].try_into().expect("4 bytes")) as usize
}

fn u64_at(b: &[u8], at: usize) -> usize {
    u64::from_le_bytes(b[at..at + 8].try_into().expect("8 bytes")) as usize
}

/// The layout of intact MCAP `bytes`: every top-level record's length, and inside the records
/// that have them the sizes, string lengths, index offsets and CRCs.
pub fn layout(bytes: &[u8]) -> Layout {
    let mut l = Layout::default();
    let mut at = 8;
    while at + 9 <= bytes.len() {
        let (opcode, len, body) = (bytes[at], u64_at(bytes, at + 1), at + 9);
        l.lengths.push((at + 1, 8));
        match opcode {
            0x06 => {
                // Chunk: times, uncompressed size, CRC, compression, compressed size.
                let n = u32_at(bytes, body + 28);
                l.lengths.extend([(body + 16, 8), (body + 28, 4), (body + 32 + n, 8)]);
                l.chunk_crcs.push(body + 24);
            }
            0x09 => {
                // Attachment: times, name, media type, data, CRC.
                let name = u32_at(bytes, body + 16);
                let media = body + 20 + name;
                l.lengths.extend([(body + 16, 4), (media, 4), (media + 4 + u32_at(bytes, media), 8)]);
                l.other_crcs.push(body + len - 4);
            }
            0x0C => l.lengths.extend([(body, 4), (body + 4 + u32_at(bytes, body), 4)]),
            0x0F => l.other_crcs.push(body),
            // Indexes: the offsets and lengths they point with.
            0x08 => l.lengths.extend([(body + 16, 8), (body + 24, 8)]),
            0x0A | 0x0D => l.lengths.extend([(body, 8), (body + 8, 8)]),
            0x02 => {
                l.lengths.push((body, 8));
                l.other_crcs.push(body + 16);
                break;
            }
            _ => {}
        }
        at = body + len;
    }
    l
}

fn below(rng: &mut Rng, n: usize) -> usize {
    (rng.next_u64() % n.max(1) as u64) as usize
}

/// `original` damaged by one mutation of `kind`, and what was done, for a failure's message.
pub fn mutate(original: &[u8], layout: &Layout, kind: Kind, rng: &mut Rng) -> (Vec<u8>, String) {
    let mut b = original.to_vec();
    let what = match kind {
        Kind::Truncate => {
            let len = below(rng, b.len());
            b.truncate(len);
            format!("cut to {len} bytes")
        }
        Kind::BitFlips => {
            let flips: Vec<(usize, u8)> =
                (0..1 + below(rng, 8)).map(|_| (below(rng, b.len()), below(rng, 8) as u8)).collect();
            for &(at, bit) in &flips {
                b[at] ^= 1 << bit;
            }
            format!("bits flipped (byte, bit): {flips:?}")
        }
        Kind::Length => {
            let (at, width) = layout.lengths[below(rng, layout.lengths.len())];
            let old = if width == 8 { u64_at(&b, at) as u64 } else { u32_at(&b, at) as u64 };
            let bits = 8 * width as u32;
            let new = match below(rng, 5) {
                0 if width == 8 => 8_900_000_000_000_000_000,
                0 => u64::from(u32::MAX),
                1 => 0,
                2 => old ^ (1 << below(rng, bits as usize)),
                3 => old.wrapping_add(1),
                _ => old.wrapping_sub(1),
            };
            let new = if width == 8 { new } else { new & u64::from(u32::MAX) };
            b[at..at + width].copy_from_slice(&new.to_le_bytes()[..width]);
            format!("length at {at} ({width} bytes) {old} -> {new}")
        }
        Kind::Crc => {
            let chunk = below(rng, 4) > 0 || layout.other_crcs.is_empty();
            let crcs = if chunk { &layout.chunk_crcs } else { &layout.other_crcs };
            let at = crcs[below(rng, crcs.len())];
            let xor = (rng.next_u64() as u32).max(1);
            for (i, x) in xor.to_le_bytes().into_iter().enumerate() {
                b[at + i] ^= x;
            }
            format!("CRC at {at} xor {xor:08x}")
        }
    };
    (b, what)
}
