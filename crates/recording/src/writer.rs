//! The MCAP writer of a recording, with the ROS 2 conventions (profile `ros2`, `ros2msg`
//! schemas with their dependencies, `cdr` payloads, `offered_qos_profiles` channel metadata).
//! Log times are the messages' own stamps, never the recorder's clock, so a deterministic run
//! records the same bytes every time.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use harvey_cdr::{Def, Ros2Msg, encode, encode_image, full_text, image_def};
use harvey_msgs::FrameHeader;
use mcap::records::{MessageHeader, Metadata};

use crate::{
    LAUNCH_MEDIA_TYPE, RECORDER_METADATA, RecordingError, WORLD_MEDIA_TYPE, WORLD_METADATA, data_files,
};

/// QoS that ROS 2 tools expect on a channel: reliable, volatile, keep-last 16 (rosbag2's YAML).
const QOS_YAML: &str = "- history: 1\n  depth: 16\n  reliability: 1\n  durability: 2\n  deadline:\n    sec: 2147483647\n    nsec: 4294967295\n  lifespan:\n    sec: 2147483647\n    nsec: 4294967295\n  liveliness: 1\n  liveliness_lease_duration:\n    sec: 2147483647\n    nsec: 4294967295\n  avoid_ros_namespace_conventions: false";
/// The same, transient local (`durability: 1`): a late joiner gets the last message
/// (`/tf_static`, the map).
fn latched_qos() -> String {
    QOS_YAML.replace("durability: 2", "durability: 1")
}

/// MCAP's chunk size: large enough to compress well, small enough to bound a crash's loss.
const CHUNK_BYTES: u64 = 4 << 20;

/// How the recorder compresses its chunks. The MCAP writer compresses every chunk alike, so this
/// is chosen for the file: camera frames are nearly all of its bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ChunkCompression {
    /// zstd at its default level 3, on the writer's worker threads: small files, but a noisy
    /// camera's 1080p frames come in faster than it keeps up (see `docs/benchmarks.md`).
    #[default]
    Zstd,
    /// zstd at level 1: on two cores it keeps up with a noisy 1080p rgb8 camera at 60 Hz.
    ZstdFast,
    /// LZ4, on one thread (the mcap crate's): where one core is all the writer has.
    Lz4,
    /// Chunks stored as they are: for a disk faster than any compressor on this CPU.
    None,
}

impl ChunkCompression {
    /// The MCAP compression and level (0 is the codec's default).
    fn mcap(self) -> (Option<mcap::Compression>, u32) {
        match self {
            Self::Zstd => (Some(mcap::Compression::Zstd), 0),
            Self::ZstdFast => (Some(mcap::Compression::Zstd), 1),
            Self::Lz4 => (Some(mcap::Compression::Lz4), 0),
            Self::None => (None, 0),
        }
    }
}

/// One recorded channel and what went through it.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ChannelStats {
    pub topic: String,
    pub messages: u64,
    /// Sequence numbers skipped: messages the recorder never saw (or a publisher restart).
    pub seq_gaps: u64,
    last_seq: Option<u64>,
    /// Several publishers number their own messages here (`rosout`): gaps are not counted.
    shared: bool,
}

/// An open recording.
pub struct Recorder {
    path: PathBuf,
    writer: mcap::Writer<BufWriter<File>>,
    channels: Vec<(u16, ChannelStats)>,
    scratch: Vec<u8>,
}

/// Handle of a channel in a [`Recorder`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Channel(usize);

impl Recorder {
    /// A recording compressed with zstd.
    pub fn create(path: &Path) -> Result<Self, RecordingError> {
        Self::create_with(path, ChunkCompression::Zstd)
    }

    /// A recording whose chunks are compressed as `compression` says.
    pub fn create_with(path: &Path, compression: ChunkCompression) -> Result<Self, RecordingError> {
        let (codec, level) = compression.mcap();
        let file =
            File::create(path).map_err(|cause| RecordingError::Create { file: path.to_owned(), cause })?;
        let writer = mcap::WriteOptions::new()
            .profile("ros2")
            .library(concat!("harvey-recorder ", env!("CARGO_PKG_VERSION")))
            .compression(codec)
            .compression_level(level)
            .chunk_size(Some(CHUNK_BYTES))
            .create(BufWriter::new(file))
            .map_err(|cause| RecordingError::Write { file: path.to_owned(), cause })?;
        Ok(Self { path: path.to_owned(), writer, channels: Vec::new(), scratch: Vec::new() })
    }

    fn err(&self, cause: mcap::McapError) -> RecordingError {
        RecordingError::Write { file: self.path.clone(), cause }
    }

