//! `harvey export`: an MCAP recording to a Rerun file, through the same drawing as the live
//! recorder, using the world file the recording carries as an attachment.

use std::path::Path;

use crate::draw::draw_recorded;
use crate::rrd::RrdWriter;
use crate::same_file::refuse_overwrite;
use crate::{Recording, RecordingError};

/// Converts `mcap` to `rrd` (which may not be `mcap` itself), calling `progress(done, total)` as
/// messages go; returns how many messages were drawn.
pub fn export(mcap: &Path, rrd: &Path, mut progress: impl FnMut(u64, u64)) -> Result<u64, RecordingError> {
    refuse_overwrite(mcap, rrd)?;
    let recording = Recording::open(mcap)?;
    let total = recording.message_count();
    // The messages are the recording; a world that no longer loads (an older file format, say)
    // only costs the drawing of the walls.
    let world = match recording.world() {
        Ok(world) => world.map(|(w, _)| w),
        Err(e) => {
            tracing::warn!("{e}; drawing without the world");
            None
        }
    };
    let mut w = RrdWriter::create(rrd, world.as_ref())?;
    let mut drawn = 0u64;
    for m in recording.messages()? {
        let m = m?;
        let i = m.index();
        let draw_error = |cause| RecordingError::Draw {
            file: mcap.to_owned(),
            index: i,
            topic: m.topic().to_owned(),
            cause: Box::new(cause),
        };
        if draw_recorded(&mut w, m.topic(), m.data()).map_err(draw_error)? {
            drawn += 1;
        }
        if i % 256 == 0 {
            progress(i as u64, total);
        }
    }
    progress(total, total);
    w.finish()?;
    Ok(drawn)
}
