//! `harvey recover`: salvages a recording whose writer died (SIGKILL, power loss) into a valid
//! MCAP file: every message of every complete chunk, the attachments, in order. What the dead
//! writer had not yet flushed is gone; how far the salvage got is reported.

use std::borrow::Cow;
use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

use enumset::EnumSet;
use mcap::read::Options;
use mcap::records::{Metadata, Record};

use crate::{RECOVER_METADATA, Recording, RecordingError};

/// What was salvaged.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Salvage {
    pub messages: u64,
    pub attachments: u64,
    /// Why reading stopped before a proper end, if it did.
    pub stopped_at: Option<String>,
}

/// Copies what can be read of `input` into a new, complete MCAP file at `output`.
pub fn recover(input: &Path, output: &Path) -> Result<Salvage, RecordingError> {
    let recording = Recording::open(input)?;
    let bytes = recording.bytes();
    if !bytes.starts_with(mcap::MAGIC) {
        return Err(RecordingError::NoMagic { file: input.to_owned() });
    }
    let not_mcap = |cause| RecordingError::NotMcap { file: input.to_owned(), cause };
    let options = EnumSet::only(Options::IgnoreEndMagic);
    let mut profile = String::new();
    let mut attachments = Vec::new();
    let mut metadata = Vec::new();
    let mut stopped_at = None;
    let linear = mcap::read::LinearReader::new_with_options(bytes, options).map_err(not_mcap)?;
    for record in linear {
        match record {
            Ok(Record::Header(h)) => profile = h.profile,
            Ok(Record::Attachment { header, data, .. }) => attachments.push((header, data)),
            Ok(Record::Metadata(m)) => metadata.push(m),
            Ok(_) => {}
            Err(e) => {
                stopped_at = Some(e.to_string());
                break;
            }
        }
    }
    let out =
        File::create(output).map_err(|cause| RecordingError::Create { file: output.to_owned(), cause })?;
    let oerr = |cause| RecordingError::Write { file: output.to_owned(), cause };
    let mut w = mcap::WriteOptions::new()
        .profile(&profile)
        .library(concat!("harvey recover ", env!("CARGO_PKG_VERSION")))
        .create(BufWriter::new(out))
        .map_err(oerr)?;
    for (h, data) in &attachments {
        let a = mcap::Attachment {
            log_time: h.log_time,
            create_time: h.create_time,
            name: h.name.clone(),
            media_type: h.media_type.clone(),
            data: Cow::Borrowed(data),
        };
        w.attach(&a).map_err(oerr)?;
    }
    for m in &metadata {
        w.write_metadata(m).map_err(oerr)?;
    }
    let mut messages = 0;
    let stream = mcap::MessageStream::new_with_options(bytes, options).map_err(not_mcap)?;
    for m in stream {
        match m {
            Ok(m) => {
                w.write(&m).map_err(oerr)?;
                messages += 1;
            }
            Err(e) => {
                stopped_at.get_or_insert(e.to_string());
                break;
            }
        }
    }
    let mut md = std::collections::BTreeMap::new();
    md.insert("source".to_owned(), input.display().to_string());
    md.insert("messages".to_owned(), messages.to_string());
    md.insert("stopped_at".to_owned(), stopped_at.clone().unwrap_or_else(|| "end of file".into()));
    w.write_metadata(&Metadata { name: RECOVER_METADATA.into(), metadata: md }).map_err(oerr)?;
    w.finish().map_err(oerr)?;
    Ok(Salvage { messages, attachments: attachments.len() as u64, stopped_at })
}
