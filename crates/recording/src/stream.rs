//! A recording's messages in file order, read with every check an MCAP file offers: each record's
//! length against the bytes left, each chunk's size limits and CRC before any of its records is
//! taken (`chunk.rs`), the data section's CRC at its data end record, and the summary section's
//! CRC at the footer, then the end magic. What mcap's `MessageStream` yields for an intact file,
//! and for a damaged one the damage and the byte offset of the record it is in, never a panic.

use std::borrow::Cow;
use std::ops::Range;
use std::sync::Arc;

use mcap::read::ChannelAccumulator;
use mcap::records::{Record, op};

use crate::chunk;
use crate::damage::Damage;
use crate::records::{Raw, record_at};
use crate::summary::{Located, check_summary_crc, footer, located};

/// Which part of the file the next top-level record is in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Part {
    Data,
    /// After the data end record, which ends at `start`.
    Summary {
        start: usize,
    },
    Done,
}

/// Where records lie: the file itself (and a chunk stored uncompressed in it), or a
/// decompressed chunk, shared with the messages read from it.
#[derive(Debug, Clone)]
enum Records<'a> {
    File(&'a [u8]),
    Chunk(Arc<Vec<u8>>),
}

impl Records<'_> {
    fn bytes(&self) -> &[u8] {
        match self {
            Records::File(b) => b,
            Records::Chunk(b) => b,
        }
    }
}

/// A message's payload: its range of the records it lies in (the file's, or its chunk's, shared
/// rather than copied out).
#[derive(Debug, Clone)]
pub(crate) struct Payload<'a> {
    records: Records<'a>,
    range: Range<usize>,
}

impl Payload<'_> {
    pub fn bytes(&self) -> &[u8] {
        &self.records.bytes()[self.range.clone()]
    }
}

/// A message linked to its channel, its payload where it lies.
#[derive(Debug, Clone)]
pub(crate) struct Linked<'a> {
    pub channel: Arc<mcap::Channel<'static>>,
    pub sequence: u32,
    pub log_time: u64,
    pub data: Payload<'a>,
}

/// The chunk whose records are being read.
struct Open<'a> {
    /// The chunk record's offset in the file.
    offset: usize,
    records: Records<'a>,
    at: usize,
}

/// The messages of MCAP `bytes`, in file order; the first damage ends them.
pub(crate) struct Stream<'a> {
    bytes: &'a [u8],
    at: usize,
    part: Part,
    chunk: Option<Open<'a>>,
    unpacker: chunk::Unpacker,
    /// Finished chunks some message may still share (a tick's messages outlive their chunk's
    /// end): reclaimed for the next chunk once none does.
    retired: Vec<Arc<Vec<u8>>>,
    channels: ChannelAccumulator<'static>,
}

impl<'a> Stream<'a> {
    /// The messages of `bytes`, which must start with the MCAP magic.
    pub fn new(bytes: &'a [u8]) -> Self {
        let at = mcap::MAGIC.len();
        let (chunk, unpacker, channels) = (None, chunk::Unpacker::default(), ChannelAccumulator::default());
        Self { bytes, at, part: Part::Data, chunk, unpacker, retired: Vec::new(), channels }
    }

