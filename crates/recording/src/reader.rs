//! Opening a recording: its messages in file order and its summary section, both read through
//! the crate's checked readers (`stream.rs`, `summary.rs`: lengths, limits, CRCs), which every
//! tool of the crate reads with. What the recording carries besides its messages (launch, world,
//! data files, the recorder's counts) is read in `attachments.rs`.

use std::cell::OnceCell;
use std::path::{Path, PathBuf};

use harvey_cdr::{Cdr, CdrError};

use crate::RecordingError;
use crate::damage::Damage;
use crate::records::check_data_crc;
use crate::stream::{Linked, Stream};
use crate::summary::Located;

/// A recording read into memory.
pub struct Recording {
    path: PathBuf,
    bytes: Vec<u8>,
    /// The summary section, read when first wanted: `Some(None)` when the footer says there is
    /// none, `None` when it does not read (`summary_error` says why).
    summary: OnceCell<Option<Option<mcap::Summary>>>,
    /// Whether the data section's CRC checks, found when first wanted.
    data_crc: OnceCell<bool>,
}

impl Recording {
    /// Reads the file; what it holds is checked as it is read.
    pub fn open(path: &Path) -> Result<Self, RecordingError> {
        let bytes =
            std::fs::read(path).map_err(|cause| RecordingError::Read { file: path.to_owned(), cause })?;
        Ok(Self { path: path.to_owned(), bytes, summary: OnceCell::new(), data_crc: OnceCell::new() })
    }

    /// The file it was read from.
    pub fn path(&self) -> &Path {
        &self.path
    }

    pub(crate) fn bytes(&self) -> &[u8] {
        &self.bytes
    }

    /// The summary section if there is one (`None` when the footer says there is none); one that
    /// does not read, or no footer at all (a writer killed), is an error.
    pub(crate) fn summary_state(&self) -> Result<Option<&mcap::Summary>, RecordingError> {
        match self.summary.get_or_init(|| crate::summary::read(&self.bytes).ok()) {
            Some(summary) => Ok(summary.as_ref()),
            None => Err(self.summary_error()),
        }
    }

    /// Why the summary does not read (read again: errors are the rare path).
    fn summary_error(&self) -> RecordingError {
        let file = self.path.clone();
        match crate::summary::read(&self.bytes) {
            Err(Located { what: Damage::NoFooter, .. }) | Ok(_) => RecordingError::NoSummary { file },
            Err(Located { offset, what }) => RecordingError::BadSummary { file, offset, what },
        }
    }

    /// Checks the data section's CRC, once: what vouches for the metadata records, which have no
    /// CRC of their own.
    pub(crate) fn check_data_section(&self) -> Result<(), RecordingError> {
        if *self.data_crc.get_or_init(|| check_data_crc(&self.bytes).is_ok()) {
            return Ok(());
        }
        match check_data_crc(&self.bytes) {
            Ok(()) => Ok(()),
            Err((offset, what)) => {
                Err(RecordingError::Damaged { file: self.path.clone(), offset: offset as u64, what })
            }
        }
    }

    /// The summary section, if there is one that reads.
    pub(crate) fn summary_if_any(&self) -> Option<&mcap::Summary> {
        self.summary_state().ok().flatten()
    }

    /// The summary section; its absence is an error that suggests `harvey recover`.
    pub(crate) fn summary(&self) -> Result<&mcap::Summary, RecordingError> {
        self.summary_state()?.ok_or_else(|| RecordingError::NoSummary { file: self.path.clone() })
    }

    /// How many messages the summary counts (0 without one): the total for a progress bar.
    pub fn message_count(&self) -> u64 {
        self.summary_if_any().and_then(|s| s.stats.as_ref()).map_or(0, |s| s.message_count)
    }

    /// Every message, in file order, each chunk's CRC checked before its messages come. Reading
    /// stops at the first damage, with an error saying how many messages came before it and the
    /// byte offset of the record it is in.
    pub fn messages(&self) -> Result<Messages<'_>, RecordingError> {
        if !self.bytes.starts_with(mcap::MAGIC) {
            return Err(RecordingError::NoMagic { file: self.path.clone() });
        }
        Ok(Messages { file: &self.path, stream: Stream::new(&self.bytes), index: 0, done: false })
    }
}

/// The messages of a [`Recording`], in file order.
pub struct Messages<'a> {
    file: &'a Path,
    stream: Stream<'a>,
    index: usize,
    done: bool,
}

