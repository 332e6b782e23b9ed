//! Opening a recording: its messages in file order and its summary section. What the recording
//! carries besides its messages (launch, world, data files, the recorder's counts) is read in
//! `attachments.rs`.

use std::cell::OnceCell;
use std::path::{Path, PathBuf};

use harvey_cdr::{Cdr, CdrError};

use crate::RecordingError;

/// A recording read into memory.
pub struct Recording {
    path: PathBuf,
    bytes: Vec<u8>,
    /// The summary section, read when first wanted; `None` when it is missing or unreadable.
    summary: OnceCell<Option<mcap::Summary>>,
}

impl Recording {
    /// Reads the file; what it holds is checked as it is read.
    pub fn open(path: &Path) -> Result<Self, RecordingError> {
        let bytes =
            std::fs::read(path).map_err(|cause| RecordingError::Read { file: path.to_owned(), cause })?;
        Ok(Self { path: path.to_owned(), bytes, summary: OnceCell::new() })
    }

    /// The file it was read from.
    pub fn path(&self) -> &Path {
        &self.path
    }

    pub(crate) fn bytes(&self) -> &[u8] {
        &self.bytes
    }

    /// The summary section, if there is one that reads.
    pub(crate) fn summary_if_any(&self) -> Option<&mcap::Summary> {
        self.summary.get_or_init(|| mcap::Summary::read(&self.bytes).ok().flatten()).as_ref()
    }

    /// The summary section; its absence is an error that suggests `harvey recover`.
    pub(crate) fn summary(&self) -> Result<&mcap::Summary, RecordingError> {
        if let Some(summary) = self.summary_if_any() {
            return Ok(summary);
        }
        let file = self.path.clone();
        Err(match mcap::Summary::read(&self.bytes) {
            Err(cause) => RecordingError::BadSummary { file, cause },
            Ok(_) => RecordingError::NoSummary { file },
        })
    }

    /// How many messages the summary counts (0 without one): the total for a progress bar.
    pub fn message_count(&self) -> u64 {
        self.summary_if_any().and_then(|s| s.stats.as_ref()).map_or(0, |s| s.message_count)
    }

    /// Every message, in file order. Reading stops at the first that does not read, with an
    /// error saying how many came before it.
    pub fn messages(&self) -> Result<Messages<'_>, RecordingError> {
        let stream = mcap::MessageStream::new(&self.bytes)
            .map_err(|cause| RecordingError::NotMcap { file: self.path.clone(), cause })?;
        Ok(Messages { file: &self.path, stream, index: 0, done: false })
    }
}

/// The messages of a [`Recording`], in file order.
pub struct Messages<'a> {
    file: &'a Path,
    stream: mcap::MessageStream<'a>,
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
            Err(cause) => {
                self.done = true;
                Some(Err(RecordingError::Corrupt { file: self.file.to_owned(), after: index, cause }))
            }
        }
    }
}

/// One recorded message.
pub struct Message<'a> {
    file: &'a Path,
    index: usize,
    inner: mcap::Message<'a>,
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
        &self.inner.data
    }

    /// The payload, owned.
    pub fn into_data(self) -> Vec<u8> {
        self.inner.data.into_owned()
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
        assert!(e.contains("cut.mcap: corrupt after 3 messages: "), "{e}");
        assert!(
            cut.launch_text()
                .expect_err("no summary")
                .to_string()
                .contains("run `harvey recover` on it first")
        );
        std::fs::remove_dir_all(&dir).ok();
    }
}