    fn add_channel(&mut self, topic: &str, def: &Def) -> Result<Channel, RecordingError> {
        self.add_channel_qos(topic, def, QOS_YAML.to_owned())
    }

    fn add_channel_qos(&mut self, topic: &str, def: &Def, qos: String) -> Result<Channel, RecordingError> {
        let schema = self
            .writer
            .add_schema(&def.schema_name(), "ros2msg", full_text(def).as_bytes())
            .map_err(|e| self.err(e))?;
        let metadata = BTreeMap::from([("offered_qos_profiles".to_owned(), qos)]);
        let id = self
            .writer
            .add_channel(schema, &format!("/{topic}"), "cdr", &metadata)
            .map_err(|e| self.err(e))?;
        let shared = topic == harvey_msgs::topics::ROSOUT.name;
        self.channels.push((id, ChannelStats { topic: topic.to_owned(), shared, ..Default::default() }));
        Ok(Channel(self.channels.len() - 1))
    }

    /// A channel of any definition, for tests of readers of other versions' recordings.
    #[cfg(test)]
    pub(crate) fn add_channel_for_test(&mut self, topic: &str, def: &Def) {
        let _ = self.add_channel(topic, def);
    }

    /// A channel for a topic of `T`.
    pub fn channel<T: Ros2Msg>(&mut self, topic: &str) -> Result<Channel, RecordingError> {
        self.add_channel(topic, T::DEF)
    }

    /// The channels of the derived topics (`derive::TOPICS`), in that order.
    pub fn derived_channels(&mut self) -> Result<Vec<Channel>, RecordingError> {
        let qos = |latched: bool| if latched { latched_qos() } else { QOS_YAML.to_owned() };
        crate::derive::TOPICS
            .iter()
            .map(|&(topic, def, latched)| self.add_channel_qos(topic, def, qos(latched)))
            .collect()
    }

    /// The channel set up for `topic`, if any.
    pub fn channel_of(&self, topic: &str) -> Option<Channel> {
        self.channels.iter().position(|(_, s)| s.topic == topic).map(Channel)
    }

    /// A channel of `sensor_msgs/msg/Image` for a frame topic.
    pub fn image_channel(&mut self, topic: &str) -> Result<Channel, RecordingError> {
        self.add_channel(topic, image_def())
    }

    fn write(&mut self, ch: Channel, seq: u64, stamp_ns: u64) -> Result<(), RecordingError> {
        let data = std::mem::take(&mut self.scratch);
        let result = self.record_encoded(ch, seq, stamp_ns, &data);
        self.scratch = data;
        result
    }

    /// Records a message already in CDR (what [`Recorder::record`] would have encoded).
    pub fn record_encoded(
        &mut self,
        ch: Channel,
        seq: u64,
        stamp_ns: u64,
        data: &[u8],
    ) -> Result<(), RecordingError> {
        let (id, stats) = &mut self.channels[ch.0];
        if let Some(last) = stats.last_seq.filter(|_| !stats.shared) {
            stats.seq_gaps += seq.saturating_sub(last + 1);
        }
        stats.last_seq = Some(seq);
        stats.messages += 1;
        let header = MessageHeader {
            channel_id: *id,
            sequence: seq as u32,
            log_time: stamp_ns,
            publish_time: stamp_ns,
        };
        let result = self.writer.write_to_known_channel(&header, data);
        result.map_err(|e| self.err(e))
    }

    pub fn record<T: Ros2Msg + harvey_msgs::Message>(
        &mut self,
        ch: Channel,
        msg: &T,
    ) -> Result<(), RecordingError> {
        self.scratch = encode(msg, std::mem::take(&mut self.scratch));
        let h = *msg.header();
        self.write(ch, h.seq, h.stamp_ns)
    }

    pub fn record_frame(
        &mut self,
        ch: Channel,
        h: &FrameHeader,
        pixels: &[u8],
    ) -> Result<(), RecordingError> {
        self.scratch = encode_image(h, pixels, std::mem::take(&mut self.scratch));
        self.write(ch, h.seq, h.stamp_ns)
    }

    /// Stores the world file the run used and the run's seed (a `harvey.world` metadata record;
    /// it places the world's `[poles]`), so that offline tools (`harvey export`) can draw it.
    pub fn attach_world(&mut self, name: &str, text: &str, seed: u64) -> Result<(), RecordingError> {
        self.attach(name, WORLD_MEDIA_TYPE, text)?;
        let metadata =
            BTreeMap::from([("file".to_owned(), name.to_owned()), ("seed".to_owned(), seed.to_string())]);
        let record = Metadata { name: WORLD_METADATA.into(), metadata };
        self.writer.write_metadata(&record).map_err(|e| self.err(e))
    }

