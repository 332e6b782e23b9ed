//! The damage the issue found, one case each on the harness's sample recording: a flipped pixel
//! under an intact CRC field (every tool used to accept it, and `recover` wrote it again under a
//! fresh CRC), an 8.9e18-byte length (an allocation abort), a length past the file (a panic in
//! mcap), a message index turned into a message by one flipped bit (which `recover` used to write
//! as a message), and `export`/`recover` asked to write over their input.
#![allow(clippy::unwrap_used, clippy::expect_used, reason = "test code")]

#[allow(dead_code, reason = "the harness's sample and readers only")]
mod mutation;

use std::path::{Path, PathBuf};

use harvey_recording::{Recording, RecordingError, compare, export, recover};
use mutation::tools::message_prints;

/// The sample and its bytes, in a fresh folder.
fn sample(name: &str) -> (PathBuf, PathBuf, Vec<u8>) {
    let dir = mutation::scratch(&format!("damage-{name}"));
    let path = dir.join("sample.mcap");
    mutation::sample::write(&path);
    let bytes = std::fs::read(&path).unwrap();
    (dir, path, bytes)
}

/// The top-level chunk records of MCAP `bytes`: (offset, body start, body length).
fn chunks(bytes: &[u8]) -> Vec<(usize, usize, usize)> {
    let (mut at, mut out) = (8, Vec::new());
    while at + 9 <= bytes.len() && bytes[at] != 0x0F {
        let len = u64::from_le_bytes(bytes[at + 1..at + 9].try_into().unwrap()) as usize;
        if bytes[at] == 0x06 {
            out.push((at, at + 9, len));
        }
        at += 9 + len;
    }
    out
}

/// `bytes` with one pixel of the first camera frame in chunk `n` changed, the chunk recompressed
/// but its CRC field left as it was: what a flipped bit in the pixels does.
fn flip_a_pixel(bytes: &[u8], n: usize) -> Vec<u8> {
    let (at, body, len) = chunks(bytes)[n];
    let compression = u32::from_le_bytes(bytes[body + 28..body + 32].try_into().unwrap()) as usize;
    let data = body + 32 + compression + 8;
    let mut records = zstd::decode_all(&bytes[data..body + len]).unwrap();
    let image = records.windows(8).position(|w| w == b"mono8\0\0\0").expect("a frame in the chunk");
    records[image + 40] ^= 0x10;
    let packed = zstd::encode_all(&records[..], 3).unwrap();
    let mut out = bytes[..at].to_vec();
    let mut header = bytes[body..body + 32 + compression].to_vec();
    header[16..24].copy_from_slice(&(records.len() as u64).to_le_bytes());
    out.push(0x06);
    out.extend_from_slice(&((header.len() + 8 + packed.len()) as u64).to_le_bytes());
    out.extend_from_slice(&header);
    out.extend_from_slice(&(packed.len() as u64).to_le_bytes());
    out.extend_from_slice(&packed);
    out.extend_from_slice(&bytes[body + len..]);
    out
}

fn error_of(r: Result<impl std::fmt::Debug, RecordingError>) -> String {
    r.expect_err("an error").to_string()
}