impl<'a> Iterator for Messages<'a> {
    type Item = Result<Message<'a>, RecordingError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        let index = self.index;
        match self.stream.next()? {
            Ok(inner) => {
                self.index += 1;
                Some(Ok(Message { file: self.file, index, inner }))
            }
            Err(Located { offset, what }) => {
                self.done = true;
                Some(Err(RecordingError::Corrupt { file: self.file.to_owned(), after: index, offset, what }))
            }
        }
    }
}

/// One recorded message.
pub struct Message<'a> {
    file: &'a Path,
    index: usize,
    inner: Linked<'a>,
}

impl<'a> Message<'a> {
    /// Its place among all the recording's messages, from 0.
    pub fn index(&self) -> usize {
        self.index
    }

    /// The topic, without the leading `/` of the ROS 2 convention.
    pub fn topic(&self) -> &str {
        self.inner.channel.topic.trim_start_matches('/')
    }

    /// The name of the channel's schema (`harvey_msgs/msg/TruePose`), empty without one.
    pub fn schema(&self) -> &str {
        self.inner.channel.schema.as_ref().map_or("", |s| s.name.as_str())
    }

    /// The MCAP sequence number: the message's own (a frame's, for camera frames).
    pub fn sequence(&self) -> u32 {
        self.inner.sequence
    }

    /// The log time: the message's stamp.
    pub fn log_time(&self) -> u64 {
        self.inner.log_time
    }

    /// The CDR payload.
    pub fn data(&self) -> &[u8] {
        self.inner.data.bytes()
    }

    /// The payload, owned.
    pub fn into_data(self) -> Vec<u8> {
        self.inner.data.bytes().to_vec()
    }

    /// The payload decoded as `T`; an error names the file, the message and its topic.
    pub fn decode<T: Cdr>(&self) -> Result<T, RecordingError> {
        harvey_cdr::decode(self.data()).map_err(|cause| self.undecodable(cause))
    }

    /// The error for a payload that does not decode.
    pub(crate) fn undecodable(&self, cause: CdrError) -> RecordingError {
        RecordingError::Decode {
            file: self.file.to_owned(),
            index: self.index,
            topic: self.topic().to_owned(),
            cause,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Recorder;
    use harvey_msgs::{Header, TruePose};

    #[test]
    fn a_file_cut_short_reads_up_to_the_cut_then_says_where_it_broke() {
        let dir = std::env::temp_dir().join(format!("harvey-reader-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("tmp");
        let (path, cut) = (dir.join("t.mcap"), dir.join("cut.mcap"));
        let mut r = Recorder::create(&path).expect("create");
        let truth = r.channel::<TruePose>("sim/truth").expect("channel");
        let mut flushed = 0;
        for seq in 1..=6u64 {
            r.record(truth, &TruePose { header: Header::new(seq, seq * 1000), ..Default::default() })
                .expect("record");
            if seq == 3 {
                r.flush().expect("flush");
                flushed = std::fs::metadata(&path).expect("size").len() as usize;
            }
        }
        r.finish().expect("finish");
        let bytes = std::fs::read(&path).expect("read");
        std::fs::write(&cut, &bytes[..flushed + 16]).expect("write");

        let whole = Recording::open(&path).expect("open");
        assert_eq!(whole.message_count(), 6);
        let stamps: Vec<u64> =
            whole.messages().expect("mcap").map(|m| m.expect("reads").log_time()).collect();
        assert_eq!(stamps, [1000, 2000, 3000, 4000, 5000, 6000]);
        let m = whole.messages().expect("mcap").nth(4).expect("a fifth").expect("reads");
        assert_eq!((m.index(), m.topic(), m.schema()), (4, "sim/truth", "harvey_msgs/msg/TruePose"));
        assert_eq!(m.decode::<TruePose>().expect("decodes").header.seq, 5);

        let cut = Recording::open(&cut).expect("open");
        assert_eq!(cut.message_count(), 0, "no summary");
        let read: Vec<_> = cut.messages().expect("mcap").collect();
        assert_eq!(read.len(), 4, "three messages, then the error");
        let e = read[3].as_ref().err().expect("cut").to_string();
        assert!(e.contains("cut.mcap: corrupt after 3 messages, at byte "), "{e}");
        assert!(
            cut.launch_text()
                .expect_err("no summary")
                .to_string()
                .contains("run `harvey recover` on it first")
        );
        std::fs::remove_dir_all(&dir).ok();
    }
}
