//! `harvey recover RECORDING -o OUT`: salvage every chunk of a recording whose writer died (or
//! whose bytes are damaged) that its CRC vouches for into a valid file; what was skipped is named
//! by its offset.

use std::path::Path;

pub fn run(recording: &Path, output: &Path) -> anyhow::Result<i32> {
    // Refused before anything is read or written.
    harvey_recording::same_file::refuse_overwrite(recording, output)?;
    let s = harvey_recording::recover::recover(recording, output)?;
    println!(
        "{}: {} messages and {} attachments salvaged{}",
        output.display(),
        s.messages,
        s.attachments,
        s.losses()
    );
    Ok(0)
}