    /// Stores the launch file of the run, so that `harvey replay` can run its services again.
    pub fn attach_launch(&mut self, name: &str, text: &str) -> Result<(), RecordingError> {
        self.attach(name, LAUNCH_MEDIA_TYPE, text)
    }

    /// Stores a data file the launch names (`data_files.rs`), under its path relative to the
    /// launch file.
    pub fn attach_data(&mut self, name: &str, bytes: &[u8]) -> Result<(), RecordingError> {
        self.attach(name, data_files::DATA_MEDIA_TYPE, bytes)
    }

    fn attach(&mut self, name: &str, media_type: &str, data: impl AsRef<[u8]>) -> Result<(), RecordingError> {
        let a = mcap::Attachment {
            log_time: 0,
            create_time: 0,
            name: name.to_owned(),
            media_type: media_type.to_owned(),
            data: std::borrow::Cow::Borrowed(data.as_ref()),
        };
        self.writer.attach(&a).map_err(|e| self.err(e))
    }

    /// Ends the current chunk and pushes it to the file: what is recorded so far survives a crash.
    pub fn flush(&mut self) -> Result<(), RecordingError> {
        self.writer.flush().map_err(|e| self.err(e))
    }

    pub fn stats(&self) -> impl Iterator<Item = &ChannelStats> {
        self.channels.iter().map(|(_, s)| s)
    }

    /// Writes the per-topic counts as a `harvey.recorder` metadata record and the summary.
    pub fn finish(mut self) -> Result<Vec<ChannelStats>, RecordingError> {
        let mut metadata = BTreeMap::new();
        for (_, s) in &self.channels {
            metadata.insert(format!("{}.messages", s.topic), s.messages.to_string());
            if !s.shared {
                metadata.insert(format!("{}.seq_gaps", s.topic), s.seq_gaps.to_string());
            }
        }
        let record = Metadata { name: RECORDER_METADATA.into(), metadata };
        self.writer.write_metadata(&record).map_err(|e| self.err(e))?;
        self.writer.finish().map_err(|e| self.err(e))?;
        Ok(self.channels.into_iter().map(|(_, s)| s).collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use harvey_msgs::{Encoding, Header, Pose2, TruePose};

    #[test]
    fn a_recording_reads_back_with_schemas_channels_and_counts() {
        let dir = std::env::temp_dir().join(format!("harvey-rec-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("tmp");
        let path = dir.join("t.mcap");
        let mut r = Recorder::create(&path).expect("create");
        let truth = r.channel::<TruePose>("sim/truth").expect("channel");
        let cam = r.image_channel("camera/frame").expect("channel");
        for seq in [1u64, 2, 5] {
            let msg = TruePose {
                header: Header::new(seq, seq * 1000),
                world_from_robot: Pose2 { x_m: seq as f64, ..Default::default() },
            };
            r.record(truth, &msg).expect("record");
        }
        r.flush().expect("flush");
        r.record_frame(cam, &FrameHeader::new(1, 1500, 2, 1, Encoding::Mono8), &[9, 8]).expect("frame");
        let stats = r.finish().expect("finish");
        assert_eq!((stats[0].messages, stats[0].seq_gaps, stats[1].messages), (3, 2, 1));

        let bytes = std::fs::read(&path).expect("read");
        let msgs: Vec<_> =
            mcap::MessageStream::new(&bytes).expect("stream").collect::<Result<_, _>>().expect("valid");
        assert_eq!(msgs.len(), 4);
        assert_eq!(msgs[0].channel.topic, "/sim/truth");
        assert_eq!(msgs[0].channel.message_encoding, "cdr");
        let schema = msgs[0].channel.schema.as_ref().expect("schema");
        assert_eq!((schema.name.as_str(), schema.encoding.as_str()), ("harvey_msgs/msg/TruePose", "ros2msg"));
        assert!(msgs[0].channel.metadata.contains_key("offered_qos_profiles"));
        let back: TruePose = harvey_cdr::decode(&msgs[2].data).expect("decode");
        assert_eq!((back.header.seq, back.world_from_robot.x_m, msgs[2].log_time), (5, 5.0, 5000));
        let summary = mcap::Summary::read(&bytes).expect("summary").expect("present");
        assert_eq!(summary.stats.expect("stats").message_count, 4);
        std::fs::remove_dir_all(&dir).ok();
    }
}