    /// The next message of the chunk being read, if it has one left.
    fn next_in_chunk(&mut self) -> Option<Result<Linked<'a>, Located>> {
        loop {
            let open = self.chunk.as_mut()?;
            if open.at >= open.records.bytes().len() {
                if let Some(Open { records: Records::Chunk(done), .. }) = self.chunk.take() {
                    // Two at most: a message kept longer keeps its chunk, not the reader's buffer.
                    if self.retired.len() == 2 {
                        self.retired.remove(0);
                    }
                    self.retired.push(done);
                }
                return None;
            }
            let (offset, at) = (open.offset, open.at);
            let in_chunk = |what| located(offset, Damage::in_chunk(at as u64, what));
            let raw = match record_at(open.records.bytes(), at) {
                Ok(raw) => raw,
                Err(what) => return Some(Err(in_chunk(what))),
            };
            open.at = raw.end;
            // A data end record inside a chunk is a stray record, skipped as mcap does.
            if raw.opcode == op::DATA_END {
                continue;
            }
            match take(&mut self.channels, raw) {
                Ok(Some((m, range))) => {
                    return Some(Ok(m.with(Payload { records: open.records.clone(), range })));
                }
                Ok(None) => {}
                Err(what) => return Some(Err(in_chunk(what))),
            }
        }
    }

    /// Hands the unpacker back a finished chunk's buffer that no message shares any more.
    fn reclaim(&mut self) {
        if let Some(i) = self.retired.iter().position(|c| Arc::strong_count(c) == 1)
            && let Ok(buffer) = Arc::try_unwrap(self.retired.swap_remove(i))
        {
            self.unpacker.give_back(buffer);
        }
    }

    /// Reads the next top-level record: `Some` with a message or damage, `None` to read on.
    fn step(&mut self) -> Option<Result<Linked<'a>, Located>> {
        let at = self.at;
        let here = |what| Some(Err(located(at, what)));
        if at >= self.bytes.len() {
            let what = if self.part == Part::Data { Damage::NoDataEnd } else { Damage::NoFooter };
            return here(what);
        }
        let raw = match record_at(self.bytes, at) {
            Ok(raw) => raw,
            Err(what) => return here(what),
        };
        self.at = raw.end;
        match (self.part, raw.opcode) {
            (Part::Data, op::CHUNK) => match raw.parse() {
                Ok(Record::Chunk { header, data }) => {
                    self.reclaim();
                    let opened = match data {
                        Cow::Borrowed(data) => self.unpacker.open(&header, data),
                        Cow::Owned(data) => self.unpacker.open(&header, &data).map(chunk::Opened::into_owned),
                    };
                    match opened {
                        Ok(opened) => {
                            let records = match opened.records {
                                Cow::Borrowed(b) => Records::File(b),
                                Cow::Owned(b) => Records::Chunk(Arc::new(b)),
                            };
                            self.chunk = Some(Open { offset: at, records, at: 0 });
                            None
                        }
                        Err(what) => here(what),
                    }
                }
                Ok(_) => None,
                Err(what) => here(what),
            },
            (Part::Data, op::DATA_END) => match raw.parse() {
                Ok(Record::DataEnd(end)) => {
                    let (saved, calculated) = (end.data_section_crc, crc32fast::hash(&self.bytes[..at]));
                    if saved != 0 && saved != calculated {
                        return here(Damage::DataCrc { saved, calculated });
                    }
                    self.part = Part::Summary { start: raw.end };
                    None
                }
                Ok(_) => None,
                Err(what) => here(what),
            },
            (Part::Data, _) => match take(&mut self.channels, raw) {
                Ok(Some((m, range))) => {
                    Some(Ok(m.with(Payload { records: Records::File(self.bytes), range })))
                }
                Ok(None) => None,
                Err(what) => here(what),
            },
            (Part::Summary { start }, op::FOOTER) => {
                self.part = Part::Done;
                self.end(start, raw).err().map(Err)
            }
            // The summary repeats schemas and channels: parsed, not taken again.
            (Part::Summary { .. }, _) => raw.parse().err().and_then(here),
            (Part::Done, _) => None,
        }
    }

    /// Checks the footer at `raw` (the summary section from `start` before it) and the end magic.
    fn end(&self, start: usize, raw: Raw<'_>) -> Result<(), Located> {
        raw.parse().map_err(|what| located(raw.offset, what))?;
        let magic = self.bytes.get(raw.end..raw.end + mcap::MAGIC.len());
        if magic != Some(mcap::MAGIC) {
            return Err(located(raw.end, Damage::NoFooter));
        }
        let at_end = footer(&self.bytes[..raw.end + mcap::MAGIC.len()])?;
        check_summary_crc(self.bytes, start, &at_end)
    }
}

/// A message's fields but its payload.
struct Head {
    channel: Arc<mcap::Channel<'static>>,
    sequence: u32,
    log_time: u64,
}

