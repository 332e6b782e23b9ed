//! A restarted recorder's continuation of its recording: what its killed predecessor left
//! (every message of every chunk whose CRC checks, as `harvey recover` salvages them) is
//! written first into the new file, so that the run stays one recording that every tool reads
//! whole. Only the unflushed tail of the killed writer is lost (at most its flush interval).
//!
//! The old file is first renamed aside (`run.mcap.interrupted`) and removed once its messages
//! are copied; a recorder killed during the copy finds the file aside again and starts over
//! from it (the new file then held only a partial copy).

use std::path::{Path, PathBuf};

use crate::{Recorder, Recording, RecordingError, salvage};

/// What was carried over.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct CarriedOver {
    pub messages: u64,
    /// Messages on topics the new recording has no channel for (none, with the same recorder).
    pub skipped: u64,
    /// File offsets of chunks whose CRC did not check (the killed writer's last, cut short).
    pub damaged_chunks: Vec<u64>,
    /// Per topic, the newest (log time, sequence) carried over: a restarted subscriber is
    /// handed a topic's newest message again, which may be one of these.
    pub newest: std::collections::BTreeMap<String, (u64, u32)>,
}

/// Where the predecessor's file waits while it is copied.
pub fn aside(path: &Path) -> PathBuf {
    let mut name = path.as_os_str().to_owned();
    name.push(".interrupted");
    PathBuf::from(name)
}

/// Moves the predecessor's file at `path` aside, unless an interrupted copy already left one
/// there (then the file at `path` is that partial copy, and is dropped). Returns the file to
/// carry over, if there is any.
pub fn set_aside(path: &Path) -> Result<Option<PathBuf>, RecordingError> {
    let old = aside(path);
    if old.is_file() {
        return Ok(Some(old));
    }
    if !path.is_file() {
        return Ok(None);
    }
    std::fs::rename(path, &old).map_err(|cause| RecordingError::Create { file: old.clone(), cause })?;
    Ok(Some(old))
}

/// Writes the messages of `old` into `rec` (whose channels are set up), handing each to `each`
/// as well (topic, log time, sequence and bytes: to draw it, to derive from it), then removes
/// `old`.
pub fn carry_over<E: From<RecordingError>>(
    old: &Path,
    rec: &mut Recorder,
    mut each: impl FnMut(&str, u64, u32, &[u8]) -> Result<(), E>,
) -> Result<CarriedOver, E> {
    let recording = Recording::open(old)?;
    let bytes = recording.bytes();
    if !bytes.starts_with(mcap::MAGIC) {
        return Err(RecordingError::NoMagic { file: old.to_owned() }.into());
    }
    let vouched = salvage::data_crc_vouches(bytes);
    let mut messages = salvage::Messages::new(bytes, recording.summary_if_any(), vouched);
    let mut out = CarriedOver::default();
    for chunk in messages.by_ref() {
        for m in &chunk {
            let topic = m.channel.topic.trim_start_matches('/');
            let Some(ch) = rec.channel_of(topic) else {
                out.skipped += 1;
                continue;
            };
            rec.record_encoded(ch, u64::from(m.sequence), m.log_time, &m.data)?;
            each(topic, m.log_time, m.sequence, &m.data)?;
            out.messages += 1;
            let newest = out.newest.entry(topic.to_owned()).or_insert((m.log_time, m.sequence));
            *newest = (*newest).max((m.log_time, m.sequence));
        }
    }
    out.damaged_chunks = messages.damaged_chunks;
    drop(recording);
    std::fs::remove_file(old).map_err(|cause| RecordingError::Create { file: old.to_owned(), cause })?;
    Ok(out)
}