#[test]
fn a_flipped_pixel_is_caught_by_its_chunks_crc_and_recover_skips_only_that_chunk() {
    let (dir, path, bytes) = sample("pixel");
    let (at, ..) = chunks(&bytes)[1];
    let damaged = dir.join("pixel.mcap");
    // The chunk moves nowhere: it starts where it did, only its data changed.
    std::fs::write(&damaged, flip_a_pixel(&bytes, 1)).unwrap();
    let crc = format!("at byte {at}: chunk CRC does not match");

    let e = error_of(message_prints(&damaged));
    assert!(e.contains("pixel.mcap: corrupt after ") && e.contains(&crc), "{e}");
    let e = error_of(compare::compare(&path, &damaged, &|_| true));
    assert!(e.contains(&crc), "{e}");
    let e = error_of(export::export(&damaged, &dir.join("out.rrd"), |_, _| {}));
    assert!(e.contains(&crc), "{e}");

    let out = dir.join("recovered.mcap");
    let s = recover::recover(&damaged, &out).unwrap();
    assert_eq!((s.damaged_chunks.as_slice(), s.stopped_at.as_deref()), (&[at as u64][..], None));
    assert!(s.losses().starts_with(&format!(", 1 damaged chunk skipped at offset {at}")), "{}", s.losses());
    let (original, salvaged) = (message_prints(&path).unwrap(), message_prints(&out).unwrap());
    let skipped = original.len() - salvaged.len();
    assert!(skipped > 50 && salvaged.iter().all(|m| original.contains(m)), "{skipped} messages skipped");
    assert_eq!(s.messages as usize, salvaged.len());
    let recovered = Recording::open(&out).unwrap();
    assert_eq!(recovered.world_text().unwrap(), mutation::sample::ARENA, "attachments survive");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_length_of_8_9e18_bytes_is_an_error_naming_the_offset_not_an_allocation() {
    let (dir, _, bytes) = sample("huge");
    let (at, body, _) = chunks(&bytes)[0];
    let huge = 8_900_000_000_000_000_000u64.to_le_bytes();
    let path = dir.join("huge.mcap");
    // The chunk's uncompressed size: what mcap reserved before decompressing.
    let mut b = bytes.clone();
    b[body + 16..body + 24].copy_from_slice(&huge);
    std::fs::write(&path, &b).unwrap();
    let e = error_of(message_prints(&path));
    assert!(e.contains(&format!("at byte {at}: chunk claims 8900000000000000000 bytes decompressed")), "{e}");
    // The chunk record's own length: past the end of the file.
    let mut b = bytes.clone();
    b[at + 1..at + 9].copy_from_slice(&huge);
    std::fs::write(&path, &b).unwrap();
    let e = error_of(message_prints(&path));
    assert!(e.contains(&format!("at byte {at}: record 0x06 claims 8900000000000000000 bytes")), "{e}");
    let s = recover::recover(&path, &dir.join("out.mcap")).unwrap();
    assert!(s.stopped_at.as_deref().is_some_and(|e| e.starts_with(&format!("at byte {at}: "))), "{s:?}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_string_length_past_its_record_is_an_error_not_a_panic() {
    let (dir, _, bytes) = sample("string");
    // The first attachment's name length, made larger than the record (mcap slices past it).
    let at = 8 + bytes[8 + 1..8 + 9].iter().rev().fold(0usize, |n, &b| n << 8 | b as usize) + 9;
    assert_eq!(bytes[at], 0x09, "an attachment follows the header");
    let mut b = bytes.clone();
    b[at + 9 + 16..at + 9 + 20].copy_from_slice(&u32::MAX.to_le_bytes());
    let path = dir.join("string.mcap");
    std::fs::write(&path, &b).unwrap();
    let e = error_of(message_prints(&path));
    assert!(e.contains(&format!("at byte {at}: record 0x09: a length field at byte 16")), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_message_index_a_flipped_bit_made_a_message_is_not_salvaged_as_one() {
    let (dir, path, bytes) = sample("opcode");
    // The first message index after a chunk: opcode 0x07, one bit from a message's 0x05. Its body
    // parses as a message on the channel it indexes, and no CRC of its own says otherwise.
    let (mut at, mut index) = (8, None);
    while at + 9 <= bytes.len() && bytes[at] != 0x0F {
        if bytes[at] == 0x07 {
            index = Some(at);
            break;
        }
        at += 9 + u64::from_le_bytes(bytes[at + 1..at + 9].try_into().unwrap()) as usize;
    }
    let at = index.expect("a message index in the data section");
    let mut b = bytes.clone();
    b[at] ^= 0b10;
    let damaged = dir.join("opcode.mcap");
    std::fs::write(&damaged, &b).unwrap();

    let out = dir.join("recovered.mcap");
    let s = recover::recover(&damaged, &out).unwrap();
    assert_eq!((s.damaged_chunks.as_slice(), s.damaged_records.as_slice()), (&[][..], &[at as u64][..]));
    assert!(!s.is_whole() && s.losses().contains(&format!("1 damaged record skipped at offset {at}")));
    let (original, salvaged) = (message_prints(&path).unwrap(), message_prints(&out).unwrap());
    assert_eq!(salvaged, original, "every chunk's messages, and nothing else");
    assert_eq!(s.messages as usize, salvaged.len());
    std::fs::remove_dir_all(&dir).ok();
}

/// `path`'s bytes are still `bytes`.
fn unchanged(path: &Path, bytes: &[u8]) {
    assert!(std::fs::read(path).unwrap() == bytes, "{} was overwritten", path.display());
}

#[test]
fn export_and_recover_refuse_to_write_over_their_input_by_any_name() {
    let (dir, path, bytes) = sample("overwrite");
    let link = dir.join("link.mcap");
    std::os::unix::fs::symlink(&path, &link).unwrap();
    for output in [&path, &link, &dir.join("./sample.mcap")] {
        let e = error_of(recover::recover(&path, output));
        assert!(e.ends_with("sample.mcap itself: refusing to overwrite the recording read"), "{e}");
        unchanged(&path, &bytes);
        let e = error_of(export::export(&path, output, |_, _| {}));
        assert!(e.contains("refusing to overwrite"), "{e}");
        unchanged(&path, &bytes);
    }
    assert!(error_of(recover::recover(&link, &path)).contains("refusing to overwrite"));
    unchanged(&path, &bytes);
    std::fs::remove_dir_all(&dir).ok();
}