impl Head {
    fn with(self, data: Payload<'_>) -> Linked<'_> {
        let Head { channel, sequence, log_time } = self;
        Linked { channel, sequence, log_time, data }
    }
}

/// Takes a record of the data section (or of a chunk): schemas and channels are kept to link the
/// messages that follow to; a message comes back linked, with where its payload lies in the bytes
/// `raw` was read from (a message record's payload is its tail); other records are parsed and left.
fn take(
    channels: &mut ChannelAccumulator<'static>,
    raw: Raw<'_>,
) -> Result<Option<(Head, Range<usize>)>, Damage> {
    match raw.parse()? {
        Record::Schema { header, data } => {
            channels.add_schema(header, Cow::Owned(data.into_owned())).map_err(Damage::Link)?;
        }
        Record::Channel(channel) => channels.add_channel(channel).map_err(Damage::Link)?,
        Record::Message { header, data } => {
            let channel = channels
                .get(header.channel_id)
                .ok_or(Damage::UnknownChannel { channel: header.channel_id })?;
            let (sequence, log_time) = (header.sequence, header.log_time);
            let range = raw.end - data.len()..raw.end;
            return Ok(Some((Head { channel, sequence, log_time }, range)));
        }
        _ => {}
    }
    Ok(None)
}

impl<'a> Iterator for Stream<'a> {
    type Item = Result<Linked<'a>, Located>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if let Some(message) = self.next_in_chunk() {
                if message.is_err() {
                    self.part = Part::Done;
                }
                return Some(message);
            }
            if self.part == Part::Done {
                return None;
            }
            if let Some(item) = self.step() {
                if item.is_err() {
                    (self.part, self.chunk) = (Part::Done, None);
                }
                return Some(item);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Recorder;
    use harvey_msgs::{Encoding, FrameHeader, Header, TruePose};

    #[test]
    fn an_intact_file_yields_exactly_what_mcaps_message_stream_does() {
        let dir = std::env::temp_dir().join(format!("harvey-stream-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("tmp");
        let path = dir.join("t.mcap");
        let mut r = Recorder::create(&path).expect("create");
        let (truth, cam) =
            (r.channel::<TruePose>("sim/truth").expect("channel"), r.image_channel("cam").expect("ch"));
        for seq in 1..=40u64 {
            r.record(truth, &TruePose { header: Header::new(seq, seq * 1000), ..Default::default() })
                .expect("record");
            let h = FrameHeader::new(seq, seq * 1000, 4, 2, Encoding::Mono8);
            r.record_frame(cam, &h, &[seq as u8; 8]).expect("frame");
            if seq % 10 == 0 {
                r.flush().expect("a chunk");
            }
        }
        r.finish().expect("finish");
        let bytes = std::fs::read(&path).expect("read");
        let ours: Vec<_> = Stream::new(&bytes)
            .map(|m| {
                let m = m.expect("intact");
                (m.channel, m.sequence, m.log_time, m.data.bytes().to_vec())
            })
            .collect();
        let theirs: Vec<_> = mcap::MessageStream::new(&bytes)
            .expect("mcap")
            .map(|m| {
                let m = m.expect("intact");
                (m.channel, m.sequence, m.log_time, m.data.into_owned())
            })
            .collect();
        assert_eq!(ours.len(), 80);
        assert_eq!(ours, theirs);
        // Read as a replay reads: the last message kept while the next is read, across chunk
        // ends. The bytes are the same, and a finished chunk's buffer still comes back for
        // the chunks after it.
        let mut kept: Option<Linked<'_>> = None;
        let mut buffers = Vec::new();
        for (k, m) in Stream::new(&bytes).enumerate() {
            let m = m.expect("intact");
            assert_eq!(m.data.bytes(), &theirs[k].3[..]);
            if let Records::Chunk(chunk) = &m.data.records
                && buffers.last() != Some(&(chunk.as_ptr() as usize))
            {
                buffers.push(chunk.as_ptr() as usize);
            }
            kept = Some(m);
        }
        drop(kept);
        assert_eq!(buffers.len(), 4, "four chunks");
        assert_eq!(buffers[2], buffers[0], "the third chunk in the first one's buffer: {buffers:?}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
